// Issue 21: the rotations between poses as information for the
// accelerometer effects (EffectFitOptions::use_between_pose_rotations), on
// the seed's twelve poses held 30 s with the gyroscope's turns between them
// (3 s each), a warm-up during the session and consumer-MEMS noise with
// bias instability and random walk (as tests/effect_trends_test.cc).
#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <memory>

#include "effect_session.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/effect_fit.h"
#include "gravcal/residuals/accel_rotation_residual.h"
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

// The session's observations with trends and the turns between the poses.
std::vector<StaticObservation> ObservationsWithTurns(const SimulatedSession& session) {
  const std::vector<StaticInterval> intervals = SessionIntervals(session);
  std::vector<StaticObservation> obs = ObservationsFromIntervals(session.log, intervals);
  AddBetweenPoseTurns(session.log, intervals, &obs);
  return obs;
}

// The accelerometer fit with `effects` over `baseline`, with or without the
// rotations between poses.
EffectFitResult Fit(const std::vector<StaticObservation>& obs, const SimulatedSession& session,
                    AccelParameterization baseline, const std::vector<Effect>& effects,
                    bool rotations) {
  EffectFitOptions options;
  options.parameterization = baseline;
  options.effects = effects;
  options.fit_gyro = false;
  options.use_between_pose_rotations = rotations;
  EffectFitResult fit;
  EXPECT_TRUE(FitEffects(obs, Nominal(session), GyroModel(), References(obs), session.gravity,
                         options, &fit))
      << fit.message;
  return fit;
}

// Typical consumer-MEMS sizes (tests/effect_trends_test.cc).
struct HiddenAccelEffect {
  Effect effect;
  double std;
};
const HiddenAccelEffect kHiddenAccel[] = {
    {Effect::kAccelQuadratic, 1.5e-4},
    {Effect::kAccelTemperatureBias, 2e-3},
    {Effect::kAccelTemperatureScale, 1e-4},
    {Effect::kAccelBiasDrift, 8.2e-5},
};

// calibrate --effects on the session; with pose_variance as
// tests/effect_trends_test.cc: the pose variance with a prior from the
// simulated correlated noise.
bool CalibrateWithEffects(const SimulatedSession& session, const std::vector<Effect>& effects,
                          bool pose_variance, Calibration* calibration) {
  Config config;
  config.effects = effects;
  config.calibration.gravity.gravity = session.gravity;
  config.calibration.refinement.estimate_pose_variance = pose_variance;
  config.calibration.refinement.pose_disturbance_prior = pose_variance ? 2.5e-4 : 0.0;
  config.calibration.refinement.pose_disturbance_prior_dof = pose_variance ? 10.0 : 0.0;
  PipelineInput input;
  input.log = session.log;
  return RunCalibration(config, input, calibration);
}

// The residual's autodiff Jacobian against central differences, with every
// effect on and a real turn.
TEST(AccelRotationResidual, JacobianMatchesNumericDifferences) {
  AccelRotationData d;
  for (int i = 0; i <= 40; ++i) {
    const double t = 0.01 * i;
    d.turn.t.push_back(t);
    const double s = std::sin(M_PI * t / 0.4);
    d.turn.gyro.push_back(Eigen::Vector3d(3.0 * s + 0.1, -1.5 * s, 0.5 * s - 0.05));
  }
  d.start_raw = Eigen::Vector3d(0.3, -0.2, 9.7);
  d.end_raw = Eigen::Vector3d(6.8, 0.1, 6.9);
  d.start_temperature_offset = -2.0;
  d.end_temperature_offset = 1.5;
  d.start_time_offset = -40.0;
  d.end_time_offset = 30.0;
  d.tangent = (Eigen::Matrix<double, 2, 3>() << 0.7, 0.0, -0.7, 0.0, 1.0, 0.0).finished();
  d.sqrt_information << 2000.0, 0.0, 150.0, 1800.0;
  std::unique_ptr<ceres::CostFunction> cost(AccelRotationResidual::Create(d));
  double bias[3] = {0.02, -0.03, 0.05};
  double upper[6] = {1.01, 0.002, -0.003, 0.99, 0.001, 1.02};
  std::vector<double> effects = testing_util::EveryAccelEffectOn();
  double gyro_bias[3] = {0.01, -0.02, 0.005};
  double gyro_matrix[9] = {1.0, 0.01, -0.02, 0.005, 0.98, 0.01, -0.01, 0.02, 1.03};
  std::vector<std::vector<double>> jacobians;
  testing_util::ExpectJacobianMatchesCentralDifferences(
      *cost, {bias, upper, effects.data(), gyro_bias, gyro_matrix},
      {3, 6, kAccelEffectParameters, 3, 9}, {1e-6, 1e-6, 1e-8, 1e-6, 1e-6}, 1e-4, &jacobians);
}

