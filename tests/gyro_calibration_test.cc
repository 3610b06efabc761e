// Gyroscope calibration from the rotations between static poses
// (gyro_calibration.h): the integrator, sigmas against the spread over many
// simulated seeds, the residual per rotation, the g-sensitivity, the joint
// fit, a missing rotation axis, bad input, the pipeline, and the agreement
// with the rate-table and handheld Kalman calibrations of the same IMU.
#include "gravcal/methods/gyro_calibration.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <random>

#include "gravcal/detection/static_detector.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/residuals/gyro_rotation_residual.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "sigma_check.h"
#include "test_util.h"
#include "util/random_vector.h"

namespace gravcal {
namespace {

// The simulated IMU of these tests: the twelve poses, hand-like rotations.
SimulatorOptions HandSession() {
  SimulatorOptions sim;
  sim.rotation_profile = RotationProfile::kHand;
  sim.hold_seconds = 6.0;
  sim.initial_still_seconds = 4.0;
  return sim;
}

struct GyroRun {
  SimulatedSession session;
  Calibration accel;
  GyroCalibrationResult gyro;
  bool ok = false;
};

GyroRun CalibrateSimulated(const SimulatorOptions& sim, uint64_t seed,
                           const GyroCalibrationOptions& options) {
  GyroRun run;
  std::string error;
  EXPECT_TRUE(Simulate(sim, seed, &run.session, &error)) << error;
  CalibrationOptions accel_options;
  accel_options.gravity.gravity = run.session.gravity;
  EXPECT_TRUE(CalibrateAccelerometer(run.session.log, accel_options, &run.accel))
      << run.accel.message;
  StaticDetection detection;
  EXPECT_TRUE(DetectStaticIntervals(run.session.log, accel_options.detector, &detection));
  EXPECT_EQ(detection.intervals.size(), run.session.poses.size()) << "seed " << seed;
  run.ok =
      CalibrateGyroscope(run.session.log, detection.intervals, run.accel.accel.model,
                         run.accel.refinement.covariance, run.accel.gravity, options, &run.gyro);
  EXPECT_TRUE(run.ok) << "seed " << seed << ": " << run.gyro.message;
  return run;
}

// The truth in the frame the calibration works in. The calibrated
// accelerometer a = U (v - b) (scale_misalignment, R = I) sees R_a^T f,
// R_a the truth accelerometer's housing rotation, so the calibrated
// gyroscope must give R_a^T w: M = R_a^T M_g, G = R_a^T G_true R_a.
Eigen::Matrix3d MatrixInAccelFrame(const SimulatedSession& s) {
  return s.accel_truth.rotation.transpose() * s.gyro_truth.matrix;
}
Eigen::Matrix3d GInAccelFrame(const SimulatedSession& s) {
  return s.accel_truth.rotation.transpose() * s.gyro_g_sensitivity * s.accel_truth.rotation;
}

// Largest attitude error of the integrated truth rate over the rotations of
// a noise-free hand-profile session.
double WorstIntegrationError(double sample_rate) {
  SimulatorOptions sim = HandSession();
  sim.raw_counts = false;
  sim.accel_noise = 0.0;
  sim.gyro_noise = 0.0;
  sim.hand_wobble_deg = 30.0;
  sim.sample_rate = sample_rate;
  SimulatedSession s;
  std::string error;
  EXPECT_TRUE(Simulate(sim, 3, &s, &error)) << error;
  double bias[3], matrix[9];
  for (int i = 0; i < 3; ++i) bias[i] = s.gyro_truth.bias(i);
  for (int i = 0; i < 9; ++i) matrix[i] = s.gyro_truth.matrix(i / 3, i % 3);
  double worst = 0.0;
  for (size_t k = 0; k + 1 < s.poses.size(); ++k) {
    GyroRotationData d;
    for (size_t i = s.poses[k].end - 1; i <= s.poses[k + 1].begin; ++i) {
      d.t.push_back(s.log.t[i]);
      d.gyro.push_back(s.log.gyro[i]);
    }
    double dq[4];
    IntegrateGyroRotation<double>(d, bias, matrix, nullptr, dq);
    const Eigen::Quaterniond estimate(dq[0], dq[1], dq[2], dq[3]);
    const Eigen::Quaterniond truth = s.poses[k].attitude.conjugate() * s.poses[k + 1].attitude;
    worst = std::max(worst, testing_util::QuaternionAngle(estimate, truth));
  }
  return worst;
}

TEST(GyroCalibration, IntegratorIsHigherOrderOnHandRotations) {
  // Rotations of up to 180 degrees in 1-4 s with a 30-degree axis wobble.
  const double e100 = WorstIntegrationError(100.0);
  const double e200 = WorstIntegrationError(200.0);
  // A trapezoid rule is second order (ratio 4) once the axis moves; the
  // cubic Magnus step is third order here (its first and last steps are
  // trapezoids where the unit comes to rest).
  EXPECT_GT(e100 / e200, 6.0) << e100 << " " << e200;
  // Far below the noise of an integrated MEMS gyroscope (about 5e-4 rad).
  EXPECT_LT(e100, 2e-5);
}

TEST(GyroCalibration, FullModelSigmaMatchesSpreadAndResidualsAtNoiseLevel) {
  const SimulatorOptions sim = HandSession();
  GyroCalibrationOptions options;
  options.parameterization = GyroParameterization::kFull;
  testing_util::SigmaCheck check;
  double chi2 = 0.0, dof = 0.0, residual2 = 0.0, sigma2 = 0.0;
  for (int seed = 1; seed <= 40; ++seed) {
    const GyroRun run = CalibrateSimulated(sim, seed, options);
    if (!run.ok) continue;
    EXPECT_TRUE(run.gyro.undetermined.empty()) << "seed " << seed;
    EXPECT_EQ(run.gyro.rotations.size(), run.session.poses.size() - 1);
    testing_util::AddEach(&check, "M_g", run.gyro.model.matrix - MatrixInAccelFrame(run.session),
                          run.gyro.matrix_std);
    testing_util::AddEach(&check, "b_g", run.gyro.model.bias - run.session.gyro_truth.bias,
                          run.gyro.bias_std);
    chi2 += run.gyro.chi2;
    dof += run.gyro.dof;
    for (const GyroRotationReport& r : run.gyro.rotations) {
      residual2 += r.residual_deg * r.residual_deg;
      sigma2 += r.sigma_deg * r.sigma_deg;
    }
  }
  check.ExpectHonest("full gyroscope model");
  // The residuals are what the noise explains: chi2 / dof near 1 (about 1800
  // dof, so +-0.1 is more than 3 standard deviations).
  EXPECT_NEAR(chi2 / dof, 1.0, 0.1);
  // The residual angle per rotation against its predicted size: the fit
  // absorbs 9 of the 22 rotation residuals, so the expected ratio is about
  // sqrt(13 / 22) = 0.77.
  const double ratio = std::sqrt(residual2 / sigma2);
  EXPECT_GT(ratio, 0.6);
  EXPECT_LT(ratio, 1.0);
}

TEST(GyroCalibration, GSensitivitySigmaMatchesSpread) {
  SimulatorOptions sim = HandSession();
  sim.effect_std[Effect::kGyroGSensitivity] = 2e-4;  // about 0.1 deg/s per g
  // 60 seeds, each parameter checked in the band of tests/sigma_check.h;
  // the 400-seed run of the property harness (tests/property) checks the
  // same model with G.
  GyroCalibrationOptions options;
  options.parameterization = GyroParameterization::kFull;
  options.g_sensitivity = true;
  testing_util::SigmaCheck check;
  for (int seed = 1; seed <= 60; ++seed) {
    const GyroRun run = CalibrateSimulated(sim, seed, options);
    if (!run.ok) continue;
    testing_util::AddEach(&check, "M_g", run.gyro.model.matrix - MatrixInAccelFrame(run.session),
                          run.gyro.matrix_std);
    testing_util::AddEach(&check, "G", run.gyro.g_sensitivity - GInAccelFrame(run.session),
                          run.gyro.g_sensitivity_std);
  }
  check.ExpectHonest("gyroscope with g-sensitivity");
}

TEST(GyroCalibration, UnmodelledGSensitivityIsFlagged) {
  SimulatorOptions sim = HandSession();
  sim.effect_std[Effect::kGyroGSensitivity] = 2e-3;
  GyroCalibrationOptions options;
  options.parameterization = GyroParameterization::kFull;
  const GyroRun run = CalibrateSimulated(sim, 1, options);
  ASSERT_TRUE(run.ok);
  bool flagged = false;
  for (const std::string& w : run.gyro.warnings) {
    flagged = flagged || w.find("gyro_g_sensitivity") != std::string::npos;
  }
  EXPECT_TRUE(flagged) << "chi2 " << run.gyro.chi2 << " dof " << run.gyro.dof;
}

TEST(GyroCalibration, JointFitSigmaMatchesSpread) {
  const SimulatorOptions sim = HandSession();
  GyroCalibrationOptions options;
  options.parameterization = GyroParameterization::kFull;
  options.joint = true;
  testing_util::SigmaCheck check;
  for (int seed = 1; seed <= 30; ++seed) {
    const GyroRun run = CalibrateSimulated(sim, seed, options);
    if (!run.ok) continue;
    ASSERT_TRUE(run.gyro.accel_refined);
    ASSERT_TRUE(run.gyro.accel.covariance_available);
    testing_util::AddEach(&check, "M_g", run.gyro.model.matrix - MatrixInAccelFrame(run.session),
                          run.gyro.matrix_std);
    testing_util::AddEach(&check, "accel_bias",
                          run.gyro.accel.model.bias - run.session.accel_truth.bias,
                          run.gyro.accel.covariance.diagonal().head<3>().cwiseSqrt());
  }
  check.ExpectHonest("joint gyroscope and accelerometer fit");
}

TEST(GyroCalibration, ScaleAndBiasModels) {
  const SimulatorOptions sim = HandSession();
  for (GyroParameterization p : {GyroParameterization::kScale, GyroParameterization::kBias}) {
    GyroCalibrationOptions options;
    options.parameterization = p;
    const GyroRun run = CalibrateSimulated(sim, 5, options);
    ASSERT_TRUE(run.ok) << run.gyro.message;
    const Eigen::Matrix3d& m = run.gyro.model.matrix;
    EXPECT_EQ(m(0, 1), 0.0);
    EXPECT_TRUE(std::isnan(run.gyro.matrix_std(0, 1)));
    const Eigen::Matrix3d truth = MatrixInAccelFrame(run.session);
    // The truth has misalignment (0.005 rad, plus the accelerometer frame's
    // 0.01 rad) and a 2 % scale spread: a restricted model is off by about
    // that, not more.
    const double tolerance = p == GyroParameterization::kScale ? 0.01 : 0.05;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(m(i, i) / truth(i, i), 1.0, tolerance) << ToString(p);
    if (p == GyroParameterization::kBias) {
      EXPECT_EQ(m(0, 0), m(1, 1));
      EXPECT_EQ(run.gyro.parameter_names.back(), "scale");
    }
  }
}

// A session whose rotations all turn about the body x or y axis: the
// gyroscope's z column is never excited. SI units, identity accelerometer.
ImuLog SessionWithoutZRotation(const GyroModel& gyro, uint64_t seed) {
  const double rate = 100.0, hold = 5.0, turn = 2.0, g = 9.80665;
  const double noise_a = 0.02, noise_g = 0.002;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto noise = [&](double s) -> Eigen::Vector3d {
    return internal::DrawVector3([&] { return n01(rng); }) * s;
  };
  ImuLog log;
  log.source = "no_z_rotation";
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  const Eigen::Matrix3d minv = gyro.matrix.inverse();
  auto emit = [&](const Eigen::Quaterniond& attitude, const Eigen::Vector3d& w) {
    log.t.push_back(static_cast<double>(log.t.size()) / rate);
    log.accel.push_back(attitude.conjugate() * Eigen::Vector3d(0, 0, g) + noise(noise_a));
    log.gyro.push_back(minv * w + gyro.bias + noise(noise_g));
  };
  constexpr int kTurns = 11;
  for (int k = 0; k <= kTurns; ++k) {
    for (int i = 0; i < hold * rate; ++i) emit(q, Eigen::Vector3d::Zero());
    if (k == kTurns) break;
    // About body x and y in turn, unless that axis is near vertical (a turn
    // about the vertical would not move gravity), by 50..120 degrees.
    const Eigen::Vector3d up = q.conjugate() * Eigen::Vector3d::UnitZ();
    const int a = std::fabs(up(k % 2)) > 0.8 ? 1 - k % 2 : k % 2;
    const Eigen::Vector3d axis = Eigen::Vector3d::Unit(a);
    const double angle = (k % 2 == 0 ? 1.0 : -1.0) * (50.0 + 7.0 * k) * M_PI / 180.0;
    const int n = static_cast<int>(turn * rate);
    for (int i = 0; i < n; ++i) {
      const double x = static_cast<double>(i) / n;
      const double s = x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
      const double ds = 30.0 * x * x * (1.0 - x) * (1.0 - x);
      emit(q * Eigen::Quaterniond(Eigen::AngleAxisd(s * angle, axis)), axis * angle * ds / turn);
    }
    q = q * Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis));
  }
  return log;
}

