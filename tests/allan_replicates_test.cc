// Replicate still logs of one unit, shaped like real ones (issue 33): the
// noise terms read from each agree with the other replicates' within their
// reported standard deviations, and a log too short to show a floor or a
// rise says so instead of giving a number.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/noise_flicker.h"
#include "gravcal/core/noise_model.h"
#include "gravcal/estimation/allan_deviation.h"
#include "gravcal/estimation/spectral_lines.h"
#include "gravcal/simulation/noise_process.h"

namespace gravcal {
namespace {

constexpr double kReplicateRate = 50.0;

// One replicate of a unit's axis at 50 Hz: white noise N = 1e-4, a flicker
// floor flat from 3 to 1000 s meeting the white noise at 30 s, a random walk
// rising out of it at 500 s, and what differs from one recording to the
// next: a 17 Hz tone (amplitude 30 % either way about 3e-3, far above the
// white noise at short tau), a slow line of period 700 s (a heater's cycle,
// amplitude 1e-5 to 3e-5, random phase: a bump at about 260 s) and a ramp
// (a warming sensor, N(0, 3e-9) per s).
NoiseProcessOptions ReplicateAxis(std::mt19937_64* rng) {
  std::uniform_real_distribution<double> spread(0.0, 1.0);
  std::normal_distribution<double> ramp(0.0, 3e-9);
  NoiseProcessOptions o;
  o.rate_hz = kReplicateRate;
  o.white_noise = 1e-4;
  const double floor = o.white_noise * o.white_noise / 30.0;
  o.bias_instability = std::sqrt(floor / kFlickerAllanFactor);
  o.bias_tau_low = 3.0;
  o.bias_tau_high = 1000.0;
  o.random_walk = std::sqrt(3.0 * floor / 500.0);
  const double tone = 3e-3 * (0.7 + 0.6 * spread(*rng));
  const double slow = 2e-5 * (0.5 + spread(*rng));
  o.tones = {{17.0, tone}, {1.0 / 700.0, slow}};
  o.ramp = ramp(*rng);
  return o;
}

struct ReplicateReading {
  AxisNoiseModel model;
  std::string message;
};

ReplicateReading ReadReplicate(const NoiseProcessOptions& o, uint64_t seed, double seconds) {
  NoiseProcess process(o, seed);
  const std::vector<double> x = process.Generate(static_cast<size_t>(seconds * o.rate_hz));
  const std::vector<SpectralLine> lines = FindSpectralLines(x, 0, x.size(), o.rate_hz);
  AllanDeviation curve;
  EXPECT_TRUE(ComputeAllanDeviation(x, 0, x.size(), o.rate_hz, AllanOptions(), &curve));
  NoiseFit fit;
  EXPECT_TRUE(FitNoiseTerms(curve, NoiseFitOptions(), lines, &fit)) << fit.message;
  return {fit.model, fit.message};
}

// Root mean square of the pairwise z = (a - b) / sqrt(sa^2 + sb^2) over
// the replicates where the term is visible; *pairs counts them.
double PairwiseRmsZ(const std::vector<NoiseTerm>& terms, int* pairs) {
  double sum = 0.0;
  *pairs = 0;
  for (size_t a = 0; a < terms.size(); ++a) {
    for (size_t b = a + 1; b < terms.size(); ++b) {
      if (!terms[a].visible() || !terms[b].visible()) continue;
      const double z = (terms[a].value - terms[b].value) / std::hypot(terms[a].std, terms[b].std);
      sum += z * z;
      ++*pairs;
    }
  }
  return *pairs > 0 ? std::sqrt(sum / *pairs) : NAN;
}

// Six two-hour replicates. Each reading must be visible (N and B; K where
// the rise is a random walk's), N within 15 % of the truth and B within a
// factor of two (B is the conventional reading of the floor, sigma_min /
// 0.664, which holds the white noise and the random walk where they meet
// the floor too: 1.1-1.5 times the flicker coefficient here). The pairwise
// z of the replicates: with exact sigmas, rms z over the 15 pairs of six
// replicates is sqrt(chi2_5 / 5), within [0.48, 1.49] at 90 %; the reported
// sigmas also hold the model's error (where on its range a term is read),
// shared by replicates of one unit, so rms z may come out lower: asserted
// in [0.3, 1.5]. On the fit before this test (main at 5c10d29) B was
// undetermined in two of the six ("does not dominate at the curve's
// floor") and read at 1311 s in another, +-120 %.
TEST(AllanReplicates, OneUnitsReplicatesAgreeWithinTheirSigmas) {
  std::mt19937_64 rng(33);
  std::vector<NoiseTerm> n, b, k;
  NoiseProcessOptions truth;
  for (uint64_t replicate = 0; replicate < 6; ++replicate) {
    truth = ReplicateAxis(&rng);
    const ReplicateReading r = ReadReplicate(truth, 900 + replicate, 7200.0);
    const AxisNoiseModel& m = r.model;
    ASSERT_TRUE(m.white_noise.visible()) << replicate << ": " << m.white_noise.reason;
    ASSERT_TRUE(m.bias_instability.visible()) << replicate << ": " << m.bias_instability.reason;
    EXPECT_NEAR(m.white_noise.value / truth.white_noise, 1.0, 0.15) << replicate;
    EXPECT_GT(m.bias_instability.value / truth.bias_instability, 0.5) << replicate;
    EXPECT_LT(m.bias_instability.value / truth.bias_instability, 2.0) << replicate;
    // N clear of the tone, B on the floor between the slopes.
    EXPECT_GT(m.white_noise.tau, 0.5) << replicate;
    EXPECT_GT(m.bias_instability.tau, 20.0) << replicate;
    EXPECT_LT(m.bias_instability.tau, 1000.0) << replicate;
    n.push_back(m.white_noise);
    b.push_back(m.bias_instability);
    k.push_back(m.random_walk);
    std::cout << replicate << ": N " << m.white_noise.value << " +- " << m.white_noise.std
              << " (tau " << m.white_noise.tau << "), B " << m.bias_instability.value << " +- "
              << m.bias_instability.std << " (tau " << m.bias_instability.tau << "), K "
              << m.random_walk.value << " +- " << m.random_walk.std << " " << m.random_walk.reason
              << "\n";
  }
  const char* names[3] = {"N", "B", "K"};
  const std::vector<NoiseTerm>* terms[3] = {&n, &b, &k};
  for (int j = 0; j < 3; ++j) {
    int pairs = 0;
    const double rms = PairwiseRmsZ(*terms[j], &pairs);
    std::cout << names[j] << ": pairwise rms z " << rms << " over " << pairs << " pairs\n";
    EXPECT_GE(pairs, j == 2 ? 3 : 15) << names[j];
    EXPECT_LT(rms, 1.5) << names[j];
    EXPECT_GT(rms, 0.3) << names[j];
  }
}

// The model read from a log of `o` (no flicker): N within 10 % of the
// truth, B undetermined with a reason that contains `why`.
AxisNoiseModel ReadWithoutFlicker(const NoiseProcessOptions& o, uint64_t seed, double seconds,
                                  const std::string& why) {
  const AxisNoiseModel m = ReadReplicate(o, seed, seconds).model;
  EXPECT_TRUE(m.white_noise.visible()) << seed << ": " << m.white_noise.reason;
  EXPECT_NEAR(m.white_noise.value / o.white_noise, 1.0, 0.1) << seed;
  EXPECT_FALSE(m.bias_instability.visible()) << seed << ": " << m.bias_instability.value;
  EXPECT_NE(m.bias_instability.reason.find(why), std::string::npos) << m.bias_instability.reason;
  return m;
}

// Ten minutes of white noise and a tone: the curve never leaves the -1/2
// slope, so neither a floor nor a rise is shown. B and K are undetermined
// with the reason (B's names its upper bound), N is read.
TEST(AllanReplicates, ShortWhiteLogShowsNoFloorNorRise) {
  NoiseProcessOptions o;
  o.rate_hz = 100.0;
  o.white_noise = 1e-4;
  o.tones = {{17.0, 1e-3}};
  for (uint64_t seed = 0; seed < 3; ++seed) {
    const AxisNoiseModel m = ReadWithoutFlicker(o, 40 + seed, 600.0, "no floor");
    EXPECT_FALSE(m.random_walk.visible()) << seed << ": " << m.random_walk.value;
    EXPECT_FALSE(m.random_walk.reason.empty());
  }
}

// White noise and a random walk, no flicker: the curve's floor is where
// the two slopes meet. B is not determined there (else a model holding N,
// K and B counts the floor twice, and `plan` finds no design): NaN, with
// the floor read as B as its upper bound and the reason. N and K are read.
// With flicker, the model's Allan variance at B's tau is the floor itself
// (B's share of the other terms taken off), not floor plus N and K again.
TEST(AllanReplicates, WhiteAndRandomWalkShowNoBiasInstability) {
  NoiseProcessOptions o;
  o.rate_hz = 50.0;
  o.white_noise = 1e-4;
  o.random_walk = std::sqrt(3.0) * o.white_noise / 100.0;  // they meet at tau 100 s
  for (uint64_t seed = 0; seed < 2; ++seed) {
    const AxisNoiseModel m = ReadWithoutFlicker(o, 70 + seed, 7200.0, "meet");
    ASSERT_TRUE(m.random_walk.visible()) << seed << ": " << m.random_walk.reason;
    EXPECT_NEAR(m.random_walk.value / o.random_walk, 1.0, 0.5) << seed;
    const double meeting = std::sqrt(2.0) * o.white_noise / std::sqrt(100.0);  // adev there
    EXPECT_GT(m.bias_instability.upper_bound * std::sqrt(kFlickerAllanFactor), 0.7 * meeting);
    EXPECT_LT(m.bias_instability.upper_bound * std::sqrt(kFlickerAllanFactor), 1.5 * meeting);
  }
  AxisNoiseModel with_flicker;
  with_flicker.white_noise.value = 1e-4;
  with_flicker.random_walk.value = 1e-6;
  with_flicker.bias_instability.value = 1e-4;
  with_flicker.bias_instability.tau = 20.0;
  EXPECT_NEAR(with_flicker.AllanVariance(20.0), kFlickerAllanFactor * 1e-8, 1e-15);
  EXPECT_NEAR(internal::FlickerAllanVariance(with_flicker),
              kFlickerAllanFactor * 1e-8 - 1e-8 / 20.0 - 1e-12 * 20.0 / 3.0, 1e-15);
  with_flicker.bias_instability.tau = NAN;  // a datasheet's B: all flicker
  EXPECT_NEAR(internal::FlickerAllanVariance(with_flicker), kFlickerAllanFactor * 1e-8, 1e-15);
  EXPECT_NEAR(with_flicker.AllanVariance(20.0),
              kFlickerAllanFactor * 1e-8 + 1e-8 / 20.0 + 1e-12 * 20.0 / 3.0, 1e-15);
}

}  // namespace
}  // namespace gravcal
