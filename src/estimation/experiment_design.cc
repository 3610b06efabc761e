#include "gravcal/estimation/experiment_design.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "estimation/design_search.h"
#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"
#include "gravcal/estimation/refinement.h"
#include "util/numbers.h"

namespace gravcal {
namespace internal {

// Unwhitened scale-free rows of the candidates (sigma 1), via the
// refinement's own Jacobian at the nominal sensor.
Eigen::MatrixXd UnitRows(const std::vector<Eigen::Vector3d>& ups, const DesignModel& model) {
  std::vector<Position> positions(ups.size());
  for (size_t k = 0; k < ups.size(); ++k) positions[k].raw_mean = model.gravity * ups[k];
  AccelModel nominal;
  nominal.parameterization = model.parameterization;
  return MagnitudeJacobian(positions, nominal, std::vector<double>(ups.size(), 1.0));
}

}  // namespace internal

namespace {

using internal::kInf;
using internal::UnitRows;

// The known-attitude model's rows (DesignModel): three per pose.
Eigen::MatrixXd KnownAttitudeJacobian(const std::vector<DesignPose>& poses,
                                      const DesignModel& model, const DesignNoise& noise) {
  const double g = model.gravity;
  // x within this of the vertical: roll is the angle of the placement error.
  const double gimbal_lock = std::cos(10.0 * M_PI / 180.0);
  std::vector<Eigen::Matrix<double, 3, 12>> blocks;
  for (size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Vector3d n = poses[k].up.normalized();
    const Eigen::Vector3d v = g * n;
    Eigen::Matrix<double, 3, 12> j = Eigen::Matrix<double, 3, 12>::Zero();
    j.leftCols<3>() = -Eigen::Matrix3d::Identity();
    for (int r = 0; r < 3; ++r) j.block<1, 3>(r, 3 + 3 * r) = v.transpose();
    const double usable = poses[k].hold_seconds - model.trimmed_seconds;
    const Eigen::Vector3d va =
        usable > 0.0 ? StillMeanVariance(noise.accel, usable) : Eigen::Vector3d::Constant(kInf);
    if (!va.allFinite()) {
      blocks.push_back(Eigen::Matrix<double, 3, 12>::Zero());
      continue;
    }
    const Eigen::Matrix3d sensor =
        Eigen::Matrix3d(va.asDiagonal()) +
        noise.pose_disturbance * noise.pose_disturbance * Eigen::Matrix3d::Identity();
    const double a2 = g * g * model.attitude_std * model.attitude_std;
    // n = (-sin p, sin r cos p, cos r cos p); the attitude errors move it by
    // dn/droll = (0, n_z, -n_y) and dn/dpitch = (-cos p, -sin r sin p, -cos r sin p).
    const double pitch = std::asin(std::clamp(-n.x(), -1.0, 1.0));
    const double roll = std::atan2(n.y(), n.z());
    const Eigen::Vector3d d_roll(0.0, n.z(), -n.y());
    const Eigen::Vector3d d_pitch(-std::cos(pitch), -std::sin(roll) * std::sin(pitch),
                                  -std::cos(roll) * std::sin(pitch));
    Eigen::Matrix3d attitude = d_roll * d_roll.transpose() + d_pitch * d_pitch.transpose();
    if (std::fabs(n.x()) > gimbal_lock) {
      // x nearly vertical: the roll is whatever angle the placement error
      // gives it, and the pitch error moves n along (0, sin r, cos r):
      // averaged over roll, half of it on each of the other two axes. (The
      // average of the covariance, not of the information: conservative,
      // see docs/workflows/plan.md.)
      attitude = 0.5 * (Eigen::Matrix3d::Identity() - n * n.transpose());
    }
    const Eigen::LLT<Eigen::Matrix3d> llt(sensor + a2 * attitude);
    blocks.push_back(llt.info() == Eigen::Success
                         ? Eigen::Matrix<double, 3, 12>(llt.matrixL().solve(j))
                         : Eigen::Matrix<double, 3, 12>::Zero());
  }
  Eigen::MatrixXd rows(3 * blocks.size(), 12);
  for (size_t b = 0; b < blocks.size(); ++b) rows.block<3, 12>(3 * b, 0) = blocks[b];
  return rows;
}

}  // namespace

DesignNoise WhiteDesignNoise(double density) {
  DesignNoise noise;
  for (AxisNoiseModel& axis : noise.accel) axis.white_noise.value = density;
  return noise;
}

bool DesignModel::IsValid(std::string* error) const {
  if (!(gravity > 0.0 && std::isfinite(gravity))) {
    *error = "DesignModel.gravity: must be positive";
    return false;
  }
  if (!(trimmed_seconds >= 0.0 && std::isfinite(trimmed_seconds))) {
    *error = "DesignModel.trimmed_seconds: must be >= 0";
    return false;
  }
  if (!(attitude_std >= 0.0 && std::isfinite(attitude_std))) {
    *error = "DesignModel.attitude_std: must be >= 0";
    return false;
  }
  if (parameterization == AccelParameterization::kAffine && !known_attitude) {
    *error =
        "DesignModel.parameterization: affine adds the housing rotation, which the magnitude "
        "cannot see; plan with scale_misalignment";
    return false;
  }
  return true;
}

double PoseMagnitudeVariance(const DesignNoise& noise, const DesignModel& model,
                             const Eigen::Vector3d& up, double hold_seconds) {
  const double usable = hold_seconds - model.trimmed_seconds;
  if (!(usable > 0.0)) return kInf;
  const Eigen::Vector3d v = StillMeanVariance(noise.accel, usable);
  if (!v.allFinite()) return kInf;
  return up.cwiseAbs2().dot(v) + noise.pose_disturbance * noise.pose_disturbance;
}

std::vector<std::string> DesignParameterNames(const DesignModel& model) {
  if (!model.known_attitude) return MagnitudeParameterNames(model.parameterization);
  const char* axes = "xyz";
  std::vector<std::string> names;
  for (int i = 0; i < 3; ++i) names.push_back(std::string("bias_") + axes[i]);
  for (int i = 0; i < 9; ++i) names.push_back(std::string("m_") + axes[i / 3] + axes[i % 3]);
  return names;
}

Eigen::MatrixXd DesignJacobian(const std::vector<DesignPose>& poses, const DesignModel& model,
                               const DesignNoise& noise) {
  if (model.known_attitude) return KnownAttitudeJacobian(poses, model, noise);
  std::vector<Eigen::Vector3d> ups;
  for (const DesignPose& p : poses) ups.push_back(p.up);
  Eigen::MatrixXd rows = UnitRows(ups, model);
  for (size_t k = 0; k < poses.size(); ++k) {
    const double v = PoseMagnitudeVariance(noise, model, poses[k].up, poses[k].hold_seconds);
    rows.row(k) *= std::isfinite(v) && v > 0.0 ? 1.0 / std::sqrt(v) : 0.0;
  }
  return rows;
}

Eigen::VectorXd PredictedStd(const Eigen::MatrixXd& fisher) {
  const Eigen::Index p = fisher.rows();
  Eigen::VectorXd out = Eigen::VectorXd::Constant(p, kInf);
  if (p == 0 || !fisher.allFinite()) return out;
  // Judged with unit diagonal, as AnalyzeObservability judges the Jacobian.
  // A column at rounding level (1e-12 of the largest) is a zero column:
  // scaling it up to unit norm would turn rounding into information.
  Eigen::VectorXd scale = fisher.diagonal().cwiseMax(0.0).cwiseSqrt();
  const double largest = scale.maxCoeff();
  Eigen::MatrixXd scaled = fisher;
  for (Eigen::Index i = 0; i < p; ++i) {
    if (!(scale(i) > 1e-12 * largest)) {
      scale(i) = 1.0;
      scaled.row(i).setZero();
      scaled.col(i).setZero();
    }
  }
  scaled = scale.cwiseInverse().asDiagonal() * scaled * scale.cwiseInverse().asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(scaled);
  if (eigen.info() != Eigen::Success) return out;
  const Eigen::VectorXd lambda = eigen.eigenvalues();
  const double top = lambda(p - 1);
  // Singular values of the Jacobian below 1e-8 of the largest (the
  // refinement's rank tolerance) are null: 1e-16 on the eigenvalues.
  Eigen::VectorXd variance = Eigen::VectorXd::Zero(p);
  std::vector<bool> undetermined(p, false);
  for (Eigen::Index k = 0; k < p; ++k) {
    const Eigen::VectorXd v = eigen.eigenvectors().col(k);
    if (!(lambda(k) > 1e-16 * top)) {
      for (Eigen::Index i = 0; i < p; ++i) {
        // As AnalyzeObservability names the parameters of a null direction.
        if (std::fabs(v(i)) >= 0.1) undetermined[i] = true;
      }
      continue;
    }
    variance += v.cwiseAbs2() / lambda(k);
  }
  for (Eigen::Index i = 0; i < p; ++i) {
    if (!undetermined[i]) out(i) = std::sqrt(variance(i)) / scale(i);
  }
  return out;
}

Eigen::VectorXd DeterminedStd(const Eigen::MatrixXd& fisher, const Eigen::VectorXd& limits) {
  // Unconditional: a parameter that trades against an undetermined or weak
  // one (a bias against the scale of an axis seen from one side only) has a
  // large or infinite marginal sigma, and is undetermined too; its sigma
  // conditional on holding the other would be a confident number for what
  // the data do not say.
  Eigen::VectorXd out = PredictedStd(fisher);
  for (Eigen::Index i = 0; i < out.size(); ++i) {
    if (!(out(i) <= limits(i))) out(i) = kInf;
  }
  return out;
}

Eigen::VectorXd StdInRawUnits(const Eigen::VectorXd& scale_free_std, double nominal_scale) {
  Eigen::VectorXd out = scale_free_std;
  for (Eigen::Index i = 0; i < out.size(); ++i) {
    out(i) = i < 3 ? out(i) / nominal_scale : out(i) * nominal_scale;
  }
  return out;
}

bool CandidateDirections(PoseSet pose_set, int count, std::vector<Eigen::Vector3d>* directions) {
  directions->clear();
  if (pose_set == PoseSet::kFree) {
    if (count < 1) return false;
    CandidateDirections(PoseSet::kFacesAnd45, 0, directions);
    // Fibonacci lattice: z evenly spaced, longitude by the golden angle.
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < count; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / count;
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      directions->emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
    }
    return true;
  }
  directions->clear();
  for (int a = 0; a < 3; ++a) {
    directions->push_back(Eigen::Vector3d::Unit(a));
    directions->push_back(-Eigen::Vector3d::Unit(a));
  }
  if (pose_set != PoseSet::kFaces) {
    for (int a = 0; a < 3; ++a) {
      for (int b = a + 1; b < 3; ++b) {
        for (double sa : {1.0, -1.0}) {
          for (double sb : {1.0, -1.0}) {
            directions->push_back(
                (sa * Eigen::Vector3d::Unit(a) + sb * Eigen::Vector3d::Unit(b)).normalized());
          }
        }
      }
    }
  }
  return true;
}

