#include "methods/gyro_rotations.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "estimation/variance_component.h"
#include "methods/direction_noise.h"
#include "methods/gyro_initial_matrix.h"

namespace gravcal {
namespace internal {
namespace {

// Rotations needed at least, per parameterization (2 residuals each; the
// bias comes from the static poses).
int MinRotations(GyroParameterization p) {
  switch (p) {
    case GyroParameterization::kBias:
      return 1;
    case GyroParameterization::kScale:
      return 2;
    default:
      return 5;
  }
}

// The smallest nonzero step between consecutive raw gyroscope samples in
// the static intervals (the quantisation step), or 0.
double GyroStep(const ImuLog& log, const std::vector<StaticInterval>& intervals) {
  double step = 0.0;
  for (const StaticInterval& s : intervals) {
    const size_t end = std::min(s.end, s.begin + 256);
    for (size_t i = s.begin + 1; i < end; ++i) {
      for (int a = 0; a < 3; ++a) {
        const double d = std::fabs(log.gyro[i](a) - log.gyro[i - 1](a));
        if (d > 0.0 && (step == 0.0 || d < step)) step = d;
      }
    }
  }
  return step;
}

// The static poses: every interval without edge_seconds at both ends (at
// most a quarter of it), which go to the rotations.
bool CorePoses(const ImuLog& log, const std::vector<StaticInterval>& intervals, double edge_seconds,
               const std::string& name, std::vector<StaticInterval>* poses, std::string* error) {
  for (size_t k = 0; k < intervals.size(); ++k) {
    const StaticInterval& iv = intervals[k];
    if (iv.begin + 2 > iv.end || iv.end > log.size() ||
        (k > 0 && iv.begin < intervals[k - 1].end)) {
      std::ostringstream s;
      s << name << ": static interval " << k << " (samples " << iv.begin << ".." << iv.end
        << ") is empty, outside the log or not after the previous one";
      *error = s.str();
      return false;
    }
    const double dt =
        (log.t[iv.end - 1] - log.t[iv.begin]) / static_cast<double>(iv.end - 1 - iv.begin);
    const size_t edge = std::min<size_t>(std::lround(edge_seconds / dt), (iv.end - iv.begin) / 4);
    poses->push_back(MakeInterval(log, iv.begin + edge, iv.end - edge));
  }
  return true;
}

// Rotations: from the last sample of one pose to the first of the next;
// those longer than max_rotation_seconds are left out with a warning.
std::vector<GyroSegment> CutRotations(const ImuLog& log, const std::vector<StaticInterval>& poses,
                                      double max_rotation_seconds,
                                      std::vector<std::string>* warnings) {
  std::vector<GyroSegment> segments;
  for (size_t k = 0; k + 1 < poses.size(); ++k) {
    GyroSegment seg;
    seg.from = static_cast<int>(k);
    seg.to = static_cast<int>(k + 1);
    seg.first = poses[k].end - 1;
    seg.last = poses[k + 1].begin;
    const double seconds = log.t[seg.last] - log.t[seg.first];
    if (seconds > max_rotation_seconds) {
      std::ostringstream s;
      s.precision(3);
      s << "the " << seconds << " s between static poses " << k << " and " << k + 1
        << " (t = " << log.t[seg.first] << " s) is longer than max_rotation_seconds; it is not "
        << "used as a rotation";
      warnings->push_back(s.str());
      continue;
    }
    segments.push_back(seg);
  }
  return segments;
}

// Gyroscope noise: the pooled per-sample covariance of the static poses
// (*pooled) and their weighted mean reading (*center).
bool PooledGyroNoise(const ImuLog& log, const std::vector<StaticInterval>& poses,
                     const std::string& name, Eigen::Matrix3d* pooled_out,
                     Eigen::Vector3d* center_out, std::string* error) {
  Eigen::Matrix3d pooled = Eigen::Matrix3d::Zero();
  double weight = 0.0, count = 0.0;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  for (const StaticInterval& s : poses) {
    const double n = static_cast<double>(s.count());
    pooled += (n - 1.0) * s.gyro_cov;
    weight += n - 1.0;
    center += n * s.gyro_mean;
    count += n;
  }
  pooled /= weight;
  center /= count;
  Eigen::Matrix3d unused;
  if (!SqrtInformation<3>(pooled, &unused)) {
    // Quantised output that never changes while still: the mean is known to
    // the uniform quantisation error, step^2 / 12.
    const double step = GyroStep(log, poses);
    pooled.diagonal().array() += step > 0.0 ? step * step / 12.0 : 0.0;
    if (!SqrtInformation<3>(pooled, &unused)) {
      *error = name +
               ": the gyroscope shows no noise at all in the static poses; its noise "
               "cannot be estimated";
      return false;
    }
  }
  *pooled_out = pooled;
  *center_out = center;
  return true;
}

// The rotations and static poses in normalised units (prep->center and
// prep->scale set), with the calibrated specific force along every rotation.
void NormaliseData(const ImuLog& log, const std::vector<StaticInterval>& poses,
                   const AccelModel& accel, const std::vector<std::vector<Eigen::Vector3d>>& forces,
                   GyroPrepared* prep) {
  const double k = prep->scale;
  const Eigen::Vector3d& center = prep->center;
  for (size_t j = 0; j < prep->segments.size(); ++j) {
    const GyroSegment& seg = prep->segments[j];
    GyroRotationData d;
    for (size_t i = seg.first; i <= seg.last; ++i) {
      d.t.push_back(log.t[i]);
      d.gyro.push_back((log.gyro[i] - center) * k);
    }
    d.force = forces[j];
    d.accel_rotation = accel.rotation;
    prep->rotations.push_back(d);
  }
  Eigen::Matrix3d unused;
  for (size_t k2 = 0; k2 < poses.size(); ++k2) {
    const StaticInterval& s = poses[k2];
    const double n = static_cast<double>(s.count());
    prep->static_gyro.push_back((s.gyro_mean - center) * k);
    Eigen::Matrix3d cov = s.gyro_cov / n;
    if (!SqrtInformation<3>(cov, &unused)) cov = prep->gyro_cov / n;
    prep->static_gyro_cov.push_back(cov * k * k);
    prep->static_force.push_back(accel.Apply(s.accel_mean));
  }
}

// The scatter of the static poses' mean rates beyond their white noise
// (bias instability, bias random walk, unmodelled Earth rate): one variance
// s^2 common to every axis and pose, estimated by REML from the pose means
// around their common value b (+ G f_k when G is estimated), whose
// parameters are the columns of J; added to every static pose's covariance.
// Not a warning: hand-placed poses show it as a matter of course.
void AddStaticPoseVariance(const GyroCalibrationOptions& options, GyroPrepared* prep) {
  const int n = static_cast<int>(prep->static_gyro.size());
  const int p = options.g_sensitivity ? 12 : 3;
  if (3 * n <= p) return;
  Eigen::VectorXd r(3 * n), sigmas(3 * n);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(3 * n, p);
  for (int k = 0; k < n; ++k) {
    for (int i = 0; i < 3; ++i) {
      r(3 * k + i) = prep->static_gyro[k](i);
      sigmas(3 * k + i) = std::sqrt(std::max(prep->static_gyro_cov[k](i, i), 1e-300));
      jacobian(3 * k + i, i) = 1.0;
      for (int j = 0; j < 3 && options.g_sensitivity; ++j) {
        jacobian(3 * k + i, 3 + 3 * i + j) = prep->static_force[k](j);
      }
    }
  }
  VarianceComponent vc;
  if (!EstimateVarianceComponent(r, sigmas, jacobian, &vc) || vc.at_boundary) return;
  for (Eigen::Matrix3d& c : prep->static_gyro_cov) c += vc.variance * Eigen::Matrix3d::Identity();
  prep->static_variance = vc.variance;
  prep->static_variance_dof = vc.dof;
}

}  // namespace

bool PrepareGyroRotations(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                          const AccelModel& accel, const GyroCalibrationOptions& options,
                          GyroPrepared* prep, Eigen::Matrix3d* m0,
                          std::vector<std::string>* warnings, std::string* error) {
  const std::string name = log.source.empty() ? "log" : log.source;
  if (!log.Validate(error)) return false;
  if (!log.has_gyro()) {
    *error = name +
             ": the log has no gyroscope columns (gx, gy, gz); the gyroscope calibration needs "
             "them (set gyro_model: none to calibrate the accelerometer only)";
    return false;
  }
  if (intervals.size() < 2) {
    std::ostringstream s;
    s << name << ": found " << intervals.size()
      << " static poses; the gyroscope calibration needs at least two (and rotations between "
         "them)";
    *error = s.str();
    return false;
  }
  std::vector<StaticInterval> poses;
  if (!CorePoses(log, intervals, options.edge_seconds, name, &poses, error)) return false;
  prep->positions = PositionsFromIntervals(poses);
  if (options.pose_variance > 0.0) {
    // s^2 I in specific force is M^-1 s^2 M^-T in raw units.
    const Eigen::Matrix3d inverse = accel.matrix().inverse();
    for (Position& p : prep->positions) {
      p.raw_mean_cov += options.pose_variance * inverse * inverse.transpose();
    }
  }
  prep->segments = CutRotations(log, poses, options.max_rotation_seconds, warnings);
  if (static_cast<int>(prep->segments.size()) < MinRotations(options.parameterization)) {
    std::ostringstream s;
    s << name << ": found " << prep->segments.size() << " rotations between static poses; the '"
      << ToString(options.parameterization) << "' gyroscope model needs at least "
      << MinRotations(options.parameterization);
    *error = s.str();
    return false;
  }
  if (!PooledGyroNoise(log, poses, name, &prep->gyro_cov, &prep->center, error)) return false;

  // Calibrated specific force along every rotation.
  std::vector<std::vector<Eigen::Vector3d>> forces;
  for (const GyroSegment& seg : prep->segments) {
    std::vector<Eigen::Vector3d> f;
    for (size_t i = seg.first; i <= seg.last; ++i) f.push_back(accel.Apply(log.accel[i]));
    forces.push_back(f);
  }
  Eigen::Matrix3d initial = Eigen::Matrix3d::Identity();
  if (!GyroInitialMatrix(log, prep->segments, forces, prep->center, options.parameterization,
                         &initial, error)) {
    *error = name + ": " + *error;
    return false;
  }
  *m0 = initial;
  prep->scale = std::cbrt(std::fabs(initial.determinant()));
  NormaliseData(log, poses, accel, forces, prep);
  prep->session_seconds = log.t[poses.back().end - 1] - log.t[poses.front().begin];
  if (options.estimate_static_variance) AddStaticPoseVariance(options, prep);
  return true;
}

}  // namespace internal
}  // namespace gravcal
