#include "gravcal/handheld_kalman.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "gravcal/calibration_io.h"
#include "gravcal/handheld_simulator.h"
#include "test_util.h"

namespace gravcal {
namespace {

// The sensor the filter's model describes: bias and scale, no cross-axis
// terms; SI units; consumer MEMS noise (simulator defaults).
SimulatorOptions FilterSensor() {
  SimulatorOptions sensor;
  sensor.raw_counts = false;
  sensor.accel_misalignment_std = 0.0;
  sensor.gyro_misalignment_std = 0.0;
  sensor.accel_bias_std = 0.2;
  sensor.gyro_bias_std = 0.02;
  return sensor;
}

// Filter settings matching the simulated sensor (noise per sample / sqrt of
// the rate) and gravity.
HandheldKalmanOptions MatchingOptions(const SimulatorOptions& sensor) {
  HandheldKalmanOptions options;
  options.gravity.gravity = sensor.gravity;
  options.accel_noise_density = sensor.accel_noise / std::sqrt(sensor.sample_rate);
  options.gyro_noise_density = sensor.gyro_noise / std::sqrt(sensor.sample_rate);
  return options;
}

// The 12 truth values in the filter's state order (accel bias, accel scale,
// gyro bias, gyro scale), SI units.
std::vector<double> TruthVector(const SimulatedSession& session) {
  const SensorErrorTruth t = ErrorTruth(session);
  std::vector<double> v;
  for (int i = 0; i < 3; ++i) v.push_back(t.accel_bias(i));
  for (int i = 0; i < 3; ++i) v.push_back(t.accel_e(i, i));
  for (int i = 0; i < 3; ++i) v.push_back(t.gyro_bias(i));
  for (int i = 0; i < 3; ++i) v.push_back(t.gyro_e(i, i));
  return v;
}

struct MonteCarlo {
  std::vector<double> sum_z2 = std::vector<double>(12, 0.0);
  std::vector<double> max_z = std::vector<double>(12, 0.0);
  std::vector<double> max_convergence = std::vector<double>(12, 0.0);
  std::vector<std::string> names;
  int runs = 0;
};

// Simulates and calibrates seeds [1, seeds]; every run must succeed with
// every state determined.
void RunMonteCarlo(const SimulatorOptions& sensor, const MotionOptions& motion,
                   const HandheldKalmanOptions& options, int seeds, MonteCarlo* mc) {
  for (int seed = 1; seed <= seeds; ++seed) {
    MotionSession s;
    std::string error;
    ASSERT_TRUE(SimulateMotion(sensor, motion, seed, &s, &error)) << error;
    Calibration c;
    ASSERT_TRUE(CalibrateHandheld(s.sensor.log, options, &c)) << c.message;
    const std::vector<double> truth = TruthVector(s.sensor);
    ASSERT_EQ(c.convergence.entries.size(), 12u);
    for (int j = 0; j < 12; ++j) {
      const ConvergenceEntry& e = c.convergence.entries[j];
      const double z = (e.value - truth[j]) / e.sigma_final;
      mc->sum_z2[j] += z * z;
      mc->max_z[j] = std::max(mc->max_z[j], std::fabs(z));
      EXPECT_TRUE(e.converged) << e.name << " seed " << seed;
      mc->max_convergence[j] = std::max(mc->max_convergence[j], e.time);
      if (seed == 1) mc->names.push_back(e.name);
    }
    ++mc->runs;
  }
}

TEST(HandheldKalman, SigmasMatchTheSpreadOverThirtyHandheldSessions) {
  const SimulatorOptions sensor = FilterSensor();
  const MotionOptions motion;
  MonteCarlo mc;
  RunMonteCarlo(sensor, motion, MatchingOptions(sensor), 30, &mc);
  ASSERT_EQ(mc.runs, 30);
  for (int j = 0; j < 12; ++j) {
    const double rms = std::sqrt(mc.sum_z2[j] / mc.runs);
    std::printf("%-16s error/sigma rms %.2f, max |error/sigma| %.2f, converged by %.1f s\n",
                mc.names[j].c_str(), rms, mc.max_z[j], mc.max_convergence[j]);
    EXPECT_LE(mc.max_z[j], 3.0) << mc.names[j];
    EXPECT_GE(rms, 0.7) << mc.names[j];
    EXPECT_LE(rms, 1.4) << mc.names[j];
    // The paper: handheld, every error within 60 s.
    EXPECT_LT(mc.max_convergence[j], 60.0) << mc.names[j];
  }
}

TEST(HandheldKalman, TurntableConvergesWithin100Seconds) {
  // The paper's table experiment: exact turns at a steady 30 deg/s (one
  // whole turn per axis), the sensor at the centre of the table, so the
  // pseudo-measurements are nearly exact.
  const SimulatorOptions sensor = FilterSensor();
  MotionOptions motion;
  motion.profile = MotionProfile::kTurntable;
  motion.rate_dps = 30.0;
  motion.seconds_per_axis = 14.0;
  motion.final_still_seconds = 40.0;
  HandheldKalmanOptions options = MatchingOptions(sensor);
  options.velocity_noise = 0.005;
  options.position_noise = 0.005;
  MonteCarlo mc;
  RunMonteCarlo(sensor, motion, options, 5, &mc);
  for (int j = 0; j < 12; ++j) {
    std::printf("%-16s max |error/sigma| %.2f, converged by %.1f s\n", mc.names[j].c_str(),
                mc.max_z[j], mc.max_convergence[j]);
    EXPECT_LE(mc.max_z[j], 3.0) << mc.names[j];
    EXPECT_LT(mc.max_convergence[j], 100.0) << mc.names[j];
  }
}

TEST(HandheldKalman, VerticalTurnsOnlyWarnAndLeaveSigmasLarge) {
  const SimulatorOptions sensor = FilterSensor();
  MotionOptions motion;
  motion.profile = MotionProfile::kVertical;
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(sensor, motion, 4, &s, &error)) << error;
  const HandheldKalmanOptions options = MatchingOptions(sensor);
  Calibration c;
  ASSERT_TRUE(CalibrateHandheld(s.sensor.log, options, &c)) << c.message;
  EXPECT_NE(c.message.find("not determined"), std::string::npos) << c.message;
  // With z up throughout: x and y never see gravity (their scales), z sees
  // only +g (its bias and scale are one number), and turns about the
  // vertical say nothing about the gyroscope scales.
  for (const char* name : {"accel_bias_z", "accel_scale_x", "accel_scale_y", "accel_scale_z",
                           "gyro_scale_x", "gyro_scale_y"}) {
    const ConvergenceEntry* entry = nullptr;
    for (const ConvergenceEntry& e : c.convergence.entries) {
      if (e.name == name) entry = &e;
    }
    ASSERT_NE(entry, nullptr) << name;
    EXPECT_FALSE(entry->converged) << name;
    EXPECT_GT(entry->sigma_final, options.convergence_fraction * entry->sigma_initial) << name;
    bool warned = false;
    for (const std::string& w : c.warnings) {
      warned |= w.rfind(name, 0) == 0 && w.find("turn the unit about its") != std::string::npos;
    }
    EXPECT_TRUE(warned) << name;
  }
  // The reported standard deviations are the large ones, not NaN.
  EXPECT_TRUE(std::isfinite(c.accel.matrix_std(0, 0)));
  EXPECT_GT(c.accel.matrix_std(0, 0), 0.1 * options.accel_scale_std * 0.99);
}

TEST(HandheldKalman, ResultUsesCalibrationModelsInRawUnits) {
  // Counts in, calibration models (raw -> SI) out.
  SimulatorOptions sensor = FilterSensor();
  sensor.raw_counts = true;
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(sensor, MotionOptions(), 7, &s, &error)) << error;
  HandheldKalmanOptions options = MatchingOptions(sensor);
  options.accel_nominal_scale = 1.0 / s.sensor.accel_units_per_si;
  options.gyro_nominal_scale = 1.0 / s.sensor.gyro_units_per_si;
  Calibration c;
  ASSERT_TRUE(CalibrateHandheld(s.sensor.log, options, &c)) << c.message;
  EXPECT_EQ(c.accel.model.parameterization, AccelParameterization::kScale);
  ASSERT_TRUE(c.gyro.estimated);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(c.accel.model.bias(i), s.sensor.accel_truth.bias(i), 3.0 * c.accel.bias_std(i));
    EXPECT_NEAR(c.accel.model.upper(i, i), s.sensor.accel_truth.upper(i, i),
                3.0 * c.accel.matrix_std(i, i));
    EXPECT_NEAR(c.gyro.model.bias(i), s.sensor.gyro_truth.bias(i), 3.0 * c.gyro.bias_std(i));
    EXPECT_NEAR(c.gyro.model.matrix(i, i), s.sensor.gyro_truth.matrix(i, i),
                3.0 * c.gyro.matrix_std(i, i));
    for (int k = 0; k < 3; ++k) {
      if (k == i) continue;
      EXPECT_EQ(c.gyro.model.matrix(i, k), 0.0);
      EXPECT_TRUE(std::isnan(c.gyro.matrix_std(i, k)));
    }
  }
  EXPECT_EQ(c.gyro.covariance.rows(), 6);
  EXPECT_EQ(c.gyro.covariance_names[3], "m_xx");
  // History: t plus value and std of 12 states, one row per update.
  ASSERT_EQ(c.history.columns.size(), 25u);
  EXPECT_EQ(c.history.columns[1], "accel_bias_x");
  EXPECT_EQ(c.history.columns[2], "accel_bias_x_std");
  EXPECT_EQ(c.history.rows(), static_cast<size_t>(c.refinement.iterations) + 1);
  // The JSON has the convergence section.
  const nlohmann::json j = nlohmann::json::parse(CalibrationToJson(c, true));
  EXPECT_EQ(j["accel"]["model"], "scale");
  EXPECT_TRUE(j["gyro"]["std"]["matrix"][0][1].is_null());
  EXPECT_TRUE(j["convergence"]["parameters"]["gyro_scale_z"]["converged"].get<bool>());
  EXPECT_FALSE(j["convergence"]["criterion"].get<std::string>().empty());
}

