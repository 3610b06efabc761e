// The effect catalogue's terms and the fit of the model with effects:
// forward/inverse round trips, a Jacobian check, estimates against simulator
// truth with honest standard deviations, and bad input.
#include "gravcal/methods/effect_fit.h"

#include <ceres/autodiff_cost_function.h>
#include <gtest/gtest.h>

#include <map>
#include <random>

#include "gravcal/residuals/gravity_magnitude_residual.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "sigma_check.h"
#include "test_util.h"
#include "util/statistics.h"

namespace gravcal {

using internal::FUpperTail;

namespace {

EffectParameters RandomParameters(std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  auto v = [&](double s) -> Eigen::Vector3d {
    return Eigen::Vector3d(n(*rng), n(*rng), n(*rng)) * s;
  };
  EffectParameters p;
  p.Vector(Effect::kAccelQuadratic) = v(2e-4);
  p.Vector(Effect::kAccelTemperatureBias) = v(0.01);
  p.Vector(Effect::kAccelTemperatureScale) = v(3e-4);
  p.Vector(Effect::kAccelBiasDrift) = v(1e-4);
  p.reference_temperature = 25.0;
  p.reference_time = 100.0;
  return p;
}

std::vector<Effect> AllAccelEffects() {
  return {Effect::kAccelQuadratic, Effect::kAccelTemperatureBias, Effect::kAccelTemperatureScale,
          Effect::kAccelBiasDrift};
}

TEST(ModelEffects, CorrectionInvertsTheSensorModel) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 200; ++i) {
    const EffectParameters p = RandomParameters(&rng);
    const Eigen::Vector3d s = 9.8 * testing_util::RandomDirection(&rng);
    const double temperature = 15.0 + 0.1 * i;
    const double time = 3.0 * i;
    const Eigen::Vector3d m = ApplyAccelEffects(p, s, temperature, time);
    Eigen::Vector3d a;
    ASSERT_TRUE(CorrectAccel(p, AllAccelEffects(), m, temperature, time, &a));
    EXPECT_LT((a - s).norm(), 1e-12);
    EXPECT_GT((m - s).norm(), 0.0);
  }
}

TEST(ModelEffects, ZeroParametersAndUnknownTemperatureAreTheIdentity) {
  EffectParameters zero;
  const Eigen::Vector3d s(1.0, -2.0, 9.0);
  EXPECT_EQ(ApplyAccelEffects(zero, s, 40.0, 50.0), s);
  std::mt19937_64 rng(4);
  EffectParameters p = RandomParameters(&rng);
  p.Vector(Effect::kAccelQuadratic).setZero();
  p.Vector(Effect::kAccelBiasDrift).setZero();
  // No temperature column: the temperature terms are off.
  EXPECT_EQ(ApplyAccelEffects(p, s, NAN, p.reference_time), s);
}

TEST(ModelEffects, NamesRoundTripAndUnknownNamesAreErrors) {
  for (const EffectInfo& info : EffectCatalogue()) {
    Effect e;
    ASSERT_TRUE(FromString(info.name, &e));
    EXPECT_EQ(e, info.effect);
    EXPECT_EQ(static_cast<int>(info.parameter_names.size()), info.num_parameters);
  }
  std::vector<Effect> effects;
  std::string error;
  EXPECT_TRUE(ParseEffects({"accel_bias_drift", "accel_bias_drift"}, &effects, &error));
  EXPECT_EQ(effects.size(), 1u);
  EXPECT_FALSE(ParseEffects({"accel_bias_drfit"}, &effects, &error));
  EXPECT_NE(error.find("accel_bias_drfit"), std::string::npos) << error;
  EXPECT_NE(error.find("accel_bias_drift"), std::string::npos) << error;
}