// The rows are counted and named; the gyroscope estimated with them is the
// simulated one (in the accelerometer's frame, so compared through M^T M);
// leaving a pose out drops its two turns; without turns the option changes
// nothing and says why.
TEST(EffectRotations, RowsAreCountedAndTheGyroscopeIsRecovered) {
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(TwelvePoseWarmUp(), 1, &session, &error)) << error;
  std::vector<StaticObservation> obs = ObservationsWithTurns(session);
  const EffectFitResult with =
      Fit(obs, session, AccelParameterization::kScaleMisalignment, {Effect::kAccelQuadratic}, true);
  EXPECT_EQ(with.accel_fit.information,
            "position magnitudes + within-pose trends + rotations between poses");
  EXPECT_EQ(with.accel_fit.rotation_residuals, 2 * 11);
  EXPECT_EQ(with.accel_fit.num_residuals, 12 + 3 * 12 + 2 * 11);
  EXPECT_EQ(with.accel_fit.num_parameters, 9 + 3 + 12);
  EXPECT_EQ(with.rotation_residuals.size(), 11u);
  EXPECT_TRUE(with.accel_fit.undetermined.empty());
  const Eigen::Matrix3d m = with.rotation_gyro_matrix;
  const Eigen::Matrix3d truth = session.gyro_truth.matrix;
  EXPECT_LT((m.transpose() * m - truth.transpose() * truth).norm(),
            1e-3 * (truth.transpose() * truth).norm());
  EXPECT_LT((with.rotation_gyro_bias - session.gyro_truth.bias).norm(),
            0.01 * session.gyro_units_per_si);
  const EffectFitResult without = Fit(obs, session, AccelParameterization::kScaleMisalignment,
                                      {Effect::kAccelQuadratic}, false);
  EXPECT_EQ(without.accel_fit.rotation_residuals, 0);
  EXPECT_EQ(without.accel_fit.num_residuals, 12 + 3 * 12);
  EXPECT_TRUE(std::isnan(without.rotation_gyro_matrix(0, 0)));

  // Pose 5 left out: the turns 4 -> 5 and 5 -> 6 go.
  std::vector<StaticObservation> left = obs;
  left.erase(left.begin() + 5);
  const EffectFitResult loo = Fit(left, session, AccelParameterization::kScaleMisalignment,
                                  {Effect::kAccelQuadratic}, true);
  EXPECT_EQ(loo.accel_fit.rotation_residuals, 2 * 9);
  for (const auto& pair : loo.rotation_poses) {
    EXPECT_EQ(left[pair.second].session_index, left[pair.first].session_index + 1);
  }

  // No turns (observations without the log's turns): the same fit as
  // without the option, with a warning.
  std::vector<StaticObservation> bare = obs;
  for (StaticObservation& o : bare) o.has_turn = false;
  const EffectFitResult none = Fit(bare, session, AccelParameterization::kScaleMisalignment,
                                   {Effect::kAccelQuadratic}, true);
  EXPECT_EQ(none.accel_fit.information, "position magnitudes + within-pose trends");
  EXPECT_DOUBLE_EQ(none.accel_fit.chi2, without.accel_fit.chi2);
  ASSERT_EQ(none.warnings.size(), 1u);
  EXPECT_NE(none.warnings[0].find("rotations between poses not used"), std::string::npos);

  EffectFitOptions bad;
  bad.rotation_gyro_bias_variance = -1.0;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("rotation_gyro_bias_variance"), std::string::npos) << error;
}