TEST(HandheldKalman, CrossAxisLayoutRuns) {
  // The layout takes the cross-axis terms: 21 + 12 states. Not in the
  // paper's model and not exposed as a key; this checks that the filter
  // takes every offset from the layout.
  const ErrorStateLayout paper;
  EXPECT_EQ(paper.size(), 21);
  EXPECT_EQ(paper.names()[12], "accel_scale_x");
  const ErrorStateLayout cross(SensorErrorTerms::ScaleAndCrossAxis(),
                               SensorErrorTerms::ScaleAndCrossAxis());
  EXPECT_EQ(cross.size(), 33);
  EXPECT_EQ(cross.offset(StateBlock::kGyroBias), 21);
  EXPECT_EQ(cross.names()[15], "accel_cross_xy");
  const SimulatorOptions sensor = FilterSensor();
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(sensor, MotionOptions(), 2, &s, &error)) << error;
  HandheldKalmanOptions options = MatchingOptions(sensor);
  options.accel_terms = SensorErrorTerms::ScaleAndCrossAxis();
  options.gyro_terms = SensorErrorTerms::ScaleAndCrossAxis();
  Calibration c;
  ASSERT_TRUE(CalibrateHandheld(s.sensor.log, options, &c)) << c.message;
  EXPECT_EQ(c.convergence.entries.size(), 24u);
  EXPECT_TRUE(c.gyro.matrix_std.allFinite());
  EXPECT_NEAR(c.gyro.model.bias(0), ErrorTruth(s.sensor).gyro_bias(0), 4.0 * c.gyro.bias_std(0));
}