TEST(GyroCalibration, MissingRotationAxisIsNamed) {
  GyroModel truth;
  truth.matrix << 1.01, 0.004, -0.003, 0.002, 0.98, 0.005, -0.004, 0.003, 1.02;
  truth.bias << 0.01, -0.02, 0.015;
  const ImuLog log = SessionWithoutZRotation(truth, 7);
  StaticDetection detection;
  ASSERT_TRUE(DetectStaticIntervals(log, StaticDetectorOptions(), &detection));
  ASSERT_EQ(detection.intervals.size(), 12u);

  GyroCalibrationOptions options;
  options.parameterization = GyroParameterization::kFull;
  GyroCalibrationResult result;
  ASSERT_TRUE(CalibrateGyroscope(log, detection.intervals, AccelModel(), Eigen::MatrixXd(), 9.80665,
                                 options, &result))
      << result.message;
  bool named = false;
  for (const std::string& w : result.warnings) {
    named = named || (w.find("no rotation about the body z axis") != std::string::npos &&
                      w.find("gyro scale z") != std::string::npos);
  }
  EXPECT_TRUE(named);
  for (int r = 0; r < 3; ++r) {
    EXPECT_TRUE(std::isnan(result.matrix_std(r, 2))) << r;
    for (int c = 0; c < 2; ++c) {
      EXPECT_TRUE(std::isfinite(result.matrix_std(r, c))) << r << c;
      EXPECT_NEAR(result.model.matrix(r, c), truth.matrix(r, c), 5.0 * result.matrix_std(r, c));
    }
  }
}

