// Time per ten-position calibration (static detection, two Kalman
// alignments per position, the step-4 Ceres fit and the step-5 normal
// equations), and per single static alignment.
#include <benchmark/benchmark.h>

#include <vector>

#include "gravcal/estimation/static_alignment.h"
#include "gravcal/methods/ten_position.h"
#include "gravcal/simulation/simulator.h"

namespace gravcal {
namespace {

SimulatorOptions Session(double hold_seconds) {
  SimulatorOptions sim;
  sim.scheme = {PoseScheme::kTen};
  sim.hold_seconds = hold_seconds;
  return sim;
}

// The simulated ten-position session of configs/ten_position.yaml (100 Hz,
// raw counts, MEMS gyroscope), `hold` seconds per position.
void BM_TenPositionCalibration(benchmark::State& state) {
  SimulatedSession s;
  std::string error;
  if (!Simulate(Session(static_cast<double>(state.range(0))), 1, &s, &error)) {
    state.SkipWithError(error.c_str());
    return;
  }
  CalibrationOptions options;
  options.gravity.gravity = s.gravity;
  TenPositionOptions ten;
  ten.gyro_nominal_scale = 1.0 / s.gyro_units_per_si;
  for (auto _ : state) {
    Calibration c;
    const bool ok = CalibrateTenPosition(s.log, options, ten, &c);
    if (!ok) {
      state.SkipWithError(c.message.c_str());
      return;
    }
    benchmark::DoNotOptimize(c.accel.model.bias);
  }
  state.counters["samples"] = static_cast<double>(s.log.size());
}
BENCHMARK(BM_TenPositionCalibration)->Arg(10)->Arg(30)->Unit(benchmark::kMillisecond);

// One fine alignment (coarse + 12-state Kalman filter) on `samples` samples.
void BM_StaticAlignment(benchmark::State& state) {
  SimulatedSession s;
  std::string error;
  if (!Simulate(Session(60.0), 1, &s, &error)) {
    state.SkipWithError(error.c_str());
    return;
  }
  const SimulatedPose& pose = s.poses[1];
  std::vector<Eigen::Vector3d> force, rate;
  for (size_t i = pose.begin; i < pose.begin + state.range(0); ++i) {
    force.push_back(s.log.accel[i] / s.accel_units_per_si);
    rate.push_back(s.log.gyro[i] / s.gyro_units_per_si);
  }
  StaticAlignmentOptions options;
  for (auto _ : state) {
    StaticAlignmentResult r;
    AlignStatic(force, rate, 0.01, options, &r);
    benchmark::DoNotOptimize(r.roll);
  }
}
BENCHMARK(BM_StaticAlignment)->Arg(1000)->Arg(3000)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