// What the rotations add. On the seed's twelve positions the magnitudes
// (and the trends, which do not see k2) barely separate the quadratic term
// of the z axis from its bias, scale and non-orthogonality; the
// directions do. And without trends (discovery's path today) the model
// with all four accelerometer effects (21 parameters) is undetermined by
// the twelve magnitudes but determined with the 22 rotation rows.
TEST(EffectRotations, RotationsDetermineWhatMagnitudesCannot) {
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(TwelvePoseWarmUp(), 1, &session, &error)) << error;
  const std::vector<StaticObservation> obs = ObservationsWithTurns(session);
  const EffectFitResult before = Fit(obs, session, AccelParameterization::kScaleMisalignment,
                                     {Effect::kAccelQuadratic}, false);
  const EffectFitResult after =
      Fit(obs, session, AccelParameterization::kScaleMisalignment, {Effect::kAccelQuadratic}, true);
  for (const char* name : {"k2_x", "k2_y", "k2_z"}) {
    const double s0 = before.accel_fit.Std(name);
    const double s1 = after.accel_fit.Std(name);
    std::printf("%s: sigma %.3g -> %.3g with rotations (Fisher information x %.1f)\n", name, s0, s1,
                s0 * s0 / (s1 * s1));
    EXPECT_LE(s1, s0) << name;
  }
  // k2_z: a typical 1.5e-4 is about 1 sigma without the rotations and more
  // than 5 sigma with them.
  EXPECT_GT(before.accel_fit.Std("k2_z"), 1e-4);
  EXPECT_LT(after.accel_fit.Std("k2_z"), 3e-5);

  const std::vector<Effect> all = {Effect::kAccelQuadratic, Effect::kAccelTemperatureBias,
                                   Effect::kAccelTemperatureScale, Effect::kAccelBiasDrift};
  EffectFitOptions options;
  options.effects = all;
  options.fit_gyro = false;
  options.use_within_pose_trends = false;
  EffectFitResult fit;
  EXPECT_FALSE(FitEffects(obs, Nominal(session), GyroModel(), References(obs), session.gravity,
                          options, &fit));
  EXPECT_NE(fit.message.find("needs at least 21"), std::string::npos) << fit.message;
  options.use_between_pose_rotations = true;
  ASSERT_TRUE(FitEffects(obs, Nominal(session), GyroModel(), References(obs), session.gravity,
                         options, &fit))
      << fit.message;
  EXPECT_TRUE(fit.accel_fit.undetermined.empty());
  EXPECT_EQ(fit.accel_fit.dof(), 12 + 22 - 21 - 12);
  std::printf("all four effects, magnitudes + rotations: dof %d, sigmas", fit.accel_fit.dof());
  for (const EffectEstimate& e : fit.estimates) {
    for (size_t p = 0; p < e.std.size(); ++p) {
      std::printf(" %s %.2g", e.names[p].c_str(), e.std[p]);
      EXPECT_TRUE(std::isfinite(e.std[p])) << e.names[p];
    }
  }
  std::printf("\n");
}

// The weights: over 40 seeds with no hidden effect the rotation rows'
// chi2 is near what they leave after the gyroscope's 12 parameters.
TEST(EffectRotations, RotationWeightsMatchTheScatter) {
  double sum = 0.0;
  const int seeds = 40;
  for (int seed = 1; seed <= seeds; ++seed) {
    SimulatedSession session;
    std::string error;
    ASSERT_TRUE(Simulate(TwelvePoseWarmUp(), seed, &session, &error)) << error;
    const std::vector<StaticObservation> obs = ObservationsWithTurns(session);
    sum += Fit(obs, session, AccelParameterization::kScaleMisalignment, {}, true)
               .accel_fit.rotation_chi2;
  }
  const double mean = sum / seeds;
  std::printf("mean rotation chi2 %.2f (22 rows, 12 gyroscope parameters)\n", mean);
  EXPECT_GT(mean, 0.7 * 10.0);
  EXPECT_LT(mean, 1.3 * 10.0);
}

// A hidden k2 of typical size: with the rotations its z component is
// estimated with an honest sigma and found; the likelihood-ratio test of
// each effect over the baseline with the rotations finds nothing when
// nothing is hidden.
TEST(EffectRotations, NoFalseEffectWithoutAHiddenOne) {
  int quiet[4] = {0, 0, 0, 0};
  for (int seed = 101; seed <= 120; ++seed) {
    SimulatedSession session;
    std::string error;
    ASSERT_TRUE(Simulate(TwelvePoseWarmUp(), seed, &session, &error)) << error;
    const std::vector<StaticObservation> obs = ObservationsWithTurns(session);
    const SensorFitSummary base =
        Fit(obs, session, AccelParameterization::kScaleMisalignment, {}, true).accel_fit;
    for (int i = 0; i < 4; ++i) {
      const SensorFitSummary ext = Fit(obs, session, AccelParameterization::kScaleMisalignment,
                                       {kHiddenAccel[i].effect}, true)
                                       .accel_fit;
      const double p =
          ChiSquareUpperTail(base.chi2 - ext.chi2, ext.num_parameters - base.num_parameters);
      if (p >= kCandidateLevel) ++quiet[i];
    }
  }
  for (int i = 0; i < 4; ++i) {
    std::printf("%s: not significant in %d of 20\n", ToString(kHiddenAccel[i].effect), quiet[i]);
    EXPECT_GE(quiet[i], 19) << ToString(kHiddenAccel[i].effect);
  }
}