TEST(GyroCalibration, BadInputGivesAMessage) {
  SimulatedSession s;
  std::string error;
  ASSERT_TRUE(Simulate(HandSession(), 1, &s, &error)) << error;
  StaticDetection detection;
  ASSERT_TRUE(DetectStaticIntervals(s.log, StaticDetectorOptions(), &detection));
  GyroCalibrationOptions options;
  GyroCalibrationResult result;
  // Nothing asked for.
  EXPECT_FALSE(CalibrateGyroscope(s.log, detection.intervals, AccelModel(), Eigen::MatrixXd(), 9.8,
                                  options, &result));
  EXPECT_NE(result.message.find("none"), std::string::npos) << result.message;
  options.parameterization = GyroParameterization::kFull;
  // No gyroscope columns.
  ImuLog no_gyro = s.log;
  no_gyro.gyro.clear();
  EXPECT_FALSE(CalibrateGyroscope(no_gyro, detection.intervals, AccelModel(), Eigen::MatrixXd(),
                                  9.8, options, &result));
  EXPECT_NE(result.message.find("no gyroscope columns"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find(s.log.source), std::string::npos) << result.message;
  // Too few poses for the full model (three poses, two rotations).
  const std::vector<StaticInterval> three(detection.intervals.begin(),
                                          detection.intervals.begin() + 3);
  EXPECT_FALSE(
      CalibrateGyroscope(s.log, three, AccelModel(), Eigen::MatrixXd(), 9.8, options, &result));
  EXPECT_NE(result.message.find("found 2 rotations"), std::string::npos) << result.message;
  // Intervals out of order.
  std::vector<StaticInterval> swapped = detection.intervals;
  std::swap(swapped[1], swapped[2]);
  EXPECT_FALSE(
      CalibrateGyroscope(s.log, swapped, AccelModel(), Eigen::MatrixXd(), 9.8, options, &result));
  EXPECT_NE(result.message.find("static interval 2"), std::string::npos) << result.message;
  // Invalid options.
  options.loss_scale = -1.0;
  EXPECT_FALSE(CalibrateGyroscope(s.log, detection.intervals, AccelModel(), Eigen::MatrixXd(), 9.8,
                                  options, &result));
  EXPECT_NE(result.message.find("gyro_loss_scale"), std::string::npos) << result.message;
}

TEST(GyroCalibration, PipelineFillsTheGyroscopeOfTheCalibration) {
  Config config;
  config.simulation = HandSession();
  std::string error;
  ASSERT_TRUE(SetConfigValue("gyro_model", "full", &config, &error)) << error;
  ASSERT_TRUE(SetConfigValue("gyro_g_sensitivity", "true", &config, &error)) << error;
  EXPECT_FALSE(SetConfigValue("gyro_model", "diagonal", &config, &error));
  EXPECT_NE(error.find("gyro_model"), std::string::npos) << error;
  SimulatedSession s;
  ASSERT_TRUE(Simulate(config.simulation, 2, &s, &error)) << error;
  config.calibration.gravity.gravity = s.gravity;
  PipelineInput input;
  input.log = s.log;
  Calibration c;
  ASSERT_TRUE(RunCalibration(config, input, &c)) << c.message;
  ASSERT_TRUE(c.gyro.estimated);
  EXPECT_EQ(c.gyro.rotation_residual_deg.size(), 11u);
  EXPECT_EQ(c.gyro.extra_names.size(), 9u);
  EXPECT_EQ(c.gyro.covariance_names.size(), 21u);
  EXPECT_LT((c.gyro.model.matrix - MatrixInAccelFrame(s)).norm(),
            1e-3 * s.gyro_truth.matrix.norm());
  const std::string json = CalibrationToJson(c, true);
  EXPECT_NE(json.find("\"rotation_residual_deg\""), std::string::npos);
  EXPECT_NE(json.find("\"g_sensitivity_xy\""), std::string::npos);

  // The same log without gyroscope: a clear error, no calibration.
  input.log.gyro.clear();
  input.log.source = "nogyro.csv";
  EXPECT_FALSE(RunCalibration(config, input, &c));
  EXPECT_FALSE(c.success);
  EXPECT_NE(c.message.find("nogyro.csv: the log has no gyroscope columns"), std::string::npos)
      << c.message;
}

// One estimate of the six numbers all three gyroscope calibrations give
// (bias x, y, z in raw units; diagonal of M_g in rad/s per raw unit, in the
// rotations method's frame, the calibrated accelerometer's) with their
// standard deviations.
struct GyroEstimate {
  const char* name = "";
  Eigen::Matrix<double, 6, 1> value, sigma;
};

GyroEstimate Estimate(const char* name, const GyroModel& model, const Eigen::Vector3d& bias_std,
                      const Eigen::Matrix3d& matrix_std) {
  GyroEstimate e;
  e.name = name;
  e.value << model.bias, model.matrix.diagonal();
  e.sigma << bias_std, matrix_std.diagonal();
  return e;
}

// An estimate of M_g in another frame, brought into the frame T rotates
// into: T M. Its covariance (bias_x..z, m_xx, m_xy, ..., m_zz) is carried
// through that linear map, d(T M)_ii = sum_k T_ik dM_ki; the bias is in raw
// units and needs nothing.
GyroEstimate Rotated(const char* name, const GyroModel& model, const Eigen::MatrixXd& covariance,
                     const Eigen::Matrix3d& t) {
  EXPECT_EQ(covariance.rows(), 12) << name;
  Eigen::Matrix<double, 6, 12> jacobian = Eigen::Matrix<double, 6, 12>::Zero();
  for (int i = 0; i < 3; ++i) {
    jacobian(i, i) = 1.0;
    for (int k = 0; k < 3; ++k) jacobian(3 + i, 3 + 3 * k + i) = t(i, k);
  }
  const Eigen::Matrix<double, 6, 6> cov = jacobian * covariance * jacobian.transpose();
  GyroEstimate e;
  e.name = name;
  e.value << model.bias, (t * model.matrix).diagonal();
  e.sigma = cov.diagonal().cwiseSqrt();
  return e;
}

// Cross-check of issue 5 ("results agree ... within their uncertainties"):
// seed `seed` of `sensor` calibrated three ways, (a) from the rotations
// between the twelve poses (hand rotations, full model), (b) on a rate
// table, (c) with the handheld Kalman filter (bias and scale, plus the
// cross-axis terms when `cross_axis`). Simulate and SimulateMotion draw the
// truth sensors first, from the same generator and options, so one seed is
// one IMU (checked); the three sessions have their own noise, so the three
// errors are independent. The comparison is in the calibrated
// accelerometer's frame, R_a^T times the body frame (MatrixInAccelFrame):
// the rotations method's and, with cross-axis terms, the filter's; the rate
// table works in the body frame and is rotated. Into `check` go every
// estimate's error / sigma ("<method> <value>") and every pair's
// difference / combined sigma ("<method> - <method> <value>").
void AddThreeWays(const SimulatorOptions& sensor, bool cross_axis, uint64_t seed,
                  testing_util::SigmaCheck* check) {
  // (a) Rotations between static poses.
  GyroCalibrationOptions rotation_options;
  rotation_options.parameterization = GyroParameterization::kFull;
  const GyroRun run = CalibrateSimulated(sensor, seed, rotation_options);
  ASSERT_TRUE(run.ok);
  const Eigen::Matrix3d& accel_rotation = run.session.accel_truth.rotation;
  // (b) Rate table.
  MotionOptions table;
  table.profile = MotionProfile::kRateTable;
  table.rate_dps = 60.0;
  table.seconds_per_axis = 20.0;
  MotionSession rate_session;
  std::string error;
  ASSERT_TRUE(SimulateMotion(sensor, table, seed, &rate_session, &error)) << error;
  RateTableResult rate;
  ASSERT_TRUE(CalibrateRateTable(rate_session.sensor.log, rate_session.segments, &rate))
      << rate.message;
  // (c) Handheld Kalman filter, its noise settings matching the sensor.
  MotionSession hand_session;
  ASSERT_TRUE(SimulateMotion(sensor, MotionOptions(), seed, &hand_session, &error)) << error;
  HandheldKalmanOptions kalman_options;
  kalman_options.gravity.gravity = sensor.gravity;
  kalman_options.accel_nominal_scale = 1.0 / hand_session.sensor.accel_units_per_si;
  kalman_options.gyro_nominal_scale = 1.0 / hand_session.sensor.gyro_units_per_si;
  kalman_options.accel_noise_density = sensor.accel_noise / std::sqrt(sensor.sample_rate);
  kalman_options.gyro_noise_density = sensor.gyro_noise / std::sqrt(sensor.sample_rate);
  if (cross_axis) {
    kalman_options.accel_terms = SensorErrorTerms::ScaleAndUpperCrossAxis();
    kalman_options.gyro_terms = SensorErrorTerms::ScaleAndCrossAxis();
  }
  Calibration kalman;
  ASSERT_TRUE(CalibrateHandheld(hand_session.sensor.log, kalman_options, &kalman))
      << kalman.message;

  // One IMU.
  const GyroModel& truth = run.session.gyro_truth;
  for (const MotionSession* m : {&rate_session, &hand_session}) {
    ASSERT_EQ(m->sensor.gyro_truth.bias, truth.bias);
    ASSERT_EQ(m->sensor.gyro_truth.matrix, truth.matrix);
    ASSERT_EQ(m->sensor.accel_truth.matrix(), run.session.accel_truth.matrix());
  }
  const GyroEstimate estimates[3] = {
      Estimate("rotations", run.gyro.model, run.gyro.bias_std, run.gyro.matrix_std),
      Rotated("rate table", rate.gyro.model, rate.gyro.covariance, accel_rotation.transpose()),
      Estimate("kalman", kalman.gyro.model, kalman.gyro.bias_std, kalman.gyro.matrix_std)};
  Eigen::Matrix<double, 6, 1> truth_value;
  truth_value << truth.bias, MatrixInAccelFrame(run.session).diagonal();
  const char* names[6] = {"b_x", "b_y", "b_z", "m_xx", "m_yy", "m_zz"};
  for (int j = 0; j < 6; ++j) {
    for (const GyroEstimate& e : estimates) {
      check->Add(std::string(e.name) + " " + names[j], e.value(j) - truth_value(j), e.sigma(j));
    }
    for (int a = 0; a < 3; ++a) {
      for (int b = a + 1; b < 3; ++b) {
        const GyroEstimate& x = estimates[a];
        const GyroEstimate& y = estimates[b];
        check->Add(std::string(x.name) + " - " + y.name + " " + names[j], x.value(j) - y.value(j),
                   std::hypot(x.sigma(j), y.sigma(j)));
      }
    }
  }
}

// Seeds of the three-way agreement: sigmas twice too large fail SigmaCheck's
// band from 30 on.
constexpr int kAgreementSeeds = 30;

void ExpectThreeWaysAgree(const SimulatorOptions& sensor, bool cross_axis, const char* context) {
  testing_util::SigmaCheck check;
  for (uint64_t seed = 1; seed <= kAgreementSeeds; ++seed) {
    AddThreeWays(sensor, cross_axis, seed, &check);
  }
  EXPECT_EQ(check.Names().size(), 36u);
  std::printf("%s", check.Table().c_str());
  check.ExpectHonest(context);
}

// The IMU the filter's model (the paper's: bias and scale) describes, no
// misalignment. With the simulator's default 0.005 rad that model is biased
// by up to 44 sigma here (seeds 1-3; benchmarks/RESULTS.md,
// HandheldKalman.CrossAxisTermsRecoverAMisalignedImu), while the other two
// still agree with each other and the truth: hence the second test.
TEST(GyroCalibration, AgreesWithRateTableAndHandheldKalman) {
  SimulatorOptions sensor = HandSession();
  sensor.accel_misalignment_std = 0.0;
  sensor.gyro_misalignment_std = 0.0;
  ExpectThreeWaysAgree(sensor, false, "three ways, aligned IMU");
}

// A misaligned IMU (simulator defaults), the filter with its cross-axis
// terms: it then works in the accelerometer's frame like the rotations
// method.
TEST(GyroCalibration, AgreesWithRateTableAndCrossAxisKalmanWhenMisaligned) {
  ExpectThreeWaysAgree(HandSession(), true, "three ways, misaligned IMU, cross-axis filter");
}

}  // namespace
}  // namespace gravcal
