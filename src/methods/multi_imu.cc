// The multi-IMU calibration (methods/multi_imu.h) in order: the shared
// poses, each IMU's separate fit, the joint start (rotations by Wahba, a
// flipped axis), the joint fit, a moved unit, the timing and the checks.
#include "gravcal/methods/multi_imu.h"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <exception>
#include <set>
#include <sstream>

#include "methods/multi_imu_internal.h"

namespace gravcal {
namespace internal {
namespace {

// sum |x_k - R S y_k|^2 at the best rotation R, S the sign change of axis
// `flip` (-1: none).
double DirectionMisfit(const std::vector<Eigen::Vector3d>& x, std::vector<Eigen::Vector3d> y,
                       int flip) {
  if (flip >= 0) {
    for (Eigen::Vector3d& v : y) v[flip] = -v[flip];
  }
  const Eigen::Matrix3d r = Wahba(x, y);
  double c = 0.0;
  for (size_t k = 0; k < x.size(); ++k) c += (x[k] - r * y[k]).squaredNorm();
  return c;
}

}  // namespace

Eigen::Matrix3d PlateImuParameters::Rotation() const {
  const Eigen::Vector3d d(delta[0], delta[1], delta[2]);
  if (d.norm() == 0.0) return c0;
  return c0 * Eigen::AngleAxisd(d.norm(), d.normalized()).toRotationMatrix();
}

Eigen::Matrix3d PlateImuParameters::RotationAfter() const {
  const Eigen::Vector3d d(delta_after[0], delta_after[1], delta_after[2]);
  if (d.norm() == 0.0) return c0_after;
  return c0_after * Eigen::AngleAxisd(d.norm(), d.normalized()).toRotationMatrix();
}

Eigen::Matrix3d PlateImuParameters::UpperMatrix() const {
  Eigen::Matrix3d u = Eigen::Matrix3d::Zero();
  u(0, 0) = upper[0];
  u(0, 1) = upper[1];
  u(0, 2) = upper[2];
  u(1, 1) = upper[3];
  u(1, 2) = upper[4];
  u(2, 2) = upper[5];
  return u;
}

Eigen::Matrix3d PlateImuParameters::GyroMatrix() const {
  Eigen::Matrix3d m;
  for (int k = 0; k < 9; ++k) m(k / 3, k % 3) = gyro_matrix[k];
  return m;
}

Eigen::Vector3d PlateImuParameters::Direction(const PlatePoseData& pose) const {
  return (UpperMatrix() * (pose.accel_mean - Eigen::Vector3d(bias[0], bias[1], bias[2])))
      .normalized();
}

Eigen::Matrix3d Wahba(const std::vector<Eigen::Vector3d>& x,
                      const std::vector<Eigen::Vector3d>& y) {
  Eigen::Matrix3d b = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < x.size(); ++k) b += x[k] * y[k].transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(b, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * d * svd.matrixV().transpose();
}

}  // namespace internal

bool MultiImuOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = "multi_imu: " + what;
    return false;
  };
  if (!(gravity > 0.0) || !std::isfinite(gravity)) return fail("gravity must be > 0");
  if (reference < 0) return fail("reference must be >= 0");
  if (!(timing_margin >= 0.0) || !(max_time_offset > 0.0))
    return fail("timing_margin must be >= 0 and max_time_offset > 0");
  if (!(permutation_tolerance_deg > 0.0) || !(mounting_warning_deg > 0.0) ||
      !(slip_min_deg > 0.0) || !(slip_factor > 0.0) || !(drift_factor > 0.0) || !(drift_min >= 0.0))
    return fail("the check thresholds must be > 0");
  if (max_iterations < 1) return fail("max_iterations must be >= 1");
  return detector.IsValid(error);
}

