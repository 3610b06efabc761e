#include "gravcal/methods/thermal_calibration.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "gravcal/simulation/thermal_simulator.h"
#include "gravcal/workflows/acceptance.h"
#include "gravcal/workflows/thermal_discovery.h"

namespace gravcal {
namespace {

// Options matching the simulator's raw units.
ThermalCalibrationOptions OptionsFor(const ThermalSimulatedSession& s) {
  ThermalCalibrationOptions o;
  o.accel_nominal_scale = 1.0 / s.accel_units_per_si;
  o.gyro_nominal_scale = 1.0 / s.gyro_units_per_si;
  return o;
}

bool Calibrate(const ThermalSimulatorOptions& sim, uint64_t seed,
               const ThermalCalibrationOptions* given, ThermalSimulatedSession* truth,
               Calibration* c) {
  std::string error;
  if (!SimulateThermal(sim, seed, truth, &error)) {
    ADD_FAILURE() << error;
    return false;
  }
  Session session;
  session.log = truth->log;
  const ThermalCalibrationOptions o = given != nullptr ? *given : OptionsFor(*truth);
  if (!CalibrateThermal(session, o, c)) {
    ADD_FAILURE() << c->message;
    return false;
  }
  return true;
}

// The raw bias at temperature T: b + db(T - T_ref).
double BiasAt(const AccelModel& a, const GyroModel& g, const ThermalModel& m, ThermalSensor s,
              int axis, double temperature) {
  const double base = s == ThermalSensor::kAccel ? a.bias(axis) : g.bias(axis);
  return base + m.Sensor(s).bias.Value(axis, temperature - m.reference_temperature);
}

// Issue 35, must show: the bias's reported sigma at five temperatures is
// honest over seeds (rms z in [0.7, 1.4]), on multi-pose soak sessions.
TEST(ThermalCalibration, BiasSigmaHonestAtFiveTemperatures) {
  const ThermalSimulatorOptions sim;  // BMI088 magnitudes, soaks -10..50 degC
  double sum_z2 = 0.0;
  int count = 0;
  // GRAVCAL_THERMAL_SEEDS=N runs N seeds instead of the default four (the
  // larger count measured for docs/workflows/thermal.md).
  const char* more = std::getenv("GRAVCAL_THERMAL_SEEDS");
  const int seeds = more != nullptr ? std::max(1, std::atoi(more)) : 4;
  for (uint64_t seed = 11; seed < 11 + static_cast<uint64_t>(seeds); ++seed) {
    ThermalSimulatedSession truth;
    Calibration c;
    ASSERT_TRUE(Calibrate(sim, seed, nullptr, &truth, &c));
    const ThermalModel& m = c.thermal;
    EXPECT_GE(m.accel.bias.order, 1) << c.message;
    for (double temperature : {-5.0, 5.0, 20.0, 35.0, 45.0}) {
      const double x = temperature - m.reference_temperature;
      for (ThermalSensor s : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
        for (int axis = 0; axis < 3; ++axis) {
          const double estimate = BiasAt(c.accel.model, c.gyro.model, m, s, axis, temperature);
          const double want = BiasAt(truth.accel, truth.gyro, truth.thermal, s, axis, temperature);
          const double sigma = m.Sensor(s).bias.Std(axis, x, true);
          ASSERT_TRUE(std::isfinite(sigma) && sigma > 0.0) << ToString(s) << axis;
          const double z = (estimate - want) / sigma;
          sum_z2 += z * z;
          ++count;
        }
      }
    }
  }
  const double rms = std::sqrt(sum_z2 / count);
  RecordProperty("rms_z", std::to_string(rms));
  std::printf("bias rms z over %d values (%d seeds): %.3f\n", count, seeds, rms);
  EXPECT_GE(rms, 0.7);
  EXPECT_LE(rms, 1.4);
}

// Must show: a single pose through a warm-up reports the terms it cannot
// determine as undetermined, never as confident numbers.
TEST(ThermalCalibration, SinglePoseRampReportsUndeterminedTerms) {
  ThermalSimulatorOptions sim;
  sim.profile = ThermalProfile::kWarmUp;
  sim.ramp_seconds = 1200.0;
  ThermalSimulatedSession truth;
  Calibration c;
  ASSERT_TRUE(Calibrate(sim, 21, nullptr, &truth, &c));
  const ThermalPolynomial& bias = c.thermal.accel.bias;
  ASSERT_GE(bias.order, 1) << c.message;
  for (int k = 1; k <= bias.order; ++k) {
    EXPECT_FALSE(bias.Determined(0, k)) << k;
    EXPECT_FALSE(bias.Determined(1, k)) << k;
  }
  EXPECT_TRUE(bias.Determined(2, 1));
  // Scale and misalignment: not determined at any power.
  const ThermalPolynomial& scale = c.thermal.accel.scale;
  for (int i = 0; i < scale.coefficients.rows(); ++i) {
    for (int k = 1; k <= scale.order; ++k) EXPECT_FALSE(scale.Determined(i, k));
  }
  EXPECT_TRUE(std::isnan(c.accel.bias_std(0)));
  EXPECT_TRUE(std::isnan(c.accel.matrix_std(0, 0)));
  ASSERT_FALSE(c.thermal.notes.empty());
  EXPECT_NE(c.thermal.notes[0].find("one static pose"), std::string::npos);
  EXPECT_TRUE(bias.coefficients.allFinite());
}

// Must show: a span too small for the chosen order is named before the
// solve, and the solve stays finite (dRonin#1854).
TEST(ThermalCalibration, SmallSpanIsCaughtAndTheSolveStaysFinite) {
  ThermalCalibrationOptions given;
  given.accel_bias_order = 3;
  const std::vector<std::string> messages = ThermalSpanMessages(6.0, given);
  ASSERT_EQ(messages.size(), 1u);
  EXPECT_EQ(messages[0],
            "your session spans 6.0 degC; the cubic accel bias term needs at least 25.0 degC, or "
            "give order 1");
  ThermalSimulatorOptions sim;
  sim.soak_temperatures = {20.0, 23.0, 26.0};
  ThermalSimulatedSession truth;
  ASSERT_TRUE(SimulateThermal(sim, 31, &truth, nullptr));
  given.accel_nominal_scale = 1.0 / truth.accel_units_per_si;
  given.gyro_nominal_scale = 1.0 / truth.gyro_units_per_si;
  Calibration c;
  ASSERT_TRUE(Calibrate(sim, 31, &given, &truth, &c));
  EXPECT_FALSE(c.warnings.empty());
  const ThermalPolynomial& bias = c.thermal.accel.bias;
  ASSERT_EQ(bias.order, 3);
  EXPECT_TRUE(bias.coefficients.allFinite());
  for (int i = 0; i < 3; ++i) EXPECT_FALSE(bias.Determined(i, 3)) << i;
  // Over the session's range the fitted change stays near the truth's
  // (no exploding coefficients): within 1 mg (10.9 counts) of it.
  for (double temperature : {20.0, 26.0}) {
    for (int axis = 0; axis < 3; ++axis) {
      const double estimate =
          BiasAt(c.accel.model, c.gyro.model, c.thermal, ThermalSensor::kAccel, axis, temperature);
      const double want =
          BiasAt(truth.accel, truth.gyro, truth.thermal, ThermalSensor::kAccel, axis, temperature);
      EXPECT_NEAR(estimate, want, 11.0) << axis << " at " << temperature;
    }
  }
}

// Hysteresis: a warm-up then cool-down through the poses with a 120 s lag
// gets the lag term, near the truth; without a lag it is not chosen.
TEST(ThermalCalibration, LagIsFoundWhereHeatingAndCoolingDisagree) {
  ThermalSimulatorOptions sim;
  sim.profile = ThermalProfile::kWarmCoolPoses;
  sim.ramp_seconds = 1200.0;
  sim.ramp_time_constant = 900.0;
  sim.hold_seconds = 10.0;
  sim.lag_time_constant = 60.0;
  // 50 Hz: the lag and the discovery depend on the windows, not on the
  // rate (half the samples of the default 100 Hz, half the test's time).
  sim.sample_rate = 50.0;
  ThermalSimulatedSession truth;
  Calibration c;
  ASSERT_TRUE(Calibrate(sim, 41, nullptr, &truth, &c));
  ASSERT_TRUE(c.thermal.lag_estimated) << c.message;
  // The fit filters the recorded temperature through the lag itself, so it
  // finds the truth (the small-lag form T - tau dT/dt it used before found
  // the steady response to the exponential ramp, tau 900 / (900 - tau) = 64
  // s).
  EXPECT_NEAR(c.thermal.lag_time_constant, 60.0,
              std::max(3.0, 4.0 * c.thermal.lag_time_constant_std));
  // Discovery (issue 35 part 7) names the hysteresis, and the higher order
  // of the bias (the truth is cubic).
  const ThermalDiscovery found = DiscoverThermal(truth.log, OptionsFor(truth));
  ASSERT_TRUE(found.tried) << found.reason;
  EXPECT_NE(std::find(found.named.begin(), found.named.end(), "thermal_hysteresis"),
            found.named.end());
  EXPECT_NE(std::find(found.named.begin(), found.named.end(), "temperature_higher_order"),
            found.named.end());
  sim.lag_time_constant = 0.0;
  ASSERT_TRUE(Calibrate(sim, 42, nullptr, &truth, &c));
  EXPECT_FALSE(c.thermal.lag_estimated) << c.message;
}

// The uncontrolled warm-up: turned through the poses while it heats, in a
// new order each cycle as a hand does. The bias is right within its sigma
// at three temperatures of the range, and the varied turns determine all
// three of the accelerometer's non-orthogonality entries that six faces
// leave open (the same order every cycle leaves two of them open).
TEST(ThermalCalibration, UncontrolledWarmUpWithPoses) {
  ThermalSimulatorOptions sim;
  sim.shuffle_poses = true;
  sim.profile = ThermalProfile::kWarmUpPoses;
  sim.ramp_seconds = 1500.0;
  sim.ramp_time_constant = 500.0;
  sim.hold_seconds = 10.0;
  ThermalSimulatedSession truth;
  Calibration c;
  ASSERT_TRUE(Calibrate(sim, 51, nullptr, &truth, &c));
  const ThermalModel& m = c.thermal;
  EXPECT_GE(m.accel.bias.order, 1) << c.message;
  EXPECT_GT(m.max_temperature - m.min_temperature, 30.0);
  std::string frame;
  for (const std::string& n : m.notes) {
    if (n.find("non-orthogonality") != std::string::npos) frame += n + "; ";
  }
  EXPECT_NE(frame.find("from the turns: n_xy"), std::string::npos) << frame;
  EXPECT_NE(frame.find("n_yz"), std::string::npos) << frame;
  EXPECT_EQ(frame.find("undetermined"), std::string::npos) << frame;
  for (double temperature : {20.0, 35.0, 50.0}) {
    const double x = temperature - m.reference_temperature;
    for (ThermalSensor s : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
      for (int axis = 0; axis < 3; ++axis) {
        const double z = (BiasAt(c.accel.model, c.gyro.model, m, s, axis, temperature) -
                          BiasAt(truth.accel, truth.gyro, truth.thermal, s, axis, temperature)) /
                         m.Sensor(s).bias.Std(axis, x, true);
        EXPECT_LT(std::abs(z), 4.0) << ToString(s) << axis << " at " << temperature;
      }
    }
  }
}

// Raw counts calibrated with nominal_scale 1 (a config for SI data): the
// fit starts from the data's own scale, says so, and still finds the
// temperature terms; before, every order came out 0 with exit 0.
TEST(ThermalCalibration, NominalScaleFarOffIsNamedAndTheFitStillWorks) {
  const ThermalSimulatorOptions sim;
  ThermalSimulatedSession truth;
  ThermalCalibrationOptions given;  // nominal scales 1: wrong for counts
  Calibration c;
  ASSERT_TRUE(Calibrate(sim, 12, &given, &truth, &c));
  bool named = false;
  for (const std::string& w : c.warnings) named |= w.find("nominal_scale") != std::string::npos;
  EXPECT_TRUE(named) << c.message;
  EXPECT_GE(c.thermal.accel.bias.order, 1) << c.message;
  EXPECT_GE(c.thermal.gyro.bias.order, 1) << c.message;
  ThermalCalibrationOptions right = OptionsFor(truth);
  Calibration reference;
  ASSERT_TRUE(Calibrate(sim, 12, &right, &truth, &reference));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(c.accel.model.bias(i), reference.accel.model.bias(i),
                1e-3 * std::abs(reference.accel.model.bias(i)) + 1e-6);
  }
}

TEST(ThermalCalibration, RefusesALogWithoutTemperature) {
  ThermalSimulatorOptions sim;
  ThermalSimulatedSession truth;
  ASSERT_TRUE(SimulateThermal(sim, 1, &truth, nullptr));
  Session session;
  session.log = truth.log;
  session.log.temperature.clear();
  Calibration c;
  EXPECT_FALSE(CalibrateThermal(session, OptionsFor(truth), &c));
  EXPECT_NE(c.message.find("temperature column"), std::string::npos);
}

}  // namespace
}  // namespace gravcal