// The autodiff Jacobian of the residual against central differences.
TEST(EffectResidual, JacobianMatchesNumericDifferences) {
  std::mt19937_64 rng(5);
  const EffectParameters p = RandomParameters(&rng);
  const Eigen::Vector3d raw(310.0, -1200.0, 15800.0);
  std::unique_ptr<ceres::CostFunction> cost(
      GravityMagnitudeResidual::CreateWithEffects(raw, 6.0, -40.0, 9.81, 0.001));
  double bias[3] = {20.0, -30.0, 45.0};
  double upper[6] = {6.0e-4, 2e-6, -3e-6, 6.1e-4, 1e-6, 5.9e-4};
  // The effects' block in the registry's layout (core/effect_registry.h).
  double effects[kAccelEffectParameters];
  std::copy(p.accel.begin(), p.accel.end(), effects);
  double* params[3] = {bias, upper, effects};
  const int sizes[3] = {3, 6, kAccelEffectParameters};
  std::vector<double> steps[3] = {std::vector<double>(3, 1e-3), std::vector<double>(6, 1e-10),
                                  std::vector<double>(kAccelEffectParameters, 1e-6)};
  for (int i = 0; i < 3; ++i) {
    steps[2][effects::kLayout.offset[static_cast<int>(Effect::kAccelQuadratic)] + i] = 1e-5;
  }
  double r;
  double jac[3][kAccelEffectParameters > 6 ? kAccelEffectParameters : 6];
  double* jacobians[3] = {jac[0], jac[1], jac[2]};
  ASSERT_TRUE(cost->Evaluate(params, &r, jacobians));
  for (int b = 0; b < 3; ++b) {
    for (int i = 0; i < sizes[b]; ++i) {
      const double x = params[b][i];
      // Steps that move |a| by 1e-7 m/s^2 or more: large enough for the
      // rounding of |a| (about 1e-15 m/s^2), small enough for the curvature.
      const double h = steps[b][i];
      double rp, rm;
      params[b][i] = x + h;
      cost->Evaluate(params, &rp, nullptr);
      params[b][i] = x - h;
      cost->Evaluate(params, &rm, nullptr);
      params[b][i] = x;
      const double numeric = (rp - rm) / (2.0 * h);
      EXPECT_NEAR(jac[b][i], numeric, 1e-5 * std::max(1.0, std::fabs(jac[b][i])))
          << "block " << b << " entry " << i;
    }
  }
}

TEST(Statistics, FUpperTailMatchesKnownValues) {
  // Values from the F distribution tables.
  EXPECT_NEAR(FUpperTail(3.8625, 3, 20), 0.025, 2e-4);
  EXPECT_NEAR(FUpperTail(2.0, 9, 27), 0.0794, 5e-4);
  EXPECT_NEAR(FUpperTail(1.0, 5, 5), 0.5, 1e-12);
  // F(1, d) is the square of Student's t: P(F > t^2) = 2 P(T > t).
  EXPECT_NEAR(FUpperTail(2.228 * 2.228, 1, 10), 0.05, 2e-4);
}

// (estimate - truth) / std of every parameter of every effect calibrate
// fits on simulated sessions with `sim`'s effects, per parameter.
// Gyroscope truths are in raw gyroscope units: M_g^-1 G R for G (R the
// accelerometer's housing rotation, since f = R a), M_g^-1 gamma for the
// tempco.
testing_util::SigmaCheck ErrorOverSigma(const SimulatorOptions& sim,
                                        const std::vector<Effect>& effects, int seeds) {
  testing_util::SigmaCheck check;
  for (int seed = 1; seed <= seeds; ++seed) {
    SimulatedSession session;
    std::string error;
    EXPECT_TRUE(Simulate(sim, seed, &session, &error)) << error;
    Config config;
    config.effects = effects;
    config.calibration.gravity.gravity = session.gravity;
    PipelineInput input;
    input.log = session.log;
    Calibration calibration;
    EXPECT_TRUE(RunCalibration(config, input, &calibration)) << calibration.message;
    const Eigen::Matrix3d gyro_inverse = session.gyro_truth.matrix.inverse();
    const Eigen::Matrix3d g_truth =
        gyro_inverse * session.gyro_g_sensitivity * session.accel_truth.rotation;
    for (const EffectEstimate& e : calibration.effects.estimates) {
      std::vector<double> truth = session.effects.Values(e.effect);
      if (e.effect == Effect::kGyroGSensitivity) {
        truth.clear();
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 3; ++c) truth.push_back(g_truth(r, c));
        }
      } else if (e.effect == Effect::kGyroTemperatureBias) {
        const Eigen::Vector3d t =
            gyro_inverse * session.effects.Vector(Effect::kGyroTemperatureBias);
        truth = {t(0), t(1), t(2)};
      } else if (e.effect == Effect::kGyroBiasDrift) {
        const Eigen::Vector3d t = gyro_inverse * session.effects.Vector(Effect::kGyroBiasDrift);
        truth = {t(0), t(1), t(2)};
      }
      for (size_t i = 0; i < e.values.size(); ++i) {
        check.Add(std::string(ToString(e.effect)) + "." + e.names[i], e.values[i] - truth[i],
                  e.std[i]);
      }
    }
  }
  std::printf("%s", check.Table().c_str());
  return check;
}

// calibrate with effects: the estimates agree with the truth within the
// reported standard deviations (every parameter inside SigmaCheck's band
// over 30 seeds).
TEST(EffectFit, CalibrateEstimatesEffectsWithHonestSigmas) {
  SimulatorOptions sim = testing_util::WarmUpSession();
  sim.effect_std[Effect::kAccelTemperatureBias] = 0.005;
  sim.effect_std[Effect::kGyroGSensitivity] = 1.8e-4;
  const testing_util::SigmaCheck check =
      ErrorOverSigma(sim, {Effect::kAccelTemperatureBias, Effect::kGyroGSensitivity}, 30);
  EXPECT_EQ(check.Names().size(), 3u + 9u);
  check.ExpectHonest("effects");
}

