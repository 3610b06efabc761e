// Cost of the fine and coarse fits per IMU: Ceres refinement (Refine) against
// the hand-written Newton iteration (NewtonRefine, both residual forms), and
// the closed-form coarse fits. Target: Ceres refinement of a 12-position IMU
// under 30 us on one core, covariance off.
//
// Each benchmark cycles over kImus synthetic IMUs (random affine truth in raw
// counts, 9.80665 / 16384 m/s^2 per count): the twelve directions of Chen et
// al. plus random directions up to 12, 24 or 48 positions, 2 degrees of
// placement tilt, 0.02 m/s^2 noise per sample, 1000 samples per position.
// Positions and the coarse fit that starts the refinement are computed once,
// outside the timed loop. Reported time is per IMU.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "estimation/newton_solver.h"
#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"
#include "gravcal/estimation/coarse_fit.h"
#include "gravcal/estimation/refinement.h"
#include "test_util.h"

namespace gravcal {
namespace {

using internal::NewtonOptions;
using internal::NewtonRefine;

constexpr double kG = 9.80665;
constexpr double kCountScale = kG / 16384.0;
constexpr double kTilt = 2.0 * M_PI / 180.0;
constexpr double kNoise = 0.02;
constexpr int kSamples = 1000;
// The solver's iteration count varies from IMU to IMU (it ends in 4 to 10
// iterations, depending on rounding near the optimum), so the average needs a
// fair number of IMUs.
constexpr int kImus = 64;

struct Imu {
  AccelModel truth;
  std::vector<Position> positions;
  std::vector<int> nominal_up;
  AccelModel start;  // The coarse fit.
};

// kImus IMUs with `num_positions` positions each, built once per count.
const std::vector<Imu>& Imus(int num_positions) {
  static std::vector<Imu> cache[3];
  const int slot = num_positions <= 12 ? 0 : num_positions <= 24 ? 1 : 2;
  std::vector<Imu>& imus = cache[slot];
  if (!imus.empty()) return imus;
  std::mt19937_64 rng(20240601 + num_positions);
  for (int i = 0; i < kImus; ++i) {
    Imu imu;
    imu.truth = AccelModel::Random(AccelParameterization::kAffine, kCountScale, 0.02, 0.01,
                                   0.3 / kCountScale, &rng);
    std::vector<Eigen::Vector3d> directions = testing_util::TwelveDirections();
    while (static_cast<int>(directions.size()) < num_positions) {
      directions.push_back(testing_util::RandomDirection(&rng));
    }
    imu.positions = testing_util::MakePositions(imu.truth, directions, kG, kTilt, kNoise, kSamples,
                                                /*set_nominal=*/true, &rng);
    AssignNominalAxes(imu.positions, nullptr, CoarseFitOptions().axis_tolerance_deg,
                      &imu.nominal_up);
    CoarseFitResult coarse;
    if (!CoarseFit(imu.positions, kG, AccelParameterization::kScaleMisalignment, CoarseFitOptions(),
                   &coarse)) {
      std::fprintf(stderr, "coarse fit failed: %s\n", coarse.message.c_str());
      std::abort();
    }
    imu.start = coarse.model;
    imus.push_back(std::move(imu));
  }
  return imus;
}

// Solver iterations per IMU and the share that converged, as counters.
// The timed loop shared by the refinement benchmarks: `solve(imu, &result)`
// refines one IMU; the counters report iterations, convergence and IMUs/s.
template <typename Solve>
void RunRefinement(benchmark::State& state, const std::vector<Imu>& imus, Solve solve) {
  RefinementResult result;
  double iterations = 0.0, converged = 0.0;
  size_t i = 0;
  for (auto _ : state) {
    const Imu& imu = imus[i++ % imus.size()];
    if (!solve(imu, &result)) {
      state.SkipWithError(result.message.c_str());
      return;
    }
    benchmark::DoNotOptimize(result.model.upper.data());
    iterations += result.iterations;
    converged += result.converged;
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["solver_iters"] = iterations / n;
  state.counters["converged"] = converged / n;
  state.counters["imus_per_s"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
}

// Args: positions, covariance (0/1).
void BM_CeresRefine(benchmark::State& state) {
  const std::vector<Imu>& imus = Imus(static_cast<int>(state.range(0)));
  RefinementOptions options;
  options.compute_covariance = state.range(1) != 0;
  RunRefinement(state, imus, [&](const Imu& imu, RefinementResult* result) {
    return Refine(imu.positions, imu.start, kG, options, result);
  });
}
BENCHMARK(BM_CeresRefine)
    ->ArgNames({"positions", "cov"})
    ->ArgsProduct({{12, 24, 48}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

// The graduated robust solve (Cauchy loss), for scale: several Ceres solves.
void BM_CeresRefineCauchy(benchmark::State& state) {
  const std::vector<Imu>& imus = Imus(static_cast<int>(state.range(0)));
  RefinementOptions options;
  options.loss = LossType::kCauchy;
  options.compute_covariance = state.range(1) != 0;
  RunRefinement(state, imus, [&](const Imu& imu, RefinementResult* result) {
    return Refine(imu.positions, imu.start, kG, options, result);
  });
}
BENCHMARK(BM_CeresRefineCauchy)
    ->ArgNames({"positions", "cov"})
    ->ArgsProduct({{12}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

// Args: positions, residual form (0 = squared magnitude, the seed's; 1 =
// magnitude, Ceres's cost), covariance (0/1).
void BM_NewtonRefine(benchmark::State& state) {
  const std::vector<Imu>& imus = Imus(static_cast<int>(state.range(0)));
  NewtonOptions options;
  options.residual =
      state.range(1) == 0 ? NewtonResidual::kSquaredMagnitude : NewtonResidual::kMagnitude;
  options.compute_covariance = state.range(2) != 0;
  RunRefinement(state, imus, [&](const Imu& imu, RefinementResult* result) {
    return NewtonRefine(imu.positions, imu.start, kG, options, result);
  });
}
BENCHMARK(BM_NewtonRefine)
    ->ArgNames({"positions", "magnitude", "cov"})
    ->ArgsProduct({{12, 24, 48}, {0, 1}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

// The seed's six-position least squares (nominal axes assigned beforehand).
void BM_SixPositionFit(benchmark::State& state) {
  const std::vector<Imu>& imus = Imus(static_cast<int>(state.range(0)));
  Eigen::Vector3d bias;
  Eigen::Matrix3d matrix;
  std::string error;
  size_t i = 0;
  for (auto _ : state) {
    const Imu& imu = imus[i++ % imus.size()];
    if (!SixPositionFit(imu.positions, imu.nominal_up, kG, &bias, &matrix, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
    benchmark::DoNotOptimize(matrix.data());
  }
  state.counters["imus_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SixPositionFit)
    ->ArgName("positions")
    ->Arg(12)
    ->Arg(24)
    ->Arg(48)
    ->Unit(benchmark::kMicrosecond);

// The general (10-coefficient) ellipsoid fit.
void BM_EllipsoidFit(benchmark::State& state) {
  const std::vector<Imu>& imus = Imus(static_cast<int>(state.range(0)));
  AccelModel model;
  std::string error;
  size_t i = 0;
  for (auto _ : state) {
    const Imu& imu = imus[i++ % imus.size()];
    if (!EllipsoidFit(imu.positions, /*diagonal=*/false, kG, &model, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
    benchmark::DoNotOptimize(model.upper.data());
  }
  state.counters["imus_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_EllipsoidFit)
    ->ArgName("positions")
    ->Arg(12)
    ->Arg(24)
    ->Arg(48)
    ->Unit(benchmark::kMicrosecond);

// CoarseFit as the pipeline calls it: nominal axes, method choice, the fit
// and the cast to the parameterisation (the six-position fit here).
void BM_CoarseFit(benchmark::State& state) {
  const std::vector<Imu>& imus = Imus(static_cast<int>(state.range(0)));
  CoarseFitResult result;
  size_t i = 0;
  for (auto _ : state) {
    const Imu& imu = imus[i++ % imus.size()];
    if (!CoarseFit(imu.positions, kG, AccelParameterization::kScaleMisalignment, CoarseFitOptions(),
                   &result)) {
      state.SkipWithError(result.message.c_str());
      return;
    }
    benchmark::DoNotOptimize(result.model.upper.data());
  }
  state.counters["imus_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_CoarseFit)
    ->ArgName("positions")
    ->Arg(12)
    ->Arg(24)
    ->Arg(48)
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
