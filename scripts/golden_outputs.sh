#!/usr/bin/env bash
# Writes the calibration JSON of the demo, of the real recordings (when
# ../shared/data/real exists) and of one simulated run of every method into
# OUT_DIR, with wall-clock fields removed, so that two builds can be compared
# with `diff -r`. Usage: scripts/golden_outputs.sh BUILD_DIR OUT_DIR
set -euo pipefail
build=$(cd "$1" && pwd)
out=$2
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
out=$(cd "$out" && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
g="$build/gravcal"
# Time fields (solver.time_s and friends) differ between any two runs.
strip() { python3 -c '
import json, sys
def walk(x):
    if isinstance(x, dict):
        return {k: walk(v) for k, v in x.items() if not (k.endswith("time_s") or k.endswith("_seconds") or k == "solve_seconds")}
    if isinstance(x, list):
        return [walk(v) for v in x]
    return x
print(json.dumps(walk(json.load(open(sys.argv[1]))), indent=1, sort_keys=True))' "$1" > "$2"; }

cd "$root"
"$g" demo --config configs/twelve_position.yaml > "$out/demo.txt" 2>&1 || true
sed -i -E -e '/(time|seconds)/d' -e 's/[0-9.]+ (us|ms|s);/<time>;/' "$out/demo.txt"

run_sim() {  # name config [extra calibrate flags...]
  local name=$1 cfg=$2; shift 2
  local sim=()
  [ "$name" = handheld_kalman ] && sim=(--sim_motion handheld)
  "$g" simulate --config "$cfg" "${sim[@]}" --seed 3 --output-dir "$tmp/$name" > /dev/null 2>&1
  local att=()
  [ "$name" = known_attitude ] && att=(--attitudes "$tmp/$name/attitudes.csv")
  "$g" calibrate --input "$tmp/$name/raw.csv" --config "$cfg" "${att[@]}" "$@" \
    --output "$tmp/$name.json" > /dev/null 2>&1 || echo "calibrate $name failed" >&2
  strip "$tmp/$name.json" "$out/$name.json"
}
run_sim twelve_position configs/twelve_position.yaml
run_sim twelve_position_newton configs/twelve_position.yaml --solver newton
run_sim twelve_position_gyro configs/twelve_position_gyro.yaml
run_sim ten_position configs/ten_position.yaml
run_sim known_attitude configs/known_attitude.yaml
run_sim handheld_kalman configs/handheld_kalman.yaml \
  --nominal_scale 0.00059855 --gyro_nominal_scale 0.000133231 --gravity 9.80665
run_sim discovery_effects configs/discovery.yaml
run_sim thermal configs/thermal.yaml
# rate_table: the simulator's rate-table motion (configs/handheld_kalman.yaml
# holds its keys) and the segments it writes.
"$g" simulate --config configs/handheld_kalman.yaml --sim_motion rate_table --seed 3 \
  --output-dir "$tmp/rate_table" > /dev/null 2>&1
"$g" calibrate --input "$tmp/rate_table/raw.csv" --config configs/rate_table.yaml \
  --segments "$tmp/rate_table/segments.csv" --output "$tmp/rate_table.json" > /dev/null 2>&1 ||
  echo "calibrate rate_table failed" >&2
strip "$tmp/rate_table.json" "$out/rate_table.json"

real="$root/../shared/data/real"
if [ -d "$real" ]; then
  for pair in ferraris_nilspod:ferraris_nilspod/session.csv \
              ferraris_nilspod_handheld:ferraris_nilspod/session.csv \
              mpu6050_ten_pose:mpu6050_ten_pose/session.csv \
              ahrs_static_poses:ahrs_static_poses/imu_good1.txt; do
    name=${pair%%:*}; file=${pair#*:}
    "$g" calibrate --input "$real/$file" --config "configs/$name.yaml" \
      --output "$tmp/real_$name.json" > /dev/null 2>&1 || echo "calibrate $name failed" >&2
    strip "$tmp/real_$name.json" "$out/real_$name.json"
  done
fi
echo "wrote $(ls "$out" | wc -l) files to $out"