namespace gravcal {
namespace {

// Issue 36: a temperature-sensitivity limit. A unit whose accelerometer
// bias tempco is planted ten times larger fails the limit by name, an
// ordinary one passes, the measured sensitivity is the truth's, and a
// calibration without a thermal model leaves the limit not checked.
TEST(ThermalCalibration, TemperatureSensitivityLimitFindsAPlantedUnit) {
  auto truth_sensitivity = [](const ThermalSimulatedSession& t) {
    Calibration c;
    c.thermal = t.thermal;
    c.accel.model = t.accel;
    return ThermalSensitivity(c, ThermalSensor::kAccel);
  };
  ThermalSimulatorOptions sim;
  sim.soak_temperatures = {0.0, 20.0, 40.0};
  sim.hold_seconds = 10.0;
  ThermalSimulatedSession normal_truth, planted_truth;
  Calibration normal, planted;
  ASSERT_TRUE(Calibrate(sim, 5, nullptr, &normal_truth, &normal));
  for (double& c : sim.accel_bias_tempco) c *= 10.0;
  ASSERT_TRUE(Calibrate(sim, 5, nullptr, &planted_truth, &planted));
  const double a = truth_sensitivity(normal_truth), b = truth_sensitivity(planted_truth);
  ASSERT_GT(b, 3.0 * a);
  EXPECT_NEAR(ThermalSensitivity(planted, ThermalSensor::kAccel), b, 0.1 * b);
  AcceptanceLimits limits;
  limits.max_accel_bias_tempco = std::sqrt(a * b);  // mg/K, between the two
  AcceptanceResult pass, fail;
  CheckAcceptance(normal, limits, &pass);
  CheckAcceptance(planted, limits, &fail);
  EXPECT_TRUE(pass.pass) << pass.message;
  EXPECT_FALSE(fail.pass);
  EXPECT_NE(fail.message.find("temperature_sensitivity.accel_bias"), std::string::npos)
      << fail.message;
  // Without a thermal model: listed, not checked, not failed.
  Calibration plain = normal;
  plain.thermal = ThermalModel();
  AcceptanceResult unchecked;
  CheckAcceptance(plain, limits, &unchecked);
  ASSERT_EQ(unchecked.checks.size(), 1u);
  EXPECT_FALSE(unchecked.checks[0].checked);
  EXPECT_TRUE(unchecked.pass);
  // The limits file key.
  AcceptanceLimits read;
  std::string error;
  ASSERT_TRUE(AcceptanceLimitsFromYaml(
      "temperature_sensitivity: {accel_bias: 0.5, gyro_bias: 0.05}", "limits.yaml", &read, &error))
      << error;
  EXPECT_EQ(read.max_accel_bias_tempco, 0.5);
  EXPECT_EQ(read.max_gyro_bias_tempco, 0.05);
  EXPECT_FALSE(AcceptanceLimitsFromYaml("temperature_sensitivity: {accel: 0.5}", "limits.yaml",
                                        &read, &error));
  EXPECT_NE(error.find("temperature_sensitivity.accel"), std::string::npos) << error;
}

}  // namespace
}  // namespace gravcal