TEST(EffectFit, CalibrateEstimatesThreeAccelAndTwoGyroEffectsWithHonestSigmas) {
  SimulatorOptions sim = testing_util::WarmUpSession();
  sim.effect_std[Effect::kAccelQuadratic] = 1.5e-4;
  sim.effect_std[Effect::kAccelTemperatureScale] = 1e-4;
  sim.effect_std[Effect::kAccelBiasDrift] = 8e-5;
  sim.effect_std[Effect::kGyroTemperatureBias] = 1.7e-4;
  sim.effect_std[Effect::kGyroBiasDrift] = 1e-5;
  const testing_util::SigmaCheck check = ErrorOverSigma(
      sim,
      {Effect::kAccelQuadratic, Effect::kAccelTemperatureScale, Effect::kAccelBiasDrift,
       Effect::kGyroTemperatureBias, Effect::kGyroBiasDrift},
      30);
  EXPECT_EQ(check.Names().size(), 5u * 3u);
  check.ExpectHonest("effects");
}

// Issue 32: the fit with effects honours the solver section. One pose
// pushed 0.05 m/s^2 along its specific force moves the least-squares bias
// by several of its standard deviations; a Cauchy loss gives the clean
// session's bias back without effects (the refinement) and, as it must,
// with them (the effect fit, which used to add its residuals with no loss
// whatever the config said).
TEST(EffectFit, RobustLossResistsADisturbedPoseAsThePlainFitDoes) {
  // Twenty poses: with twelve for nine parameters every pose has a leverage
  // near 0.75, and no loss can tell a disturbed one from the rest.
  SimulatorOptions sim;
  sim.scheme = {PoseScheme::kRandom, 20};
  sim.hold_seconds = 30.0;  // long enough for the within-pose trends
  SimulatedSession clean;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 5, &clean, &error)) << error;
  SimulatedSession disturbed = clean;
  const SimulatedPose& pose = disturbed.poses[5];
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (size_t i = pose.begin; i < pose.end; ++i) mean += disturbed.log.accel[i];
  const Eigen::Vector3d push =
      (0.05 * disturbed.accel_units_per_si * mean.normalized()).array().round().matrix();
  for (size_t i = pose.begin; i < pose.end; ++i) disturbed.log.accel[i] += push;

  struct Fit {
    Eigen::Vector3d bias, std;
  };
  auto fit = [](const SimulatedSession& s, const std::vector<Effect>& effects, LossType loss) {
    Config config;
    config.effects = effects;
    config.calibration.gravity.gravity = s.gravity;
    config.calibration.refinement.loss = loss;
    PipelineInput input;
    input.log = s.log;
    Calibration c;
    EXPECT_TRUE(RunCalibration(config, input, &c)) << c.message;
    EXPECT_TRUE(c.accel.bias_std.allFinite()) << c.message;
    return Fit{c.accel.model.bias, c.accel.bias_std};
  };
  for (const std::vector<Effect>& effects :
       {std::vector<Effect>{}, std::vector<Effect>{Effect::kAccelBiasDrift}}) {
    const Fit reference = fit(clean, effects, LossType::kNone);
    const Fit plain = fit(disturbed, effects, LossType::kNone);
    const Fit robust = fit(disturbed, effects, LossType::kCauchy);
    // The largest bias change over the axes, in counts and in sigmas.
    const double moved = (plain.bias - reference.bias).cwiseAbs().maxCoeff();
    const double restored = (robust.bias - reference.bias).cwiseAbs().maxCoeff();
    const double sigma = reference.std.maxCoeff();
    std::printf("%s: the disturbed pose moves the bias %.3g counts (%.3g sigma); cauchy %.3g\n",
                effects.empty() ? "no effects" : "accel_bias_drift", moved, moved / sigma,
                restored);
    EXPECT_GT(moved, 4.0 * sigma) << "the planted pose must matter";
    // Down-weighted, not removed, and one pose fewer: within 2 sigma of the
    // clean session (measured: 0.12 counts without effects, 0.56 = 1.3
    // sigma with the drift, against 7.7 and 24 counts moved).
    EXPECT_LT(restored, 0.1 * moved);
    EXPECT_LT(restored, 2.0 * sigma);
  }
}

