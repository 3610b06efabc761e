// Time per gyroscope calibration (CalibrateGyroscope) for a 12-pose and a
// 40-pose simulated session: hand-like rotations, raw counts, the
// accelerometer calibrated and the static intervals detected outside the
// timed loop.
#include <benchmark/benchmark.h>

#include <atomic>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/gyro_calibration.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/residuals/gyro_rotation_residual.h"
#include "gravcal/simulation/simulator.h"
#include "util/cancellation.h"

namespace gravcal {
namespace {

struct Prepared {
  SimulatedSession session;
  Calibration accel;
  std::vector<StaticInterval> intervals;
};

Prepared Prepare(const SimulatorScheme& scheme, uint64_t seed) {
  SimulatorOptions sim;
  sim.scheme = scheme;
  sim.rotation_profile = RotationProfile::kHand;
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

// range(0): 12 or 40 poses; range(1): 0 = full, 1 = full + G, 2 = joint;
// range(2): 1 = one solver thread, as inside a batch worker (the limit run
// beside the default, where a single calibration takes the machine's
// threads). Google Benchmark's CPU time is the calling thread's only: compare
// the real time.
void BM_GyroCalibration(benchmark::State& state) {
  const std::atomic<bool> never(false);
  std::optional<internal::ScopedCancelFlag> one_thread;
  if (state.range(2) == 1) one_thread.emplace(&never);
  const SimulatorScheme scheme = state.range(0) == 12 ? SimulatorScheme{PoseScheme::kTwelve}
                                                      : SimulatorScheme{PoseScheme::kRandom, 40};
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
BENCHMARK(BM_GyroCalibration)
    ->ArgsProduct({{12, 40}, {0, 1, 2}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The derivatives of one turn's attitude change (300 samples at 100 Hz, a
// rate up to 2 rad/s sweeping its axis) with respect to b_g, M_g and G, as
// the rotation residuals need them at every solver iteration. range(0): 0 =
// dual numbers carried through every sample (IntegrateGyroRotation with
// ceres::Jet<double, 21>), 1 = IntegrateGyroRotationJacobian (what the
// residuals use).
void BM_TurnDerivatives(benchmark::State& state) {
  GyroRotationData turn;
  for (int k = 0; k < 300; ++k) {
    const double t = 0.01 * k;
    const double s = std::sin(M_PI * k / 300.0);
    turn.t.push_back(t);
    turn.gyro.push_back(Eigen::Vector3d(std::cos(3.0 * t), std::sin(2.0 * t), 0.5) * 2.0 * s /
                        0.01);
    turn.force.push_back(Eigen::Vector3d(0.5, -2.0, 9.5));
  }
  double b[3] = {1.0, -2.0, 0.5}, m[9] = {0.01, 1e-4, 0.0, -1e-4, 0.01, 2e-4, 0.0, 0.0, 0.01};
  double g[9] = {1e-4, 0.0, 0.0, 0.0, -1e-4, 0.0, 0.0, 0.0, 2e-4};
  using Dual = ceres::Jet<double, 21>;
  Dual db[3], dm[9], dg[9];
  for (int i = 0; i < 3; ++i) db[i] = Dual(b[i], i);
  for (int i = 0; i < 9; ++i) dm[i] = Dual(m[i], 3 + i);
  for (int i = 0; i < 9; ++i) dg[i] = Dual(g[i], 12 + i);
  for (auto _ : state) {
    if (state.range(0) == 0) {
      Dual dq[4];
      IntegrateGyroRotation<Dual>(turn, db, dm, dg, dq);
      benchmark::DoNotOptimize(dq);
    } else {
      double dq[4];
      Eigen::Matrix<double, 4, 21> jacobian;
      IntegrateGyroRotationJacobian(turn, b, m, g, dq, &jacobian);
      benchmark::DoNotOptimize(jacobian);
    }
  }
}
BENCHMARK(BM_TurnDerivatives)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
