// The effect catalogue's terms and the fit of the model with effects:
// forward/inverse round trips, a Jacobian check, estimates against simulator
// truth with honest standard deviations, and bad input.
#include "gravcal/effect_fit.h"

#include <ceres/autodiff_cost_function.h>
#include <gtest/gtest.h>

#include <random>

#include "effect_residual.h"
#include "gravcal/config.h"
#include "gravcal/pipeline.h"
#include "gravcal/simulator.h"
#include "statistics.h"
#include "test_util.h"

namespace gravcal {
namespace {

EffectParameters RandomParameters(std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  auto v = [&](double s) -> Eigen::Vector3d {
    return Eigen::Vector3d(n(*rng), n(*rng), n(*rng)) * s;
  };
  EffectParameters p;
  p.accel_quadratic = v(2e-4);
  p.accel_temperature_bias = v(0.01);
  p.accel_temperature_scale = v(3e-4);
  p.accel_bias_drift = v(1e-4);
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
  p.accel_quadratic.setZero();
  p.accel_bias_drift.setZero();
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
      AccelEffectResidual::Create(raw, 6.0, -40.0, 9.81, 0.001));
  double bias[3] = {20.0, -30.0, 45.0};
  double upper[6] = {6.0e-4, 2e-6, -3e-6, 6.1e-4, 1e-6, 5.9e-4};
  double blocks[4][3];
  const Eigen::Vector3d* values[4] = {&p.accel_quadratic, &p.accel_temperature_bias,
                                      &p.accel_temperature_scale, &p.accel_bias_drift};
  for (int b = 0; b < 4; ++b) {
    for (int i = 0; i < 3; ++i) blocks[b][i] = (*values[b])(i);
  }
  double* params[6] = {bias, upper, blocks[0], blocks[1], blocks[2], blocks[3]};
  const int sizes[6] = {3, 6, 3, 3, 3, 3};
  const double kStep[6] = {1e-3, 1e-10, 1e-5, 1e-6, 1e-6, 1e-6};
  double r;
  double jac[6][6];
  double* jacobians[6] = {jac[0], jac[1], jac[2], jac[3], jac[4], jac[5]};
  ASSERT_TRUE(cost->Evaluate(params, &r, jacobians));
  for (int b = 0; b < 6; ++b) {
    for (int i = 0; i < sizes[b]; ++i) {
      const double x = params[b][i];
      // Steps that move |a| by 1e-7 m/s^2 or more: large enough for the
      // rounding of |a| (about 1e-15 m/s^2), small enough for the curvature.
      const double h = kStep[b];
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

// calibrate with effects on simulated sessions: the estimates agree with
// the truth within the reported standard deviations (rms of error / std in
// [0.7, 1.4] over 30 seeds) for the accelerometer bias tempco and the
// gyroscope g-sensitivity (in raw gyroscope units per m/s^2: M_g^-1 G R,
// R the accelerometer's housing rotation, since f = R a).
TEST(EffectFit, CalibrateEstimatesEffectsWithHonestSigmas) {
  Config config;
  config.effects = {Effect::kAccelTemperatureBias, Effect::kGyroGSensitivity};
  SimulatorOptions& sim = config.simulation;
  sim.scheme = "random:24";
  sim.hold_seconds = 10.0;
  sim.rotation_seconds = 2.0;
  sim.temperature_start = 20.0;
  sim.temperature_end = 35.0;
  sim.temperature_tau = 120.0;
  sim.accel_temperature_bias_std = 0.005;
  sim.gyro_g_sensitivity_std = 1.8e-4;
  const int seeds = 30;
  double beta_ratio = 0.0, g_ratio = 0.0;
  int beta_count = 0, g_count = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    SimulatedSession session;
    std::string error;
    ASSERT_TRUE(Simulate(sim, seed, &session, &error)) << error;
    Config c = config;
    c.calibration.gravity.gravity = session.gravity;
    PipelineInput input;
    input.log = session.log;
    Calibration calibration;
    ASSERT_TRUE(RunCalibration(c, input, &calibration)) << calibration.message;
    ASSERT_EQ(calibration.effects.estimates.size(), 2u);
    const Eigen::Matrix3d g_truth = session.gyro_truth.matrix.inverse() *
                                    session.gyro_g_sensitivity * session.accel_truth.rotation;
    for (const EffectEstimate& e : calibration.effects.estimates) {
      for (size_t i = 0; i < e.values.size(); ++i) {
        ASSERT_TRUE(std::isfinite(e.std[i])) << e.names[i];
        if (e.effect == Effect::kAccelTemperatureBias) {
          const double z = (e.values[i] - session.effects.accel_temperature_bias(i)) / e.std[i];
          beta_ratio += z * z;
          ++beta_count;
        } else {
          const double z = (e.values[i] - g_truth(i / 3, i % 3)) / e.std[i];
          g_ratio += z * z;
          ++g_count;
        }
      }
    }
    EXPECT_TRUE(calibration.gyro.estimated);
  }
  beta_ratio = std::sqrt(beta_ratio / beta_count);
  g_ratio = std::sqrt(g_ratio / g_count);
  std::printf("rms error/std: accel_temperature_bias %.3f, gyro_g_sensitivity %.3f\n", beta_ratio,
              g_ratio);
  EXPECT_GT(beta_ratio, 0.7);
  EXPECT_LT(beta_ratio, 1.4);
  EXPECT_GT(g_ratio, 0.7);
  EXPECT_LT(g_ratio, 1.4);
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

  // Twelve positions cannot carry 9 + 3 + 3 accelerometer parameters.
  config.effects = {Effect::kAccelQuadratic, Effect::kAccelBiasDrift};
  Calibration e;
  EXPECT_FALSE(RunCalibration(config, input, &e));
  EXPECT_NE(e.message.find("needs at least 15"), std::string::npos) << e.message;
}

}  // namespace
}  // namespace gravcal