TEST(HandheldKalman, RejectsBadInput) {
  const SimulatorOptions sensor = FilterSensor();
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(sensor, MotionOptions(), 1, &s, &error)) << error;
  const HandheldKalmanOptions options = MatchingOptions(sensor);
  Calibration c;
  ImuLog no_gyro = s.sensor.log;
  no_gyro.gyro.clear();
  EXPECT_FALSE(CalibrateHandheld(no_gyro, options, &c));
  EXPECT_NE(c.message.find("needs a gyroscope"), std::string::npos) << c.message;

  ImuLog short_log = s.sensor.log;
  short_log.t.resize(200);
  short_log.accel.resize(200);
  short_log.gyro.resize(200);
  short_log.temperature.resize(200);
  EXPECT_FALSE(CalibrateHandheld(short_log, options, &c));
  EXPECT_NE(c.message.find("too short"), std::string::npos) << c.message;

  HandheldKalmanOptions wrong_scale = options;
  wrong_scale.accel_nominal_scale = 1.0 / 16384.0;
  EXPECT_FALSE(CalibrateHandheld(s.sensor.log, wrong_scale, &c));
  EXPECT_NE(c.message.find("nominal_scale"), std::string::npos) << c.message;

  HandheldKalmanOptions bad = options;
  bad.update_interval = -1.0;
  EXPECT_FALSE(CalibrateHandheld(s.sensor.log, bad, &c));
  EXPECT_NE(c.message.find("hk_update_interval"), std::string::npos) << c.message;
  bad = options;
  bad.earth_rate = true;
  EXPECT_FALSE(bad.IsValid(&error));
  EXPECT_NE(error.find("latitude"), std::string::npos) << error;
}

}  // namespace
}  // namespace gravcal
