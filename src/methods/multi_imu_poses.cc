// The multi-IMU calibration's data (methods/multi_imu.h): the poses every
// IMU holds still, each IMU's view of them, and the starting values of its
// intrinsics.
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "methods/multi_imu_internal.h"

namespace gravcal {
namespace internal {

// Starting intrinsics of one IMU from its poses: an axis-aligned ellipsoid
// sum_j a_j (v_j - c_j)^2 = 1 through the pose means (a sphere with fewer
// than 6 poses, the nominal scale with fewer than 4), then b = c and
// U = diag(g sqrt(a_j)).
void StartIntrinsics(const PlateImuData& imu, double gravity, PlateImuParameters* p) {
  const size_t n = imu.poses.size();
  const double s = imu.imu->accel_scale;
  for (int j = 0; j < 6; ++j) p->upper[j] = 0.0;
  p->upper[0] = p->upper[3] = p->upper[5] = s;
  for (int j = 0; j < 3; ++j) p->bias[j] = 0.0;
  if (n >= 6) {
    Eigen::MatrixXd a(n, 6);
    Eigen::VectorXd one = Eigen::VectorXd::Ones(n);
    for (size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d v = imu.poses[k].accel_mean * s;
      a.row(k) << v.x() * v.x(), v.y() * v.y(), v.z() * v.z(), v.x(), v.y(), v.z();
    }
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(one);
    if (x.allFinite() && x[0] > 0 && x[1] > 0 && x[2] > 0) {
      Eigen::Vector3d c;
      double k = 1.0;
      for (int j = 0; j < 3; ++j) {
        c[j] = -x[3 + j] / (2.0 * x[j]);
        k += x[j] * c[j] * c[j];
      }
      if (k > 0.0) {
        for (int j = 0; j < 3; ++j) p->bias[j] = c[j] / s;
        p->upper[0] = s * gravity * std::sqrt(x[0] / k);
        p->upper[3] = s * gravity * std::sqrt(x[1] / k);
        p->upper[5] = s * gravity * std::sqrt(x[2] / k);
        return;
      }
    }
  }
  if (n >= 4) {
    // |v - c|^2 = r^2: 2 v.c + (r^2 - |c|^2) = |v|^2.
    Eigen::MatrixXd a(n, 4);
    Eigen::VectorXd y(n);
    for (size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d v = imu.poses[k].accel_mean * s;
      a.row(k) << 2.0 * v.x(), 2.0 * v.y(), 2.0 * v.z(), 1.0;
      y[k] = v.squaredNorm();
    }
    const Eigen::VectorXd x = a.colPivHouseholderQr().solve(y);
    const double r2 = x[3] + x.head<3>().squaredNorm();
    if (x.allFinite() && r2 > 0.0) {
      for (int j = 0; j < 3; ++j) p->bias[j] = x[j] / s;
      const double u = s * gravity / std::sqrt(r2);
      p->upper[0] = p->upper[3] = p->upper[5] = u;
    }
  }
}

// Starting gyroscope: b_g the mean of the still means, M_g = s I with s
// the stated scale, or the data's when the two differ by more than 30 %:
// the largest ratio over the turns of the tilt between the two poses
// (from the accelerometer) to the integrated raw rate |sum (u - b_g) dt|
// (a turn about a horizontal axis shows its whole angle as tilt).
void StartGyro(const PlateImuData& imu, const std::vector<Eigen::Vector3d>& dirs,
               PlateImuParameters* p, std::vector<std::string>* notes) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const PlatePoseData& pose : imu.poses) mean += pose.gyro_mean;
  mean /= static_cast<double>(std::max<size_t>(1, imu.poses.size()));
  for (int j = 0; j < 3; ++j) p->gyro_bias[j] = mean[j];
  double data_scale = 0.0;
  for (size_t k = 0; k < imu.turns.size(); ++k) {
    const GyroRotationData& turn = imu.turns[k];
    if (turn.t.size() < 2) continue;
    const double tilt = std::acos(std::clamp(dirs[k].dot(dirs[k + 1]), -1.0, 1.0));
    if (tilt < 20.0 * M_PI / 180.0) continue;
    Eigen::Vector3d phi = Eigen::Vector3d::Zero();
    for (size_t j = 1; j < turn.t.size(); ++j) {
      phi += 0.5 * (turn.gyro[j] + turn.gyro[j - 1] - 2.0 * mean) * (turn.t[j] - turn.t[j - 1]);
    }
    if (phi.norm() > 0.0) data_scale = std::max(data_scale, tilt / phi.norm());
  }
  double scale = imu.imu->gyro_scale;
  if (data_scale > 0.0 && std::abs(std::log(data_scale / scale)) > std::log(1.3)) {
    std::ostringstream s;
    s << imu.imu->name << ": the turns show a gyroscope scale of about " << data_scale
      << " rad/s per raw unit, not the stated " << scale << ": started from the data's";
    notes->push_back(s.str());
    scale = data_scale;
  }
  for (int j = 0; j < 9; ++j) p->gyro_matrix[j] = j % 4 == 0 ? scale : 0.0;
}