bool DesignOptions::IsValid(const DesignModel& model, std::string* error) const {
  if (!model.IsValid(error)) return false;
  const int p = static_cast<int>(DesignParameterNames(model).size());
  if (targets.size() != p || !targets.allFinite() || !(targets.minCoeff() > 0.0)) {
    *error = "DesignOptions.targets: one positive target per parameter (" + std::to_string(p) + ")";
    return false;
  }
  if (!(overhead_seconds >= 0.0) || !(min_hold_seconds > model.trimmed_seconds) ||
      !(max_hold_seconds >= min_hold_seconds) || !std::isfinite(max_hold_seconds)) {
    *error =
        "DesignOptions: overhead_seconds >= 0 and trimmed_seconds < min_hold_seconds <= "
        "max_hold_seconds";
    return false;
  }
  if (!(min_separation_deg >= 0.0 && min_separation_deg <= 90.0)) {
    *error = "DesignOptions.min_separation_deg: 0 to 90";
    return false;
  }
  if (redundancy < 0 || max_poses < p + redundancy || !(max_time_seconds >= 0.0)) {
    *error = "DesignOptions: redundancy >= 0, max_poses >= parameters + redundancy (" +
             std::to_string(p + redundancy) + ") and max_time_seconds >= 0";
    return false;
  }
  return true;
}

double DesignSeconds(const std::vector<DesignPose>& poses, double overhead_seconds) {
  double total = 0.0;
  for (const DesignPose& p : poses) total += p.hold_seconds + overhead_seconds;
  return total;
}

DesignResult EvaluateDesign(const std::vector<DesignPose>& poses, const DesignModel& model,
                            const DesignNoise& noise, const DesignOptions& options) {
  DesignResult result;
  result.poses = poses;
  const Eigen::MatrixXd j = DesignJacobian(poses, model, noise);
  result.predicted_std = PredictedStd(j.transpose() * j);
  result.worst_ratio = (result.predicted_std.array() / options.targets.array()).maxCoeff();
  result.meets_targets = result.worst_ratio <= 1.0;
  result.total_seconds = DesignSeconds(poses, options.overhead_seconds);
  result.message = result.meets_targets ? "every target met" : "not every target met";
  return result;
}

}  // namespace gravcal