namespace {

bool CalibrateImpl(const std::vector<PlateImu>& imus, const MultiImuOptions& options,
                   MultiImuResult* result) {
  using namespace internal;
  *result = MultiImuResult();
  std::string error;
  if (!options.IsValid(&error)) {
    result->message = error;
    return false;
  }
  if (imus.empty()) {
    result->message = "multi_imu: no IMUs";
    return false;
  }
  if (options.reference >= static_cast<int>(imus.size())) {
    result->message = "multi_imu: the reference index is past the IMUs";
    return false;
  }
  std::set<std::string> names;
  for (const PlateImu& imu : imus) {
    if (!names.insert(imu.name).second) {
      result->message = "multi_imu: IMU name '" + imu.name + "' is given twice";
      return false;
    }
    if (!(imu.accel_scale > 0.0) || !(imu.gyro_scale > 0.0)) {
      result->message = "multi_imu: " + imu.name + ": accel and gyro scales must be > 0";
      return false;
    }
  }
  const int ref = options.reference;
  result->reference = ref;
  // Detection per IMU, then the shared poses.
  std::vector<StaticDetection> detections(imus.size());
  for (size_t i = 0; i < imus.size(); ++i) {
    if (!imus[i].log.Validate(&error)) {
      result->message = imus[i].name + ": " + error;
      return false;
    }
    if (!DetectStaticIntervals(imus[i].log, options.detector, &detections[i])) {
      result->message = imus[i].name + ": " + detections[i].message;
      return false;
    }
  }
  std::vector<std::pair<double, double>> windows;
  SharedPoses(imus, detections, ref, &windows, &result->warnings);
  if (windows.empty()) {
    result->message = "multi_imu: no still period is shared by every IMU";
    return false;
  }
  const size_t pose_count = windows.size();
  result->poses = static_cast<int>(pose_count);
  std::vector<PlateImuData> data(imus.size());
  for (size_t i = 0; i < imus.size(); ++i) {
    PlateImuData& d = data[i];
    d.imu = &imus[i];
    d.has_gyro = imus[i].log.has_gyro();
    double gyro_var = 0.0, accel_var = 0.0;
    for (const auto& [b, e] : windows) {
      d.poses.push_back(PoseOf(imus[i].log, b, e));
      const PlatePoseData& p = d.poses.back();
      const double n = static_cast<double>(p.end - p.begin);
      accel_var += p.accel_sigma * p.accel_sigma * n;
      gyro_var += p.gyro_sigma * p.gyro_sigma * n;
    }
    d.accel_noise = std::sqrt(accel_var / pose_count) * imus[i].accel_scale;
    d.gyro_noise = std::sqrt(gyro_var / pose_count) * imus[i].gyro_scale;
    // Convert the accelerometer sigmas to m/s^2.
    for (PlatePoseData& p : d.poses) p.accel_sigma *= imus[i].accel_scale;
  }
  result->imus.resize(imus.size());
  for (size_t i = 0; i < imus.size(); ++i) result->imus[i].name = imus[i].name;
  if (pose_count == 1) {
    SinglePose(data, options, result);
    return true;
  }
  // Turns.
  for (PlateImuData& d : data) {
    d.turns.resize(pose_count - 1);
    if (!d.has_gyro) continue;
    const ImuLog& log = d.imu->log;
    for (size_t k = 0; k + 1 < pose_count; ++k) {
      const size_t first = d.poses[k].end - 1, last = d.poses[k + 1].begin;
      if (last <= first + 1 || log.t[last] - log.t[first] > 120.0) continue;
      GyroRotationData& turn = d.turns[k];
      turn.t.assign(log.t.begin() + first, log.t.begin() + last + 1);
      turn.gyro.assign(log.gyro.begin() + first, log.gyro.begin() + last + 1);
      double h2 = 0.0;
      for (size_t j = 1; j < turn.t.size(); ++j) {
        h2 += std::pow(turn.t[j] - turn.t[j - 1], 2);
      }
      const double sigma = std::sqrt(d.gyro_noise * d.gyro_noise * h2 + 1e-12);
      turn.sqrt_information = Eigen::Matrix2d::Identity() / sigma;
    }
  }
  // Separate fits: each IMU alone, its own poses.
  std::vector<PlateImuParameters> separate(imus.size());
  std::vector<std::vector<Eigen::Vector3d>> own_dirs(imus.size());
  std::vector<FitOutput> separate_out(imus.size());
  std::vector<GroupFactors> own_factors(imus.size());
  for (size_t i = 0; i < imus.size(); ++i) {
    PlateImuParameters& p = separate[i];
    StartIntrinsics(data[i], options.gravity, &p);
    for (const PlatePoseData& pose : data[i].poses) own_dirs[i].push_back(p.Direction(pose));
    if (data[i].has_gyro) StartGyro(data[i], own_dirs[i], &p, &result->warnings);
    for (size_t k = 0; k < data[i].turns.size(); ++k) {
      data[i].turns[k].tangent = TangentBasis(own_dirs[i][k + 1]);
    }
    std::vector<GroupFactors> f;
    if (!FitWithFactors(data, {static_cast<int>(i)}, static_cast<int>(i), options.gravity,
                        options.max_iterations, {}, &separate, &own_dirs[i], &f,
                        &separate_out[i])) {
      result->message = imus[i].name + ": " + separate_out[i].message;
      return false;
    }
    own_factors[i] = f[0];
  }
  // The joint start: intrinsics from the separate fits, rotations by Wahba
  // between each IMU's directions and the reference's.
  std::vector<PlateImuParameters> joint = separate;
  std::vector<Eigen::Vector3d> dirs = own_dirs[ref];
  for (size_t i = 0; i < imus.size(); ++i) {
    PlateImuParameters& p = joint[i];
    for (int j = 0; j < 3; ++j) p.delta[j] = 0.0;
    if (static_cast<int>(i) != ref) {
      // Left-handed axes: one axis read with the wrong sign shows as a
      // reflection between the two sets of directions; the axis whose sign
      // change fits best is flipped in U (row j of U negated) and named.
      // A sign change of one axis equals that of another times a half turn:
      // the axis is the one that leaves the rotation nearest the stated.
      int flip = -1;
      const double none = DirectionMisfit(dirs, own_dirs[i], -1);
      const Eigen::Matrix3d stated =
          imus[ref].stated_mounting.transpose() * imus[i].stated_mounting;
      double nearest = 1e300;
      for (int j = 0; j < 3; ++j) {
        std::vector<Eigen::Vector3d> y = own_dirs[i];
        for (Eigen::Vector3d& v : y) v[j] = -v[j];
        if (DirectionMisfit(dirs, y, -1) >= 0.25 * none) continue;
        const Eigen::Matrix3d r = stated.transpose() * Wahba(dirs, y);
        const double angle = std::acos(std::clamp((r.trace() - 1.0) / 2.0, -1.0, 1.0));
        if (angle < nearest) {
          nearest = angle;
          flip = j;
        }
      }
      if (flip >= 0) {
        const int row[3][3] = {{0, 1, 2}, {-1, 3, 4}, {-1, -1, 5}};
        for (int c = 0; c < 3; ++c) {
          if (row[flip][c] >= 0) p.upper[row[flip][c]] = -p.upper[row[flip][c]];
        }
        for (Eigen::Vector3d& d : own_dirs[i]) d[flip] = -d[flip];
        // The gyroscope's axis reads with the same wrong sign: M_g = s S.
        const double scale =
            (std::abs(p.gyro_matrix[0]) + std::abs(p.gyro_matrix[4]) + std::abs(p.gyro_matrix[8])) /
            3.0;
        for (int k = 0; k < 9; ++k) p.gyro_matrix[k] = k % 4 == 0 ? scale : 0.0;
        p.gyro_matrix[4 * flip] = -scale;
        result->warnings.push_back(imus[i].name + "'s " + std::string(1, "xyz"[flip]) +
                                   " accelerometer axis reads with the wrong sign (its axes are "
                                   "left-handed): flipped or miswired axis?");
      }
    }
    p.c0 = static_cast<int>(i) == ref ? Eigen::Matrix3d::Identity() : Wahba(dirs, own_dirs[i]);
    for (size_t k = 0; k < data[i].turns.size(); ++k) {
      data[i].turns[k].tangent = TangentBasis(p.c0.transpose() * dirs[k + 1]);
    }
  }
  std::vector<int> members;
  for (size_t i = 0; i < imus.size(); ++i) members.push_back(static_cast<int>(i));
  std::vector<GroupFactors> factors;
  FitOutput out;
  if (!FitWithFactors(data, members, ref, options.gravity, options.max_iterations, own_factors,
                      &joint, &dirs, &factors, &out)) {
    result->message = out.message;
    return false;
  }
  // A unit that moved: its own rotation after the move, and fit again.
  int split = -1;
  const int moved = FindMovedUnit(data, joint, options, &split, result);
  if (moved >= 0) {
    PlateImuParameters& p = joint[moved];
    p.split = split;
    std::vector<Eigen::Vector3d> x, y;
    for (size_t k = split; k < pose_count; ++k) {
      x.push_back(dirs[k]);
      y.push_back(p.Direction(data[moved].poses[k]));
    }
    p.c0_after = Wahba(x, y);
    for (int j = 0; j < 3; ++j) p.delta_after[j] = 0.0;
    for (size_t k = split; k < data[moved].turns.size(); ++k) {
      data[moved].turns[k].tangent = TangentBasis(p.c0_after.transpose() * dirs[k + 1]);
    }
    if (!FitWithFactors(data, members, ref, options.gravity, options.max_iterations, own_factors,
                        &joint, &dirs, &factors, &out)) {
      result->message = out.message;
      return false;
    }
  }
  // The separate calibrations' sigmas: each IMU's own fit with its own
  // variance factors, as a calibration of that IMU alone would report them.
  if (options.separate) {
    for (size_t i = 0; i < imus.size(); ++i) {
      if (separate_out[i].covariance.empty()) continue;
      result->imus[i].separate_std = StdsOf(separate_out[i].covariance[0], data[i].has_gyro);
    }
  }
  for (size_t i = 0; i < imus.size(); ++i) {
    PlateImuResult& r = result->imus[i];
    r.accel_factor = factors[i].accel;
    r.gyro_factor = factors[i].gyro;
    r.turn_factor = factors[i].turn;
    result->accel_factor = std::max(result->accel_factor, r.accel_factor);
    result->gyro_factor = std::max(result->gyro_factor, r.gyro_factor);
    result->turn_factor = std::max(result->turn_factor, r.turn_factor);
  }
  for (size_t i = 0; i < imus.size(); ++i) {
    PlateImuResult& r = result->imus[i];
    const Eigen::MatrixXd cov = FullLayout(out.covariance[i], data[i].has_gyro);
    FillCalibration(data[i], joint[i], cov, options.gravity, &r.calibration);
    r.joint_std = StdsOf(cov, data[i].has_gyro);
    r.rotation = joint[i].Rotation();
    r.rotation_covariance = cov.bottomRightCorner(3, 3);
    for (int j = 0; j < 3; ++j) r.rotation_std[j] = std::sqrt(r.rotation_covariance(j, j));
    if (static_cast<int>(i) == ref) {
      r.rotation_std.setZero();
      r.rotation_covariance.setZero();
    }
    r.accel_residual_rms = out.accel_rms[i];
    r.turn_residual_deg = out.turn_rms_deg[i];
    bool any_nan = false;
    for (double s : r.joint_std) any_nan = any_nan || !std::isfinite(s);
    if (any_nan && data[i].has_gyro) {
      r.calibration.warnings.push_back("the session does not determine every parameter of " +
                                       imus[i].name + " (those with no standard deviation)");
    }
  }
  result->turns = 0;
  for (const GyroRotationData& t : data[ref].turns) result->turns += t.t.size() >= 2;
  CheckMountings(data, joint, ref, options, result);
  EstimateTimeOffsets(data, joint, ref, options, result);
  result->undetermined.push_back(
      "the lever arm between the IMUs is not observable from gravity and slow turns: not "
      "estimated (the rotations and time offsets do not depend on it)");
  if (result->turns == 0) {
    result->undetermined.push_back(
        "static poses alone give no time offset: the session has no turns between its poses");
  }
  result->success = true;
  std::ostringstream s;
  s << "multi_imu: " << imus.size() << " IMUs on " << pose_count << " shared poses and "
    << result->turns << " turns";
  result->message = s.str();
  return true;
}

}  // namespace

bool CalibrateMultiImu(const std::vector<PlateImu>& imus, const MultiImuOptions& options,
                       MultiImuResult* result) {
  if (result == nullptr) return false;
  try {
    return CalibrateImpl(imus, options, result);
  } catch (const std::exception& e) {
    result->success = false;
    result->message = std::string("multi_imu failed: ") + e.what();
    return false;
  }
}

}  // namespace gravcal
