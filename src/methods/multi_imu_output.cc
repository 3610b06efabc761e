// The multi-IMU calibration's results (methods/multi_imu.h): each IMU's
// calibration in the existing schema, the sigmas compared between the
// joint and separate fits, and the single-pose case.
#include <algorithm>
#include <cmath>

#include "methods/multi_imu_internal.h"
#include "methods/static_positions.h"

namespace gravcal {
namespace internal {
namespace {

constexpr const char* kPlateIntrinsicNames[21] = {
    "bias_x", "bias_y", "bias_z",      "u_xx",        "u_xy",        "u_xz", "u_yy",
    "u_yz",   "u_zz",   "gyro_bias_x", "gyro_bias_y", "gyro_bias_z", "m_xx", "m_xy",
    "m_xz",   "m_yx",   "m_yy",        "m_yz",        "m_zx",        "m_zy", "m_zz"};

}  // namespace

// The per-IMU Calibration in the existing schema.
void FillCalibration(const PlateImuData& imu, const PlateImuParameters& p,
                     const Eigen::MatrixXd& cov, double gravity, Calibration* c) {
  c->success = true;
  c->method = "multi_imu";
  c->gravity = gravity;
  c->gravity_source = "config";
  AccelModel& a = c->accel.model;
  a.parameterization = AccelParameterization::kScaleMisalignment;
  a.bias = Eigen::Vector3d(p.bias[0], p.bias[1], p.bias[2]);
  a.SetUpper(p.upper);
  a.rotation.setIdentity();
  const int accel_n = 9;
  auto sd = [&](int k) { return std::sqrt(cov(k, k)); };
  for (int j = 0; j < 3; ++j) c->accel.bias_std[j] = sd(j);
  c->accel.matrix_std.setConstant(NAN);
  const int rc[6][2] = {{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}};
  for (int k = 0; k < 6; ++k) c->accel.matrix_std(rc[k][0], rc[k][1]) = sd(3 + k);
  c->accel.covariance = cov.topLeftCorner(accel_n, accel_n);
  c->accel.covariance_names.assign(kPlateIntrinsicNames, kPlateIntrinsicNames + accel_n);
  if (imu.has_gyro) {
    GyroCalibration& g = c->gyro;
    g.estimated = true;
    g.model.bias = Eigen::Vector3d(p.gyro_bias[0], p.gyro_bias[1], p.gyro_bias[2]);
    g.model.matrix = p.GyroMatrix();
    for (int j = 0; j < 3; ++j) g.bias_std[j] = sd(9 + j);
    for (int k = 0; k < 9; ++k) g.matrix_std(k / 3, k % 3) = sd(12 + k);
    g.covariance = cov.block(9, 9, 12, 12);
    g.covariance_names = {"bias_x", "bias_y", "bias_z", "m_xx", "m_xy", "m_xz",
                          "m_yx",   "m_yy",   "m_yz",   "m_zx", "m_zy", "m_zz"};
  }
  // Each shared pose as a position of this IMU (its hold's samples, mean
  // and noise: what the acceptance limits' noise density reads).
  std::vector<double> residuals;
  c->positions.clear();
  const ImuLog& log = imu.imu->log;
  for (const PlatePoseData& pose : imu.poses) {
    Eigen::Vector3d m = a.upper * (pose.accel_mean - a.bias);
    residuals.push_back(m.norm() - gravity);
    PositionReport r;
    r.position.raw_mean = pose.accel_mean;
    r.position.sample_count = pose.end - pose.begin;
    r.position.raw_mean_cov = pose.accel_raw_std.array().square().matrix().asDiagonal();
    r.position.raw_mean_cov /= static_cast<double>(std::max<size_t>(1, r.position.sample_count));
    r.position.t_begin = pose.begin < log.size() ? log.t[pose.begin] : NAN;
    r.position.t_end = pose.end >= 1 && pose.end <= log.size() ? log.t[pose.end - 1] : NAN;
    r.position.temperature = NAN;
    r.raw_std = pose.accel_raw_std;
    r.residual_after = residuals.back();
    r.sigma = pose.accel_sigma;
    c->positions.push_back(r);
  }
  c->residual_refined = SummarizeResiduals(residuals);
  MeasureGyroHoldNoise(log, NAN, c);
  c->message = "multi_imu: calibrated on the plate's shared poses";
}

// The standard deviations of [b U b_g M_g] (21; gyro NaN when absent).
std::vector<double> StdsOf(const Eigen::MatrixXd& cov, bool gyro) {
  std::vector<double> s(21, NAN);
  for (int k = 0; k < 9; ++k) s[k] = std::sqrt(cov(k, k));
  if (gyro) {
    for (int k = 9; k < 21; ++k) s[k] = std::sqrt(cov(k, k));
  }
  return s;
}

// Expands a member covariance without gyro (9 + 3) to the 24 layout.
Eigen::MatrixXd FullLayout(const Eigen::MatrixXd& cov, bool gyro) {
  if (gyro) return cov;
  Eigen::MatrixXd full = Eigen::MatrixXd::Constant(24, 24, NAN);
  full.topLeftCorner(9, 9) = cov.topLeftCorner(9, 9);
  full.bottomRightCorner(3, 3) = cov.bottomRightCorner(3, 3);
  full.block(0, 21, 9, 3) = cov.block(0, 9, 9, 3);
  full.block(21, 0, 3, 9) = cov.block(9, 0, 3, 9);
  return full;
}

void SinglePose(const std::vector<PlateImuData>& data, const MultiImuOptions& options,
                MultiImuResult* result) {
  const int ref = options.reference;
  // The reference's up direction and each unit's, nominal scale.
  std::vector<Eigen::Vector3d> up(data.size());
  for (size_t i = 0; i < data.size(); ++i) {
    const PlatePoseData& pose = data[i].poses[0];
    const double s = data[i].imu->accel_scale;
    const Eigen::Vector3d a = pose.accel_mean * s;
    up[i] = a.normalized();
    PlateImuResult& r = result->imus[i];
    r.up_offset = a.norm() - options.gravity;
    r.up_offset_std = pose.accel_sigma;
    Calibration& c = r.calibration;
    c.success = true;
    c.method = "multi_imu";
    c.gravity = options.gravity;
    c.accel.model.bias.setZero();
    c.accel.model.upper = Eigen::Matrix3d::Identity() * s;
    c.message =
        "multi_imu: one pose: only the offset along gravity (bias plus scale error along the "
        "up axis) is determined; bias, scale and non-orthogonality are not";
    c.warnings.push_back(c.message);
    r.joint_std.assign(21, NAN);
  }
  for (size_t i = 0; i < data.size(); ++i) {
    // The tilt between the units: the shortest rotation; the heading about
    // gravity is not determined.
    result->imus[i].rotation =
        Eigen::Quaterniond::FromTwoVectors(up[i], up[ref]).toRotationMatrix();
  }
  result->undetermined.push_back(
      "one pose: each unit's bias, scale, non-orthogonality and gyroscope model are not "
      "determined; only each unit's offset along gravity is (its up_offset)");
  result->undetermined.push_back(
      "one pose: the rotation between the units is determined only up to a turn about gravity "
      "(the tilt between them is known, the heading not)");
  result->undetermined.push_back("one pose: no turns, so no time offsets");
  result->success = true;
  result->message = "multi_imu: one shared pose; offsets along gravity only";
}

}  // namespace internal
}  // namespace gravcal
