#!/usr/bin/env bash
# gravcal apply, two builds on one log, interleaved: MB/s of input (wall and
# CPU, the median of the runs) and their ratio, and whether the outputs are
# the same bytes. CPU time is every thread's; the wall-time ratio is the
# figure a user sees (apply runs on one thread per core, issue 39 part 3).
# Usage: benchmarks/apply_compare.sh BEFORE_GRAVCAL AFTER_GRAVCAL CALIB.json LOG [RUNS]
set -euo pipefail
before=$1 after=$2 calib=$3 log=$4 runs=${5:-5}
bytes=$(stat -c %s "$log")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The same bytes (written to files, once each).
"$before" apply --calibration "$calib" --input "$log" --output "$tmp/before.csv" 2> /dev/null
"$after" apply --calibration "$calib" --input "$log" --output "$tmp/after.csv" 2> /dev/null
if cmp -s "$tmp/before.csv" "$tmp/after.csv"; then same=identical; else same=DIFFERENT; fi
rm -f "$tmp/before.csv" "$tmp/after.csv"
for ((i = 0; i < runs; ++i)); do
  for side in before after; do
    bin=${!side}
    /usr/bin/time -f "%e %U %S" -o "$tmp/t" "$bin" apply --calibration "$calib" --input "$log" \
      --output - > /dev/null 2> /dev/null
    read -r wall user sys < "$tmp/t"
    echo "$side $wall $(echo "$user + $sys" | bc)" >> "$tmp/times"
  done
done
median() { sort -n | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
bw=$(awk '$1=="before" {print $2}' "$tmp/times" | median)
aw=$(awk '$1=="after" {print $2}' "$tmp/times" | median)
bc_=$(awk '$1=="before" {print $3}' "$tmp/times" | median)
ac=$(awk '$1=="after" {print $3}' "$tmp/times" | median)
awk -v b="$bytes" -v bw="$bw" -v aw="$aw" -v bc="$bc_" -v ac="$ac" -v same="$same" -v runs="$runs" \
  -v load="$(cut -d' ' -f1-3 /proc/loadavg)" 'BEGIN {
  mb = b / 1e6
  printf "log %.0f MB, %d runs each, interleaved, load average %s\n", mb, runs, load
  printf "before: %.1f MB/s wall, %.1f MB/s CPU\n", mb / bw, mb / bc
  printf "after:  %.1f MB/s wall, %.1f MB/s CPU\n", mb / aw, mb / ac
  printf "after / before: %.2fx wall, %.2fx CPU; output %s\n", bw / aw, bc / ac, same
}'
