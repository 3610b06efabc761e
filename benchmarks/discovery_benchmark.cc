// Cost of one full discovery run (DiscoverFromObservations): baseline fit,
// leave-one-out cross-validation of the baseline, every applicable
// catalogue effect refitted with Ceres, scored (LRT, BIC, leave-one-out CV),
// and the extended model refitted and cross-validated per step, until
// nothing is significant.
//
// Sessions are simulated once (outside the timed loop) with the static
// detection done; kSessions of them are cycled. Cases:
// - twelve, scale baseline: the seed's twelve positions with the `scale`
//   baseline, so every one of the 8 catalogue effects can be tried (6 + 3
//   parameters leave 3 residual dof); no hidden effect.
// - twelve, scale_misalignment baseline: only the gyroscope effects can be
//   tried (9 + 3 parameters would leave no dof for the accelerometer ones).
// - random:24 with an accelerometer bias tempco hidden: one step found.
// Reported time is per discovery run; counter `steps` = effects named.
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/discovery.h"

namespace gravcal {
namespace {

constexpr int kSessions = 8;

struct Session {
  std::vector<StaticObservation> observations;
  CalibrationOptions calibration;
};

std::vector<Session> MakeSessions(const SimulatorOptions& sim, AccelParameterization p) {
  std::vector<Session> out;
  for (int seed = 1; seed <= kSessions; ++seed) {
    SimulatedSession s;
    std::string error;
    if (!Simulate(sim, seed, &s, &error)) continue;
    Session session;
    session.calibration.gravity.gravity = s.gravity;
    session.calibration.refinement.parameterization = p;
    StaticDetection detection;
    if (!DetectStaticIntervals(s.log, session.calibration.detector, &detection)) continue;
    session.observations = ObservationsFromIntervals(detection.intervals, true);
    out.push_back(session);
  }
  return out;
}

SimulatorOptions WarmUp(const SimulatorScheme& scheme) {
  SimulatorOptions o;
  o.scheme = scheme;
  o.temperature_start = 20.0;
  o.temperature_end = 35.0;
  o.temperature_tau = 120.0;
  return o;
}

void Run(benchmark::State& state, const std::vector<Session>& sessions) {
  DiscoveryOptions options;
  size_t i = 0;
  double steps = 0.0;
  int runs = 0;
  for (auto _ : state) {
    const Session& s = sessions[i++ % sessions.size()];
    DiscoveryResult result;
    const bool ok = DiscoverFromObservations(s.observations, s.calibration, {}, options, &result);
    if (!ok) {
      state.SkipWithError(result.message.c_str());
      return;
    }
    steps += static_cast<double>(result.steps.size());
    ++runs;
    benchmark::DoNotOptimize(result.verdict);
  }
  state.counters["steps"] = runs > 0 ? steps / runs : 0.0;
}

void BM_DiscoveryTwelveScaleBaseline(benchmark::State& state) {
  static const std::vector<Session> sessions =
      MakeSessions(WarmUp({PoseScheme::kTwelve}), AccelParameterization::kScale);
  // The scale baseline misses the truth's non-orthogonality: the first step
  // names accel_misalignment, as it should.
  Run(state, sessions);
}
BENCHMARK(BM_DiscoveryTwelveScaleBaseline)->Unit(benchmark::kMillisecond);

void BM_DiscoveryTwelveNoMisalignmentScaleBaseline(benchmark::State& state) {
  SimulatorOptions sim = WarmUp({PoseScheme::kTwelve});
  sim.accel_misalignment_std = 0.0;
  static const std::vector<Session> sessions = MakeSessions(sim, AccelParameterization::kScale);
  Run(state, sessions);
}
BENCHMARK(BM_DiscoveryTwelveNoMisalignmentScaleBaseline)->Unit(benchmark::kMillisecond);

void BM_DiscoveryTwelveScaleMisalignmentBaseline(benchmark::State& state) {
  static const std::vector<Session> sessions =
      MakeSessions(WarmUp({PoseScheme::kTwelve}), AccelParameterization::kScaleMisalignment);
  Run(state, sessions);
}
BENCHMARK(BM_DiscoveryTwelveScaleMisalignmentBaseline)->Unit(benchmark::kMillisecond);

void BM_DiscoveryRandom24HiddenTemperatureBias(benchmark::State& state) {
  SimulatorOptions sim = WarmUp({PoseScheme::kRandom, 24});
  sim.effect_std[Effect::kAccelTemperatureBias] = 0.005;
  static const std::vector<Session> sessions =
      MakeSessions(sim, AccelParameterization::kScaleMisalignment);
  Run(state, sessions);
}
BENCHMARK(BM_DiscoveryRandom24HiddenTemperatureBias)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
