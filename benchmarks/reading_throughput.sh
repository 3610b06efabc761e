#!/usr/bin/env bash
# Issue 39: how fast gravcal reads long logs, as ratios to the limits
# measured on the same file in the same run, and its peak memory.
#
#   benchmarks/reading_throughput.sh BUILD_DIR [GB] [WORK_DIR] [GRAVCAL]
#   COMMANDS="inspect calibrate" benchmarks/reading_throughput.sh ...  (a subset)
#
# Makes two logs of about GB gigabytes (default 1) with `gravcal simulate`
# in WORK_DIR (default $TMPDIR/gravcal_reading; never in the repository):
# still.csv (a long still stretch, for `noise` and `inspect`) and poses.csv
# (twelve long poses with gyroscope turns, for `calibrate`), at 1 kHz in raw
# counts (about 43 bytes a row). For each command it reports MB/s and, from
# the same run, the ratios to `wc -l` and to benchmarks/fast_float_loop.cc
# (every field parsed with fast_float, nothing checked or kept), and the
# peak resident memory (/usr/bin/time -v). GRAVCAL (default BUILD_DIR/
# gravcal) lets another build's binary be timed on the same files. The logs
# are kept for a second run (delete WORK_DIR when done).
set -euo pipefail
build=$(cd "$1" && pwd)
gb=${2:-1}
work=${3:-${TMPDIR:-/tmp}/gravcal_reading}
g=${4:-$build/gravcal}
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$work"
config="$root/configs/twelve_position_gyro.yaml"

# Seconds at 1 kHz for GB gigabytes of 43-byte rows.
seconds=$(python3 -c "print(int($gb * 1e9 / 43 / 1000))")
if [ ! -s "$work/still.csv" ]; then
  "$build/gravcal" simulate --config "$config" --output-dir "$work/still" --sim_sample_rate 1000 \
    --sim_initial_still "$seconds" --sim_hold 10 >/dev/null 2>&1
  mv "$work/still/raw.csv" "$work/still.csv"
fi
if [ ! -s "$work/poses.csv" ]; then
  hold=$(python3 -c "print(int($seconds / 12))")
  "$build/gravcal" simulate --config "$config" --output-dir "$work/poses" --sim_sample_rate 1000 \
    --sim_hold "$hold" >/dev/null 2>&1
  mv "$work/poses/raw.csv" "$work/poses.csv"
fi
g++ -O2 -std=c++17 "$root/benchmarks/fast_float_loop.cc" -o "$work/fast_float_loop"

# Runs a command under /usr/bin/time -v; prints "cpu_seconds wall_seconds
# peak_MB". The rates below are per CPU second (user + system): the 2-core
# machine is shared, and the wall clock counts the time other processes
# held the cores. Since the reader parses a long log on every core (io/
# log_blocks.h) its CPU time is the sum over the threads: "wall x wc" (wall
# clock against wc -l's, same run) is the figure the parallel reader moves,
# and it is only meaningful on an idle machine.
measure() {
  /usr/bin/time -v "$@" >/dev/null 2>"$work/time.txt" || {
    echo "failed: $*" >&2
    tail -3 "$work/time.txt" >&2
    echo "nan nan nan"
    return
  }
  python3 - "$work/time.txt" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (\S+)", text).group(1)
seconds = 0.0
for part in wall.split(":"):
    seconds = seconds * 60 + float(part)
rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", text).group(1))
cpu = sum(float(re.search(rf"{k} time \(seconds\): (\S+)", text).group(1)) for k in ("User", "System"))
print(f"{cpu:.2f} {seconds:.2f} {rss / 1024:.0f}")
PY
}

echo "date: $(date -u '+%Y-%m-%d %H:%M UTC'); machine: $(nproc) cores, $(uname -m)," \
  "load $(cut -d' ' -f1-3 /proc/loadavg); gravcal: $g"
printf '%-10s %-10s %6s %7s %7s %7s %9s %9s %10s %8s\n' command file MB "cpu s" "wall s" MB/s "x wc -l" "x ff loop" "wall x wc" "peak MB"
run() {  # name file command...
  local name=$1 file=$2
  shift 2
  case " ${COMMANDS:-inspect noise calibrate} " in *" $name "*) ;; *) return 0 ;; esac
  local mb
  mb=$(python3 -c "import os; print(os.path.getsize('$file') / 1e6)")
  cat "$file" >/dev/null  # from the page cache for every run below
  read -r wc_s wc_wall _ < <(measure wc -l "$file")
  read -r ff_s _ _ < <(measure "$work/fast_float_loop" "$file")
  read -r s wall peak < <(measure "$@")
  python3 - "$name" "$(basename "$file")" "$mb" "$s" "$wall" "$wc_s" "$ff_s" "$peak" "$wc_wall" <<'PY'
import sys
name, file, mb, s, wall, wc, ff, peak, wc_wall = sys.argv[1:]
mb, s, wc, ff = float(mb), float(s), max(float(wc), 0.01), max(float(ff), 0.01)
ww = max(float(wc_wall), 0.01) / max(float(wall), 0.01)
print(f"{name:<10} {file:<10} {mb:6.0f} {s:7.2f} {wall:>7} {mb / s:7.0f} {wc / s:9.3f} {ff / s:9.3f} {ww:10.3f} {peak:>8}")
print(f"  limits: wc -l {mb / wc:.0f} MB/s, fast_float loop {mb / ff:.0f} MB/s (CPU)")
PY
}
run inspect "$work/still.csv" "$g" inspect --input "$work/still.csv"
# simulate's raw counts: 16384 per g, 131 per deg/s.
units="--nominal_scale 0.000598550415 --gyro_nominal_scale 0.000133231240"
# shellcheck disable=SC2086
run noise "$work/still.csv" "$g" noise --config "$config" --input "$work/still.csv" $units \
  --output "$work/noise.json"
run calibrate "$work/poses.csv" "$g" calibrate --config "$config" --input "$work/poses.csv" \
  --output "$work/calibration.json"