// Issue 32's leftover: the gyroscope part of the effect fit honours the
// robust loss as the accelerometer part does. Twenty poses at rest whose mean
// rates scatter by their own noise about b_g, one pushed 100 sigma on x:
// least squares moves b_g by a twentieth of the push; a Cauchy loss keeps
// it within 2 sigma of the truth and says so in the fit's information.
TEST(EffectFit, GyroPartHonoursTheRobustLoss) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> unit(0.0, 1.0);
  const Eigen::Vector3d truth(3.0, -2.0, 1.5);
  const double sigma = 0.01;  // of each pose's mean rate, raw units
  std::vector<StaticObservation> observations(20);
  for (size_t k = 0; k < observations.size(); ++k) {
    StaticObservation& o = observations[k];
    o.accel.raw_mean = 9.81 * testing_util::RandomDirection(&rng);
    o.accel.raw_mean_cov = 1e-6 * Eigen::Matrix3d::Identity();
    o.accel.sample_count = 1000;
    o.accel.t_begin = 40.0 * k;
    o.accel.t_end = o.accel.t_begin + 30.0;
    o.has_gyro = true;
    o.gyro_mean = truth + sigma * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    o.gyro_mean_cov = sigma * sigma * Eigen::Matrix3d::Identity();
  }
  observations[7].gyro_mean.x() += 100.0 * sigma;
  auto fit = [&](LossType loss) {
    EffectFitOptions options;
    options.fit_accel = false;
    options.loss = loss;
    EffectFitResult result;
    EXPECT_TRUE(FitEffects(observations, AccelModel(), GyroModel(), EffectParameters(), 9.81,
                           options, &result))
        << result.message;
    return result;
  };
  const EffectFitResult plain = fit(LossType::kNone);
  const EffectFitResult robust = fit(LossType::kCauchy);
  const double bias_sigma = sigma / std::sqrt(20.0);
  EXPECT_GT(std::abs(plain.gyro.bias.x() - truth.x()), 10.0 * bias_sigma);
  EXPECT_LT((robust.gyro.bias - truth).cwiseAbs().maxCoeff(), 2.0 * bias_sigma)
      << robust.gyro.bias.transpose();
  EXPECT_EQ(plain.gyro_fit.information, "static mean rates");
  EXPECT_EQ(robust.gyro_fit.information, "static mean rates (cauchy loss)");
  // The covariance counts the set-aside pose as the solve did: b_g's sigma
  // stays near that of the nineteen clean poses.
  EXPECT_LT(robust.gyro_bias_std.x(), 1.5 * bias_sigma);
}

// covariance: false holds with effects too: the same estimates, and no
// standard deviations or covariance (they were computed and written).
TEST(EffectFit, CovarianceFalseHoldsForTheFitWithEffects) {
  SimulatorOptions sim = testing_util::WarmUpSession();
  sim.effect_std[Effect::kAccelTemperatureBias] = 0.005;
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 2, &session, &error)) << error;
  Config config;
  config.effects = {Effect::kAccelTemperatureBias};
  config.calibration.gravity.gravity = session.gravity;
  PipelineInput input;
  input.log = session.log;
  Calibration with, without;
  ASSERT_TRUE(RunCalibration(config, input, &with)) << with.message;
  config.calibration.refinement.compute_covariance = false;
  ASSERT_TRUE(RunCalibration(config, input, &without)) << without.message;
  EXPECT_TRUE(with.accel.bias_std.allFinite());
  EXPECT_GT(with.accel.covariance.size(), 0);
  EXPECT_FALSE(without.accel.bias_std.array().isFinite().any()) << without.accel.bias_std;
  EXPECT_EQ(without.accel.covariance.size(), 0);
  EXPECT_LT((with.accel.model.bias - without.accel.model.bias).norm(),
            1e-6 * with.accel.model.bias.norm() + 1e-9);
}

TEST(EffectFit, EffectsTheLogCannotSupportFailWithTheirName) {
  SimulatorOptions sim;
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 1, &session, &error)) << error;
  Config config;
  config.calibration.gravity.gravity = session.gravity;
  PipelineInput input;
  input.log = session.log;
  input.log.temperature.clear();
  config.effects = {Effect::kAccelTemperatureScale};
  Calibration c;
  EXPECT_FALSE(RunCalibration(config, input, &c));
  EXPECT_NE(c.message.find("accel_temperature_scale"), std::string::npos) << c.message;
  EXPECT_NE(c.message.find("temperature"), std::string::npos) << c.message;

  // Constant temperature: the tempco is not determined by the positions.
  input.log = session.log;
  Calibration d;
  EXPECT_FALSE(RunCalibration(config, input, &d));
  EXPECT_NE(d.message.find("do not determine"), std::string::npos) << d.message;

  // Twelve magnitudes cannot carry 9 + 3 + 3 accelerometer parameters, but
  // the within-pose trends determine the drift, so calibrate fits them (the
  // magnitude-only refusal is tested in effect_trends_test.cc).
  config.effects = {Effect::kAccelQuadratic, Effect::kAccelBiasDrift};
  Calibration e;
  EXPECT_TRUE(RunCalibration(config, input, &e)) << e.message;
  EXPECT_EQ(e.effects.estimates.size(), 2u);
}

}  // namespace
}  // namespace gravcal
