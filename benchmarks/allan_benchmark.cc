// Allan deviation and noise-term fit of a long still log: 8 hours at 200 Hz,
// six axes (5.76 million samples each), the curve at 2 points per octave up
// to a fifth of the log, then the fit.
#include <benchmark/benchmark.h>

#include <array>
#include <vector>

#include "gravcal/estimation/allan_deviation.h"
#include "gravcal/simulation/noise_process.h"

namespace gravcal {
namespace {

constexpr double kRate = 200.0;

const std::array<std::vector<double>, 6>& Axes() {
  static const std::array<std::vector<double>, 6> axes = [] {
    std::array<std::vector<double>, 6> out;
    NoiseProcessOptions o;
    o.rate_hz = kRate;
    o.white_noise = 1e-3;
    o.bias_instability = 2e-3;
    o.bias_tau_low = 0.1;
    o.bias_tau_high = 1000.0;
    o.random_walk = 1e-4;
    for (int a = 0; a < 6; ++a) {
      NoiseProcess p(o, a);
      out[a] = p.Generate(static_cast<size_t>(8 * 3600 * kRate));
    }
    return out;
  }();
  return axes;
}

void BM_AllanDeviationAndFitSixAxes(benchmark::State& state) {
  const auto& axes = Axes();
  AllanOptions options;
  options.points_per_octave = static_cast<int>(state.range(0));
  size_t points = 0;
  for (auto _ : state) {
    for (const std::vector<double>& x : axes) {
      AllanDeviation curve;
      ComputeAllanDeviation(x, 0, x.size(), kRate, options, &curve);
      NoiseFit fit;
      FitNoiseTerms(curve, NoiseFitOptions(), &fit);
      points = curve.points.size();
      benchmark::DoNotOptimize(fit.model.white_noise.value);
    }
  }
  state.counters["taus"] = static_cast<double>(points);
}
BENCHMARK(BM_AllanDeviationAndFitSixAxes)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
