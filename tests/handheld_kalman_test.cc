#include "gravcal/methods/handheld_kalman.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "estimation/strapdown.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "sigma_check.h"
#include "test_util.h"

namespace gravcal {
namespace {

using internal::EarthRateEnu;

// Seeds of the Monte Carlo tests: 30 where a run is cheap enough, so that
// sigmas twice too large fail SigmaCheck's band.
constexpr int kTurntableSeeds = 30;
constexpr int kCrossAxisSeeds = 30;
constexpr int kLeverArmSeeds = 30;

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
// the rate) and gravity; the hand's pseudo-measurement noise is the shipped
// default (configs/handheld_kalman.yaml: 3 cm and 3 cm/s), which the default
// profile's sway (1 cm rms per axis, up to 0.5 Hz: about 1.4 cm from the
// start at up to about 2 cm/s) must satisfy.
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
  testing_util::SigmaCheck check;
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
      mc->check.Add(e.name, e.value - truth[j], e.sigma_final);
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
  std::printf("%s", mc.check.Table().c_str());
  mc.check.ExpectHonest("handheld, shipped defaults");
  for (int j = 0; j < 12; ++j) {
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
  RunMonteCarlo(sensor, motion, options, kTurntableSeeds, &mc);
  std::printf("%s", mc.check.Table().c_str());
  mc.check.ExpectHonest("turntable");
  for (int j = 0; j < 12; ++j) {
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

TEST(HandheldKalman, LayoutTakesCrossAxisTerms) {
  const ErrorStateLayout paper;
  EXPECT_EQ(paper.size(), 21);
  EXPECT_EQ(paper.names()[12], "accel_scale_x");
  const ErrorStateLayout cross(SensorErrorTerms::ScaleAndUpperCrossAxis(),
                               SensorErrorTerms::ScaleAndCrossAxis());
  EXPECT_EQ(cross.size(), 30);
  EXPECT_EQ(cross.offset(StateBlock::kGyroBias), 18);
  EXPECT_EQ(cross.names()[15], "accel_cross_xy");
  EXPECT_EQ(cross.names()[29], "gyro_cross_zy");
}

TEST(HandheldKalman, CrossAxisTermsRecoverAMisalignedImu) {
  // With misalignment the paper's model is biased (benchmarks/RESULTS.md:
  // errors about 10 sigma at 0.005 rad). With the cross-axis terms (the
  // accelerometer's x axis and xy plane define the body frame) every entry
  // comes out within its sigma. Truth in that frame: the accelerometer is U
  // (M = R U), the gyroscope M_g^-1 R.
  SimulatorOptions sensor = FilterSensor();
  sensor.accel_misalignment_std = 0.005;
  sensor.gyro_misalignment_std = 0.005;
  HandheldKalmanOptions options = MatchingOptions(sensor);
  options.accel_terms = SensorErrorTerms::ScaleAndUpperCrossAxis();
  options.gyro_terms = SensorErrorTerms::ScaleAndCrossAxis();
  const ErrorStateLayout layout(options.accel_terms, options.gyro_terms);
  testing_util::SigmaCheck check;
  for (int seed = 1; seed <= kCrossAxisSeeds; ++seed) {
    MotionSession s;
    std::string error;
    ASSERT_TRUE(SimulateMotion(sensor, MotionOptions(), seed, &s, &error)) << error;
    Calibration c;
    ASSERT_TRUE(CalibrateHandheld(s.sensor.log, options, &c)) << c.message;
    EXPECT_EQ(c.accel.model.parameterization, AccelParameterization::kScaleMisalignment);
    const Eigen::Matrix3d accel_e =
        s.sensor.accel_truth.upper.inverse() - Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d gyro_e =
        s.sensor.gyro_truth.matrix.inverse() * s.sensor.accel_truth.rotation -
        Eigen::Matrix3d::Identity();
    std::vector<double> truth;
    for (int i = 0; i < 3; ++i) truth.push_back(s.sensor.accel_truth.bias(i));
    for (const auto& [r, k] : layout.accel().matrix_entries) truth.push_back(accel_e(r, k));
    for (int i = 0; i < 3; ++i) truth.push_back(s.sensor.gyro_truth.bias(i));
    for (const auto& [r, k] : layout.gyro().matrix_entries) truth.push_back(gyro_e(r, k));
    ASSERT_EQ(c.convergence.entries.size(), truth.size());
    for (size_t j = 0; j < truth.size(); ++j) {
      const ConvergenceEntry& e = c.convergence.entries[j];
      check.Add(e.name, e.value - truth[j], e.sigma_final);
      // Bias and scale converge as without cross-axis terms; the cross-axis
      // terms shrink to 10-20 % of their prior in a minute.
      if (e.name.find("_cross_") == std::string::npos) {
        EXPECT_TRUE(e.converged) << e.name << " seed " << seed;
      } else {
        EXPECT_LT(e.sigma_final, 0.3 * e.sigma_initial) << e.name << " seed " << seed;
      }
    }
  }
  std::printf("%s", check.Table().c_str());
  check.ExpectHonest("cross-axis filter");
}

TEST(HandheldKalman, LeverArmIsEstimatedWhenAsked) {
  // The sensor 3 cm from the point the hand turns about: its centripetal
  // acceleration and circular motion look like accelerometer errors to the
  // paper's model (error/sigma RMS up to about 3.8); with hk_lever_arm the
  // pseudo-measurements hold the turning point still and r is a state.
  const SimulatorOptions sensor = FilterSensor();
  MotionOptions motion;
  motion.lever_arm = 0.03;
  HandheldKalmanOptions options = MatchingOptions(sensor);
  testing_util::SigmaCheck with_check;
  double sum_z2_without = 0.0;
  int count = 0;
  for (int seed = 1; seed <= kLeverArmSeeds; ++seed) {
    MotionSession s;
    std::string error;
    ASSERT_TRUE(SimulateMotion(sensor, motion, seed, &s, &error)) << error;
    const std::vector<double> truth = TruthVector(s.sensor);
    Calibration without, with;
    options.estimate_lever_arm = false;
    ASSERT_TRUE(CalibrateHandheld(s.sensor.log, options, &without)) << without.message;
    options.estimate_lever_arm = true;
    ASSERT_TRUE(CalibrateHandheld(s.sensor.log, options, &with)) << with.message;
    ASSERT_EQ(with.convergence.entries.size(), 15u);
    for (int j = 0; j < 15; ++j) {
      const ConvergenceEntry& e = with.convergence.entries[j];
      const double t = j < 12 ? truth[j] : s.lever_arm(j - 12);
      with_check.Add(e.name, e.value - t, e.sigma_final);
      if (j >= 12) {
        EXPECT_EQ(e.unit, "m");
        EXPECT_LT(e.sigma_final, 0.005) << e.name;
        continue;
      }
      const ConvergenceEntry& w = without.convergence.entries[j];
      sum_z2_without += std::pow((w.value - t) / w.sigma_final, 2);
      ++count;
    }
  }
  const double rms_without = std::sqrt(sum_z2_without / count);
  std::printf("lever arm 3 cm: error/sigma RMS %.2f without hk_lever_arm; with it:\n%s",
              rms_without, with_check.Table().c_str());
  // Without the lever arm the 12 states pooled are far outside the band for
  // `count` draws; with it every state, the lever arm too, is inside.
  EXPECT_GT(rms_without, testing_util::SigmaBandFor(count).rms_high);
  with_check.ExpectHonest("filter with hk_lever_arm");
}

// A session whose gyroscope senses the Earth rate (added to the simulated
// samples through the truth attitude, 45 deg latitude). With the option on
// the filter models it: its gyroscope biases are within their sigmas (each of
// three |error/sigma| under the bound three honest N(0, 1) values all stay
// inside with probability 0.999). With it off, the biases absorb some
// average of the body-frame Earth rate, a vector no longer than the Earth
// rate Omega (the filter's weights are matrices, hence the factor 2 below):
// the two estimates must differ by more than 0.1 Omega (an option that does
// nothing gives exactly 0) and less than 2 Omega (a wrong unit or a doubled
// rate gives more).
TEST(HandheldKalman, EarthRateOptionRuns) {
  const SimulatorOptions sensor = FilterSensor();
  const double latitude = 45.0;
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(sensor, MotionOptions(), 9, &s, &error)) << error;
  const Eigen::Matrix3d to_raw = s.sensor.gyro_truth.matrix.inverse();
  for (size_t i = 0; i < s.sensor.log.size(); ++i) {
    s.sensor.log.gyro[i] += to_raw * (s.attitude[i].conjugate() * EarthRateEnu(latitude));
  }
  const std::vector<double> truth = TruthVector(s.sensor);
  const double bound =
      testing_util::NormalQuantile(1.0 - 0.5 * (1.0 - testing_util::kSigmaBandProbability) / 3);
  Eigen::Vector3d bias[2];
  for (bool on : {true, false}) {
    HandheldKalmanOptions options = MatchingOptions(sensor);
    options.earth_rate = on;
    options.gravity.latitude = latitude;
    Calibration c;
    ASSERT_TRUE(CalibrateHandheld(s.sensor.log, options, &c)) << c.message;
    for (int j = 6; j < 9; ++j) {
      const ConvergenceEntry& e = c.convergence.entries[j];
      bias[on](j - 6) = e.value;
      std::printf("earth_rate %d %s error %.3g sigma %.3g\n", on, e.name.c_str(),
                  e.value - truth[j], e.sigma_final);
      if (on) EXPECT_LT(std::fabs(e.value - truth[j]), bound * e.sigma_final) << e.name;
    }
  }
  const double shift = (bias[0] - bias[1]).norm();
  std::printf("bias shift off - on %.3g rad/s, Earth rate %.3g\n", shift, kEarthRate);
  EXPECT_GT(shift, 0.1 * kEarthRate);
  EXPECT_LT(shift, 2.0 * kEarthRate);
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

TEST(HandheldKalman, RealFerrarisSessionAgreesWithStaticReferences) {
  const std::string dir = testing_util::RealDataDir();
  if (dir.empty()) GTEST_SKIP() << "no real data folder";
  const std::string session = "ferraris_nilspod/session.csv";
  auto calibrate = [&](const std::string& config_name, Calibration* c) {
    Config config;
    PipelineInput input;
    std::string error;
    ASSERT_TRUE(testing_util::LoadRealSession(config_name, session, &config, &input.log, &error))
        << error;
    ASSERT_TRUE(RunCalibration(config, input, c)) << c->message;
  };
  Calibration handheld, faces;
  calibrate("ferraris_nilspod_handheld.yaml", &handheld);
  calibrate("ferraris_nilspod.yaml", &faces);
  // The accelerometer against the six-face magnitude fit of the same session
  // (m/s^2 and scale factor). Observed with the config's cross-axis terms and
  // lever arm: 0.004 m/s^2 and 0.0004 (the paper's diagonal model: 0.02 and
  // 0.0015).
  EXPECT_NEAR(handheld.refinement.chi2 / handheld.refinement.dof, 1.0, 0.5);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(handheld.accel.model.bias(i), faces.accel.model.bias(i), 0.01) << i;
    EXPECT_NEAR(handheld.accel.model.upper(i, i), faces.accel.model.matrix()(i, i), 0.001) << i;
  }
  // The gyroscope bias against its mean over the six still faces (deg/s;
  // the Earth rate cancels over opposite faces). Observed: 0.009, 0.002 and
  // 0.04 deg/s, the last 20 times the filter's sigma: something this model
  // still lacks on the z gyroscope.
  std::ifstream in(dir + "/ferraris_nilspod/sections.json");
  const nlohmann::json sections = nlohmann::json::parse(in);
  Config config;
  ImuLog log;
  std::string error;
  ASSERT_TRUE(
      testing_util::LoadRealSession("ferraris_nilspod.yaml", session, &config, &log, &error))
      << error;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (const char* face : {"x_p", "x_a", "y_p", "y_a", "z_p", "z_a"}) {
    for (int i = sections[face]["start"].get<int>(); i < sections[face]["end"].get<int>(); ++i) {
      sum += log.gyro[i];
      ++count;
    }
  }
  const Eigen::Vector3d still_mean = sum / count;
  ASSERT_TRUE(handheld.gyro.estimated);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(handheld.gyro.model.bias(i), still_mean(i), 0.06) << i;
    // Scale within 5 % of the factory's deg/s.
    EXPECT_NEAR(handheld.gyro.model.matrix(i, i), M_PI / 180.0, 0.05 * M_PI / 180.0) << i;
  }
}

}  // namespace
}  // namespace gravcal