// Intervals of `log` matched to the reference's by time: the shared pose is
// the intersection of one interval of every IMU.
bool SharedPoses(const std::vector<PlateImu>& imus, const std::vector<StaticDetection>& detections,
                 int reference, std::vector<std::pair<double, double>>* windows,
                 std::vector<std::string>* notes) {
  for (const StaticInterval& r : detections[reference].intervals) {
    double begin = r.t_begin, end = r.t_end;
    bool all = true;
    for (size_t i = 0; i < imus.size() && all; ++i) {
      if (static_cast<int>(i) == reference) continue;
      double best = 0.0;
      double b = 0.0, e = 0.0;
      for (const StaticInterval& o : detections[i].intervals) {
        const double overlap = std::min(o.t_end, end) - std::max(o.t_begin, begin);
        if (overlap > best) {
          best = overlap;
          b = o.t_begin;
          e = o.t_end;
        }
      }
      if (best < 0.5 * (r.t_end - r.t_begin)) {
        all = false;
        break;
      }
      begin = std::max(begin, b);
      end = std::min(end, e);
    }
    if (!all) {
      std::ostringstream s;
      s << "the still period at " << r.t_begin << "-" << r.t_end
        << " s is not still in every IMU: left out";
      notes->push_back(s.str());
      continue;
    }
    windows->push_back({begin, end});
  }
  return true;
}

PlatePoseData PoseOf(const ImuLog& log, double begin, double end) {
  PlatePoseData p;
  p.begin = std::lower_bound(log.t.begin(), log.t.end(), begin) - log.t.begin();
  p.end = std::upper_bound(log.t.begin(), log.t.end(), end) - log.t.begin();
  if (p.end <= p.begin) p.end = std::min(log.size(), p.begin + 1);
  const StaticInterval s = MakeInterval(log, p.begin, p.end);
  const double n = static_cast<double>(std::max<size_t>(1, s.count()));
  p.accel_mean = s.accel_mean;
  p.accel_raw_std = s.accel_cov.diagonal().cwiseMax(0.0).cwiseSqrt();
  // Each axis at least its quantisation: step^2 / 12, the step the smallest
  // nonzero change between samples (and a relative floor for data with
  // none, such as a constant reading).
  const double accel_step2 = s.accel_resolution.squaredNorm() / 3.0;
  const double accel_var = std::max(
      {s.accel_cov.trace() / 3.0, accel_step2 / 12.0, 1e-24 * s.accel_mean.squaredNorm() + 1e-300});
  p.accel_sigma = std::sqrt(accel_var / n);
  p.gyro_mean = s.gyro_mean;
  double gyro_step2 = 0.0;
  if (log.has_gyro()) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (size_t k = p.begin + 1; k < std::min(p.end, p.begin + 256); ++k) {
      for (int j = 0; j < 3; ++j) {
        const double d = std::abs(log.gyro[k][j] - log.gyro[k - 1][j]);
        if (d > 0.0 && (step[j] == 0.0 || d < step[j])) step[j] = d;
      }
    }
    gyro_step2 = step.squaredNorm() / 3.0;
  }
  p.gyro_sigma = std::sqrt(std::max({s.gyro_cov.trace() / 3.0, gyro_step2 / 12.0, 1e-30}) / n);
  return p;
}

}  // namespace internal
}  // namespace gravcal
