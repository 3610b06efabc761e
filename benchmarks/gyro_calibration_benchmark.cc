// Time per gyroscope calibration (CalibrateGyroscope) for a 12-pose and a
// 40-pose simulated session: hand-like rotations, raw counts, the
// accelerometer calibrated and the static intervals detected outside the
// timed loop.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/simulation/simulator.h"

namespace gravcal {
namespace {

struct Prepared {
  SimulatedSession session;
  Calibration accel;
  std::vector<StaticInterval> intervals;
};

Prepared Prepare(const std::string& scheme, uint64_t seed) {
  SimulatorOptions sim;
  sim.scheme = scheme;
  sim.rotation_profile = "hand";
  sim.hold_seconds = 6.0;
  Prepared p;
  std::string error;
  if (!Simulate(sim, seed, &p.session, &error)) return p;
  CalibrationOptions options;
  options.gravity.gravity = p.session.gravity;
  CalibrateAccelerometer(p.session.log, options, &p.accel);
  StaticDetection detection;
  DetectStaticIntervals(p.session.log, options.detector, &detection);
  p.intervals = detection.intervals;
  return p;
}

// range(0): 12 or 40 poses; range(1): 0 = full, 1 = full + G, 2 = joint.
void BM_GyroCalibration(benchmark::State& state) {
  const std::string scheme = state.range(0) == 12 ? "twelve" : "random:40";
  std::vector<Prepared> sessions;
  for (uint64_t seed = 1; seed <= 4; ++seed) sessions.push_back(Prepare(scheme, seed));
  GyroCalibrationOptions options;
  options.parameterization = GyroParameterization::kFull;
  options.g_sensitivity = state.range(1) == 1;
  options.joint = state.range(1) == 2;
  size_t i = 0;
  double iterations = 0.0, failures = 0.0;
  for (auto _ : state) {
    const Prepared& p = sessions[i++ % sessions.size()];
    GyroCalibrationResult result;
    const bool ok =
        CalibrateGyroscope(p.session.log, p.intervals, p.accel.accel.model,
                           p.accel.refinement.covariance, p.accel.gravity, options, &result);
    failures += ok ? 0.0 : 1.0;
    iterations += result.iterations;
    benchmark::DoNotOptimize(result);
  }
  state.counters["solver_iters"] =
      benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
  state.counters["failures"] = failures;
}
BENCHMARK(BM_GyroCalibration)->ArgsProduct({{12, 40}, {0, 1, 2}})->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