// calibrate --effects (RunCalibration), which uses the rotations when the
// log has a gyroscope, with all four accelerometer effects hidden and
// estimated together (12 parameters; tests/effect_trends_test.cc checks
// each alone, now also with the rotations): error / reported sigma over 30
// seeds, rms in [0.8, 1.25] and within the honest band, k2_z among them.
TEST(EffectRotations, CalibrateEstimatesAllFourEffectsWithHonestSigmas) {
  SimulatorOptions sim = TwelvePoseWarmUp();
  for (const HiddenAccelEffect& h : kHiddenAccel) sim = WithHidden(sim, h.effect, h.std);
  testing_util::SigmaCheck check;
  for (int seed = 1; seed <= 30; ++seed) {
    SimulatedSession session;
    std::string error;
    ASSERT_TRUE(Simulate(sim, seed, &session, &error)) << error;
    std::vector<Effect> effects;
    for (const HiddenAccelEffect& h : kHiddenAccel) effects.push_back(h.effect);
    Calibration calibration;
    ASSERT_TRUE(CalibrateWithEffects(session, effects, true, &calibration)) << calibration.message;
    EXPECT_NE(calibration.message.find("rotations between poses"), std::string::npos)
        << calibration.message;
    ASSERT_EQ(calibration.effects.estimates.size(), 4u);
    for (const EffectEstimate& e : calibration.effects.estimates) {
      const std::vector<double> truth = session.effects.Values(e.effect);
      for (size_t p = 0; p < e.values.size(); ++p) {
        check.Add("all", e.values[p] - truth[p], e.std[p]);
        check.Add(ToString(e.effect), e.values[p] - truth[p], e.std[p]);
        check.Add(e.names[p], e.values[p] - truth[p], e.std[p]);
      }
    }
  }
  std::printf("%s", check.Table().c_str());
  EXPECT_EQ(check.Count("all"), 360);
  for (const HiddenAccelEffect& h : kHiddenAccel) {
    EXPECT_GT(check.Rms(ToString(h.effect)), 0.8) << ToString(h.effect);
    EXPECT_LT(check.Rms(ToString(h.effect)), 1.25) << ToString(h.effect);
  }
  check.ExpectHonest("all four effects");
}

// Hidden gyroscope effects: the bias drift and temperature bias are taken
// out by the turns' local level at rest (the mean of the two poses' static
// means), so no accelerometer effect is named; a g-sensitivity is not
// modelled in the turns: the rows exceed their noise and the fit says so,
// and calibrate --effects then fits without them.
TEST(EffectRotations, HiddenGyroscopeEffectsAreNotTakenForAccelerometerOnes) {
  for (int which = 0; which < 3; ++which) {
    SimulatorOptions sim = TwelvePoseWarmUp();
    // 0.01 deg/s/K, 0.03 deg/s/min, 0.05 deg/s/g (discovery_test.cc).
    if (which == 0) sim.effect_std[Effect::kGyroTemperatureBias] = 1.7e-4;
    if (which == 1) sim.effect_std[Effect::kGyroBiasDrift] = 1e-5;
    if (which == 2) sim.effect_std[Effect::kGyroGSensitivity] = 9e-5;
    int significant = 0, warned = 0;
    for (int seed = 1; seed <= 10; ++seed) {
      SimulatedSession session;
      std::string error;
      ASSERT_TRUE(Simulate(sim, seed, &session, &error)) << error;
      const std::vector<StaticObservation> obs = ObservationsWithTurns(session);
      const EffectFitResult base =
          Fit(obs, session, AccelParameterization::kScaleMisalignment, {}, true);
      if (!base.warnings.empty()) ++warned;
      for (const HiddenAccelEffect& h : kHiddenAccel) {
        const SensorFitSummary ext =
            Fit(obs, session, AccelParameterization::kScaleMisalignment, {h.effect}, true)
                .accel_fit;
        if (ChiSquareUpperTail(base.accel_fit.chi2 - ext.chi2, 3) < kCandidateLevel) ++significant;
      }
      if (which == 2 && seed == 1) {
        Calibration calibration;
        ASSERT_TRUE(CalibrateWithEffects(session, {Effect::kAccelQuadratic}, false, &calibration))
            << calibration.message;
        EXPECT_EQ(calibration.message.find("rotations between poses"), std::string::npos)
            << calibration.message;
        bool said = false;
        for (const std::string& w : calibration.warnings) {
          said = said || w.find("exceed their noise") != std::string::npos;
        }
        EXPECT_TRUE(said);
      }
    }
    std::printf(
        "gyroscope effect %d: %d of 40 accelerometer tests significant, warned in %d of 10\n",
        which, significant, warned);
    if (which < 2) {
      EXPECT_LE(significant, 2);
      EXPECT_LE(warned, 1);
    } else {
      EXPECT_GE(warned, 9);
    }
  }
}

}  // namespace
}  // namespace gravcal
