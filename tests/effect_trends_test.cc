// Issue 21, estimation side: the within-pose trends make three-parameter
// accelerometer effects testable and estimable on a twelve-position session
// (the seed's twelve poses held 30 s, gyroscope, a warm-up during the
// session, consumer-MEMS noise with bias instability and random walk).
// Also the trend residual's Jacobian, the trend statistics on known data,
// and the magnitude-only path.
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "effect_session.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/effect_fit.h"
#include "gravcal/residuals/accel_trend_residual.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "jacobian_check.h"
#include "sigma_check.h"
#include "test_util.h"
#include "util/statistics.h"

namespace gravcal {
namespace {

using internal::ChiSquareUpperTail;
using testing_util::kCandidateLevel;
using testing_util::Nominal;
using testing_util::References;
using testing_util::SessionIntervals;
using testing_util::TwelvePoseWarmUp;
using testing_util::WithHidden;

struct HiddenEffect {
  Effect effect;
  double std;
  AccelParameterization baseline;
};

// Typical consumer-MEMS sizes (the discovery test's): k2 1.5e-4 /(m/s^2),
// bias tempco 0.2 mg/K, scale tempco 0.01 %/K, drift 0.5 mg/min; the
// non-orthogonality is the simulator's default 0.01 rad, hidden from a
// scale-only baseline.
const HiddenEffect kHidden[] = {
    {Effect::kAccelQuadratic, 1.5e-4, AccelParameterization::kScaleMisalignment},
    {Effect::kAccelTemperatureBias, 2e-3, AccelParameterization::kScaleMisalignment},
    {Effect::kAccelTemperatureScale, 1e-4, AccelParameterization::kScaleMisalignment},
    {Effect::kAccelBiasDrift, 8.2e-5, AccelParameterization::kScaleMisalignment},
    {Effect::kAccelMisalignment, 0.0, AccelParameterization::kScale},
};

// The observations of a simulated session's poses (the simulator's own
// still periods, so that detection is not under test here) with trends.
std::vector<StaticObservation> SessionObservations(const SimulatedSession& session) {
  return ObservationsFromIntervals(session.log, SessionIntervals(session));
}

// chi2 of the accelerometer fit with `effects` over `baseline`.
SensorFitSummary AccelFit(const std::vector<StaticObservation>& observations,
                          const SimulatedSession& session, AccelParameterization baseline,
                          const std::vector<Effect>& effects) {
  EffectFitOptions options;
  options.parameterization = baseline;
  options.effects = effects;
  options.fit_gyro = false;
  EffectFitResult fit;
  EXPECT_TRUE(FitEffects(observations, Nominal(session), GyroModel(), References(observations),
                         session.gravity, options, &fit))
      << fit.message;
  EXPECT_TRUE(fit.accel_fit.converged) << fit.message;
  return fit.accel_fit;
}

// p of the likelihood-ratio test of `effect` over the baseline.
double LikelihoodRatioP(const std::vector<StaticObservation>& observations,
                        const SimulatedSession& session, const HiddenEffect& h) {
  const SensorFitSummary base = AccelFit(observations, session, h.baseline, {});
  const SensorFitSummary ext = AccelFit(observations, session, h.baseline, {h.effect});
  return ChiSquareUpperTail(base.chi2 - ext.chi2, ext.num_parameters - base.num_parameters);
}

// The trend residual's autodiff Jacobian against central differences.
TEST(AccelTrendResidual, JacobianMatchesNumericDifferences) {
  const Eigen::Vector3d raw(310.0, -1200.0, 15800.0);
  const Eigen::Vector3d slope(0.02, -0.01, 0.05);
  Eigen::Matrix3d whitening;
  whitening << 30.0, 0.0, 0.0, 2.0, 25.0, 0.0, -1.0, 3.0, 28.0;
  std::unique_ptr<ceres::CostFunction> cost(
      AccelTrendResidual::Create(raw, slope, whitening, 0.03, 4.0, -50.0));
  double bias[3] = {20.0, -30.0, 45.0};
  double upper[6] = {6.0e-4, 2e-6, -3e-6, 6.1e-4, 1e-6, 5.9e-4};
  std::vector<double> effects = testing_util::EveryAccelEffectOn();
  std::vector<std::vector<double>> jac;
  testing_util::ExpectJacobianMatchesCentralDifferences(*cost, {bias, upper, effects.data()},
                                                        {3, 6, kAccelEffectParameters},
                                                        {1e-2, 1e-9, 1e-8}, 1e-5, &jac);
  // The quadratic term predicts no trend.
  const int k2 = effects::kLayout.offset[static_cast<int>(Effect::kAccelQuadratic)];
  for (size_t row = 0; row < jac[2].size() / kAccelEffectParameters; ++row) {
    for (int i = 0; i < 3; ++i) EXPECT_EQ(jac[2][row * kAccelEffectParameters + k2 + i], 0.0);
  }
  // The one row along gravity (discover's trends): same parameters, one
  // residual.
  AccelTrendResidual::Whitening along(1, 3);
  along << 0.01, -0.07, 0.99;
  std::unique_ptr<ceres::CostFunction> one(
      AccelTrendResidual::Create(raw, slope, along * 30.0, 0.03, 4.0, -50.0));
  EXPECT_EQ(one->num_residuals(), 1);
  testing_util::ExpectJacobianMatchesCentralDifferences(*one, {bias, upper, effects.data()},
                                                        {3, 6, kAccelEffectParameters},
                                                        {1e-2, 1e-9, 1e-8}, 1e-5, &jac);
}

// A still log with a known linear trend and white noise: the slope is
// recovered and its stated covariance matches the spread over seeds.
TEST(WithinPoseTrends, RecoverAKnownSlopeWithHonestCovariance) {
  testing_util::SigmaCheck check;
  for (int seed = 1; seed <= 200; ++seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    ImuLog log;
    const Eigen::Vector3d slope(0.5, -0.2, 0.0);
    std::vector<StaticInterval> intervals;
    for (int pose = 0; pose < 4; ++pose) {
      const size_t begin = log.t.size();
      for (int i = 0; i < 1000; ++i) {
        const double t = 20.0 * pose + 0.01 * i;
        log.t.push_back(t);
        log.accel.push_back(Eigen::Vector3d(100.0, -50.0, 1600.0) + slope * (t - 20.0 * pose) +
                            Eigen::Vector3d(n(rng), 2.0 * n(rng), n(rng)));
        log.temperature.push_back(25.0 + 0.1 * t);
      }
      intervals.push_back(MakeInterval(log, begin, log.t.size()));
    }
    const std::vector<StaticObservation> obs = ObservationsFromIntervals(log, intervals);
    ASSERT_EQ(obs.size(), 4u);
    for (const StaticObservation& o : obs) {
      ASSERT_TRUE(o.has_trend);
      EXPECT_NEAR(o.temperature_slope, 0.1, 1e-9);
      for (int a = 0; a < 3; ++a) {
        check.Add("slope_" + std::to_string(a), o.accel_slope(a) - slope(a),
                  std::sqrt(o.accel_slope_cov(a, a)));
      }
    }
  }
  std::printf("%s", check.Table().c_str());
  check.ExpectHonest("within-pose slope");
}

TEST(WithinPoseTrends, ShortPosesAndInvalidOptionsGiveNoTrend) {
  ImuLog log;
  std::vector<StaticInterval> intervals;
  for (int pose = 0; pose < 3; ++pose) {
    const size_t begin = log.t.size();
    // 2 s poses: shorter than min_seconds (3 s).
    for (int i = 0; i < 200; ++i) {
      log.t.push_back(10.0 * pose + 0.01 * i);
      log.accel.push_back(0.01 * Eigen::Vector3d(i % 3, i % 5, 980.0 + i % 7));
    }
    intervals.push_back(MakeInterval(log, begin, log.t.size()));
  }
  for (const StaticObservation& o : ObservationsFromIntervals(log, intervals)) {
    EXPECT_FALSE(o.has_trend);
  }
  WithinPoseTrendOptions options;
  options.min_seconds = 1.0;
  for (const StaticObservation& o : ObservationsFromIntervals(log, intervals, options)) {
    EXPECT_TRUE(o.has_trend);
  }
  options.batches = 2;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_NE(error.find("batches"), std::string::npos) << error;
  EXPECT_TRUE(ObservationsFromIntervals(log, intervals, options).empty());
}

// The twelve-position session: with the trends each accelerometer effect
// is significant over the baseline in at least 18 of 20 seeds; the fit
// says which information it used and counts the trend residuals.
TEST(EffectTrends, TwelvePositionsDetectEveryAccelEffect) {
  for (const HiddenEffect& h : kHidden) {
    const SimulatorOptions sim = WithHidden(TwelvePoseWarmUp(), h.effect, h.std);
    int significant = 0;
    for (int seed = 1; seed <= 20; ++seed) {
      SimulatedSession session;
      std::string error;
      ASSERT_TRUE(Simulate(sim, seed, &session, &error)) << error;
      const std::vector<StaticObservation> obs = SessionObservations(session);
      if (LikelihoodRatioP(obs, session, h) < kCandidateLevel) ++significant;
      if (seed == 1) {
        const SensorFitSummary f = AccelFit(obs, session, h.baseline, {h.effect});
        EXPECT_EQ(f.information, "position magnitudes + within-pose trends");
        EXPECT_EQ(f.trend_residuals, 3 * 12);
        EXPECT_EQ(f.num_residuals, 12 + 3 * 12);
        EXPECT_TRUE(f.undetermined.empty());
      }
    }
    std::printf("%s: significant in %d of 20\n", ToString(h.effect), significant);
    EXPECT_GE(significant, 18) << ToString(h.effect);
  }
}

// No hidden effect (scale_misalignment baseline, non-orthogonality in it):
// no accelerometer effect is significant in at least 19 of 20 seeds.
TEST(EffectTrends, TwelvePositionsWithoutHiddenEffectShowNone) {
  const SimulatorOptions sim = TwelvePoseWarmUp();
  int quiet[4] = {0, 0, 0, 0};
  for (int seed = 101; seed <= 120; ++seed) {
    SimulatedSession session;
    std::string error;
    ASSERT_TRUE(Simulate(sim, seed, &session, &error)) << error;
    const std::vector<StaticObservation> obs = SessionObservations(session);
    for (int i = 0; i < 4; ++i) {
      if (LikelihoodRatioP(obs, session, kHidden[i]) >= kCandidateLevel) ++quiet[i];
    }
  }
  for (int i = 0; i < 4; ++i) {
    std::printf("%s: not significant in %d of 20\n", ToString(kHidden[i].effect), quiet[i]);
    EXPECT_GE(quiet[i], 19) << ToString(kHidden[i].effect);
  }
}

// Without the trends (the magnitude-only path) twelve positions leave the
// drift undetermined on top of the 9-parameter baseline and the
// quadratic term: the trends are what determines it.
TEST(EffectTrends, MagnitudeOnlyPathIsKept) {
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(TwelvePoseWarmUp(), 1, &session, &error)) << error;
  const std::vector<StaticObservation> obs = SessionObservations(session);
  EffectFitOptions options;
  options.effects = {Effect::kAccelBiasDrift};
  options.use_within_pose_trends = false;
  EffectFitResult fit;
  ASSERT_TRUE(FitEffects(obs, Nominal(session), GyroModel(), References(obs), session.gravity,
                         options, &fit))
      << fit.message;
  EXPECT_EQ(fit.accel_fit.information, "position magnitudes");
  EXPECT_EQ(fit.accel_fit.num_residuals, 12);
  EXPECT_EQ(fit.accel_fit.trend_residuals, 0);
  // A fixed extra variance adds to every magnitude's sigma^2.
  const std::vector<double> white = fit.accel_sigmas;
  options.magnitude_extra_variance = 4e-8;
  ASSERT_TRUE(FitEffects(obs, Nominal(session), GyroModel(), References(obs), session.gravity,
                         options, &fit))
      << fit.message;
  for (size_t k = 0; k < white.size(); ++k) {
    EXPECT_NEAR(fit.accel_sigmas[k], std::sqrt(white[k] * white[k] + 4e-8), 1e-12);
  }
  options.magnitude_extra_variance = -1.0;
  EXPECT_FALSE(FitEffects(obs, Nominal(session), GyroModel(), References(obs), session.gravity,
                          options, &fit));
  EXPECT_NE(fit.message.find("magnitude_extra_variance"), std::string::npos) << fit.message;
  options.magnitude_extra_variance = 0.0;
  options.effects = {Effect::kAccelQuadratic, Effect::kAccelBiasDrift};
  EXPECT_FALSE(FitEffects(obs, Nominal(session), GyroModel(), References(obs), session.gravity,
                          options, &fit));
  EXPECT_NE(fit.message.find("needs at least 15"), std::string::npos) << fit.message;
  options.use_within_pose_trends = true;
  ASSERT_TRUE(FitEffects(obs, Nominal(session), GyroModel(), References(obs), session.gravity,
                         options, &fit))
      << fit.message;
  EXPECT_TRUE(fit.accel_fit.undetermined.empty());
}

// calibrate --effects (FitCalibrationEffects) on the twelve-position
// session: error / reported sigma of every effect parameter, 30 seeds, rms
// over the effect's three parameters in [0.8, 1.25].
TEST(EffectTrends, CalibrateEstimatesEffectsOnTwelvePositionsWithHonestSigmas) {
  for (int i = 0; i < 4; ++i) {
    const HiddenEffect& h = kHidden[i];
    const SimulatorOptions sim = WithHidden(TwelvePoseWarmUp(), h.effect, h.std);
    testing_util::SigmaCheck check;
    for (int seed = 1; seed <= 30; ++seed) {
      SimulatedSession session;
      std::string error;
      ASSERT_TRUE(Simulate(sim, seed, &session, &error)) << error;
      Config config;
      config.effects = {h.effect};
      config.calibration.gravity.gravity = session.gravity;
      // The correlated noise makes the pose means scatter beyond their
      // samples' noise (chi2/dof of the magnitudes about 1.7): the pose
      // variance of hand_placed.yaml, with a prior from the simulated noise,
      // for the quadratic term, which rests on the magnitudes alone:
      // flicker 0.664 B sqrt(2) = 1.9e-4 and random walk K sqrt(T / 6) over
      // the 400 s session = 1.6e-4 m/s^2 per pose, 2.5e-4 together.
      config.calibration.refinement.estimate_pose_variance = true;
      config.calibration.refinement.pose_disturbance_prior = 2.5e-4;
      config.calibration.refinement.pose_disturbance_prior_dof = 10.0;
      PipelineInput input;
      input.log = session.log;
      Calibration calibration;
      ASSERT_TRUE(RunCalibration(config, input, &calibration)) << calibration.message;
      ASSERT_EQ(calibration.effects.estimates.size(), 1u);
      const EffectEstimate& e = calibration.effects.estimates[0];
      const std::vector<double> truth = session.effects.Values(e.effect);
      for (size_t p = 0; p < e.values.size(); ++p) {
        check.Add("all", e.values[p] - truth[p], e.std[p]);
        check.Add(e.names[p], e.values[p] - truth[p], e.std[p]);
      }
    }
    std::printf("%s\n%s", ToString(h.effect), check.Table().c_str());
    EXPECT_EQ(check.Count("all"), 90) << ToString(h.effect);
    EXPECT_GT(check.Rms("all"), 0.8) << ToString(h.effect);
    EXPECT_LT(check.Rms("all"), 1.25) << ToString(h.effect);
    check.ExpectHonest(ToString(h.effect));
  }
}

}  // namespace
}  // namespace gravcal
