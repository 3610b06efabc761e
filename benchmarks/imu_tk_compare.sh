#!/usr/bin/env bash
# gravcal against imu_tk (Tedaldi et al. 2014) on imu_tk's own example
# recording (bin/test_data/xsens_acc.mat and xsens_gyro.mat: accelerometer
# and gyroscope of an Xsens unit in raw counts, 38 static poses), timed
# interleaved: imu_tk, gravcal, imu_tk, ... each run a fresh process doing
# what its example does (read both files, calibrate the accelerometer and the
# gyroscope, write the result).
#
# Usage: benchmarks/imu_tk_compare.sh IMU_TK_SOURCE GRAVCAL_BUILD [RUNS]
#   IMU_TK_SOURCE  a checkout of imu_tk (github.com/Kyle-ak/imu_tk); the
#                  script fetches nothing and builds imu_tk's calibration
#                  without its GUI (no Qt, OpenGL or GLUT: the plotting
#                  calls, reached only in verbose mode, are stubbed).
#   GRAVCAL_BUILD  a Release build folder of gravcal (with build/gravcal).
#   RUNS           runs of each (default 10).
# Prints the median wall time and peak memory of each and their ratio.
# Needs g++, Ceres, Eigen and Boost headers (imu_tk includes boost).
set -euo pipefail
src=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
runs=${3:-10}
acc=$src/bin/test_data/xsens_acc.mat
gyro=$src/bin/test_data/xsens_gyro.mat
for f in "$acc" "$gyro" "$src/src/calibration.cpp" "$build/gravcal"; do
  [ -e "$f" ] || { echo "imu_tk_compare: $f is missing" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# imu_tk's example (apps/test_imu_calib.cpp) without the GUI.
cat > "$work/driver.cc" <<'CC'
#include <vector>
#include "imu_tk/calibration.h"
#include "imu_tk/io_utils.h"
#include "imu_tk/visualization.h"
namespace imu_tk {
// Plotting is reached only with verbose output, which the driver leaves off.
Plot::Plot() {}
template <typename T>
void Plot::plotIntervals(const std::vector<TriadData_<T>>&, const std::vector<DataInterval>&,
                         DataInterval) {}
template void Plot::plotIntervals<double>(const std::vector<TriadData_<double>>&,
                                          const std::vector<DataInterval>&, DataInterval);
template void Plot::plotIntervals<float>(const std::vector<TriadData_<float>>&,
                                         const std::vector<DataInterval>&, DataInterval);
void waitForKey() {}
}  // namespace imu_tk
int main(int argc, char** argv) {
  using namespace imu_tk;
  std::vector<TriadData> acc, gyro;
  importAsciiData(argv[1], acc, TIMESTAMP_UNIT_SEC);
  importAsciiData(argv[2], gyro, TIMESTAMP_UNIT_SEC);
  CalibratedTriad init_acc, init_gyro;
  init_acc.setBias(Eigen::Vector3d(32768, 32768, 32768));
  init_gyro.setScale(Eigen::Vector3d(1.0 / 6258.0, 1.0 / 6258.0, 1.0 / 6258.0));
  MultiPosCalibration calib;
  calib.setInitStaticIntervalDuration(50.0);
  calib.setInitAccCalibration(init_acc);
  calib.setInitGyroCalibration(init_gyro);
  calib.setGravityMagnitude(9.81744);
  calib.enableVerboseOutput(false);
  calib.enableAccUseMeans(false);
  if (!calib.calibrateAccGyro(acc, gyro)) return 1;
  calib.getAccCalib().save(argv[3]);
  calib.getGyroCalib().save(argv[4]);
  return 0;
}
CC
# Three setters of calibration.h return a value they never set; g++ -O2 and
# above then lets the call fall into the next function. A copy of the
# headers gets the missing `return`.
cp -r "$src/include" "$work/include"
sed -i -E 's/^(\s+(_T|int|bool) (set|enable)\w*\(.*\)\s*\{ *\w+ = (\w+);) *\};/\1 return \4; }/' \
  "$work/include/imu_tk/calibration.h"
echo "building imu_tk (calibration, filters, io_utils; -O3)" >&2
g++ -O3 -DNDEBUG -std=c++14 -w -I"$work/include" -I/usr/include/eigen3 \
  "$work/driver.cc" "$src/src/calibration.cpp" "$src/src/filters.cpp" "$src/src/io_utils.cpp" \
  -o "$work/imu_tk_calib" -lceres -lglog -lpthread

# The same recording, settings as imu_tk's example: whitespace columns, the
# gyroscope in a second file, g = 9.81744, full gyroscope model.
cat > "$work/xsens.yaml" <<'YAML'
method: twelve_position
format: whitespace
columns: [t, ax, ay, az]
gravity: 9.81744
parameterization: scale_misalignment
gyro_model: full
YAML

# wall seconds, user + system CPU seconds and peak kB of one command,
# appended to $1.
measure() {
  local out=$1; shift
  /usr/bin/time -f "%e %U %S %M" -o "$work/time" "$@" > /dev/null 2>&1 ||
    { echo "imu_tk_compare: failed: $*" >&2; exit 1; }
  cat "$work/time" >> "$out"
}
: > "$work/imu_tk.txt"
: > "$work/gravcal.txt"
for ((i = 0; i < runs; i++)); do
  measure "$work/imu_tk.txt" "$work/imu_tk_calib" "$acc" "$gyro" "$work/acc.calib" "$work/gyro.calib"
  measure "$work/gravcal.txt" "$build/gravcal" calibrate --config "$work/xsens.yaml" \
    --input "$acc" --gyro_path "$gyro" --output "$work/gravcal.json"
done
python3 - "$work/imu_tk.txt" "$work/gravcal.txt" "$runs" <<'PY'
import statistics, sys
def load(p):
    rows = [list(map(float, l.split())) for l in open(p) if l.strip()]
    return (statistics.median(r[0] for r in rows), statistics.median(r[1] + r[2] for r in rows),
            statistics.median(r[3] for r in rows) / 1024)
it, gc = load(sys.argv[1]), load(sys.argv[2])
print("runs of each, interleaved: %s (medians)" % sys.argv[3])
print("imu_tk : %.3f s wall, %.3f s CPU, %.1f MB peak" % it)
print("gravcal: %.3f s wall, %.3f s CPU, %.1f MB peak" % gc)
print("gravcal: %.1fx faster (wall), %.1fx less CPU, %.1fx less memory"
      % (it[0] / gc[0], it[1] / gc[1], it[2] / gc[2]))
PY
