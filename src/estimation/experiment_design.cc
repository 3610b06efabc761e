#include "gravcal/estimation/experiment_design.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"
#include "gravcal/estimation/refinement.h"
#include "util/numbers.h"

namespace gravcal {

namespace {

using internal::kInf;

// Unwhitened scale-free rows of the candidates (sigma 1), via the
// refinement's own Jacobian at the nominal sensor.
Eigen::MatrixXd UnitRows(const std::vector<Eigen::Vector3d>& ups, const DesignModel& model) {
  std::vector<Position> positions(ups.size());
  for (size_t k = 0; k < ups.size(); ++k) positions[k].raw_mean = model.gravity * ups[k];
  AccelModel nominal;
  nominal.parameterization = model.parameterization;
  return MagnitudeJacobian(positions, nominal, std::vector<double>(ups.size(), 1.0));
}

// Greedy selection with Fedorov exchange of `count` rows of `rows`
// (whitened at one common hold) on trace(W F^-1). Repeats allowed.
class Exchanger {
 public:
  Exchanger(const Eigen::MatrixXd& rows, const Eigen::VectorXd& weights)
      : rows_(rows), weights_(weights), p_(static_cast<int>(rows.cols())) {
    double top = 0.0;
    for (Eigen::Index c = 0; c < rows_.rows(); ++c) top = std::max(top, rows_.row(c).squaredNorm());
    // A ridge small against one pose keeps F invertible while it has fewer
    // than p poses; it does not change which pose helps most once F is full.
    ridge_ = 1e-9 * (top > 0.0 ? top : 1.0);
  }

  // Adds poses greedily until there are `count`, then exchanges.
  std::vector<int> Select(std::vector<int> chosen, int count) {
    Eigen::MatrixXd finv = Inverse(chosen);
    while (static_cast<int>(chosen.size()) < count) {
      const int best = BestAddition(finv);
      Add(best, &finv);
      chosen.push_back(best);
    }
    for (int pass = 0; pass < 10; ++pass) {
      bool improved = false;
      for (size_t i = 0; i < chosen.size(); ++i) {
        const double before = Criterion(finv);
        Eigen::MatrixXd removed = finv;
        if (!Remove(chosen[i], &removed)) continue;
        const int best = BestAddition(removed);
        if (best == chosen[i]) continue;
        Eigen::MatrixXd added = removed;
        Add(best, &added);
        if (Criterion(added) < before * (1.0 - 1e-9)) {
          chosen[i] = best;
          finv = added;
          improved = true;
        }
      }
      if (!improved) break;
    }
    return chosen;
  }

 private:
  Eigen::MatrixXd Inverse(const std::vector<int>& chosen) const {
    Eigen::MatrixXd f = ridge_ * Eigen::MatrixXd::Identity(p_, p_);
    for (int c : chosen) f += rows_.row(c).transpose() * rows_.row(c);
    return f.ldlt().solve(Eigen::MatrixXd::Identity(p_, p_));
  }
  double Criterion(const Eigen::MatrixXd& finv) const {
    return (weights_.array() * finv.diagonal().array()).sum();
  }
  // The row whose addition lowers the criterion most:
  // Delta = -(b^T W b) / (1 + a^T b), b = F^-1 a.
  int BestAddition(const Eigen::MatrixXd& finv) const {
    int best = 0;
    double best_gain = -1.0;
    Eigen::VectorXd b(p_);
    for (Eigen::Index c = 0; c < rows_.rows(); ++c) {
      b.noalias() = finv * rows_.row(c).transpose();
      const double gain =
          (weights_.array() * b.array().square()).sum() / (1.0 + rows_.row(c).dot(b));
      if (gain > best_gain) {
        best_gain = gain;
        best = static_cast<int>(c);
      }
    }
    return best;
  }
  void Add(int c, Eigen::MatrixXd* finv) const {
    const Eigen::VectorXd b = *finv * rows_.row(c).transpose();
    *finv -= b * b.transpose() / (1.0 + rows_.row(c).dot(b));
  }
  bool Remove(int c, Eigen::MatrixXd* finv) const {
    const Eigen::VectorXd b = *finv * rows_.row(c).transpose();
    const double d = 1.0 - rows_.row(c).dot(b);
    if (!(d > 1e-12)) return false;
    *finv += b * b.transpose() / d;
    return true;
  }

  const Eigen::MatrixXd& rows_;
  const Eigen::VectorXd& weights_;
  const int p_;
  double ridge_ = 0.0;
};

std::vector<DesignPose> PosesAt(const std::vector<Eigen::Vector3d>& ups, double hold) {
  std::vector<DesignPose> poses(ups.size());
  for (size_t k = 0; k < ups.size(); ++k) poses[k] = {ups[k], hold};
  return poses;
}

// Rows of the candidates whitened at `hold`.
Eigen::MatrixXd WhitenedRows(const Eigen::MatrixXd& unit_rows,
                             const std::vector<Eigen::Vector3d>& candidates,
                             const DesignModel& model, const DesignNoise& noise, double hold) {
  Eigen::MatrixXd rows = unit_rows;
  for (size_t c = 0; c < candidates.size(); ++c) {
    const double v = PoseMagnitudeVariance(noise, model, candidates[c], hold);
    rows.row(c) *= std::isfinite(v) && v > 0.0 ? 1.0 / std::sqrt(v) : 0.0;
  }
  return rows;
}

// Directions closer than `separation_deg` as one pose holding their summed
// time, along their hold-weighted mean direction (one overhead fewer, and a
// person or the static detector could not tell them apart anyway); the
// order of first appearance is kept.
std::vector<DesignPose> MergeRepeats(const std::vector<DesignPose>& poses, double separation_deg) {
  const double cos_limit = std::cos(separation_deg * M_PI / 180.0);
  std::vector<DesignPose> merged;
  std::vector<Eigen::Vector3d> sums;
  for (const DesignPose& p : poses) {
    size_t m = 0;
    while (m < merged.size() && merged[m].up.dot(p.up) < cos_limit) ++m;
    if (m == merged.size()) {
      merged.push_back(p);
      sums.push_back(p.hold_seconds * p.up);
    } else {
      merged[m].hold_seconds += p.hold_seconds;
      sums[m] += p.hold_seconds * p.up;
      merged[m].up = sums[m].normalized();
    }
  }
  return merged;
}

// The smallest factor (>= the one bringing the shortest hold to min_hold)
// by which every hold of `poses` can be multiplied and still meet the
// targets; false when even the largest allowed factor does not.
bool ShortestScaling(const std::vector<DesignPose>& poses, const DesignModel& model,
                     const DesignNoise& noise, const DesignOptions& options, DesignResult* result) {
  double shortest = kInf, longest = 0.0;
  for (const DesignPose& p : poses) {
    shortest = std::min(shortest, p.hold_seconds);
    longest = std::max(longest, p.hold_seconds);
  }
  const double lo_limit = options.min_hold_seconds / shortest;
  const double hi_limit = options.max_hold_seconds / longest;
  auto scaled = [&](double f) {
    std::vector<DesignPose> out = poses;
    for (DesignPose& p : out) p.hold_seconds *= f;
    return out;
  };
  if (!(hi_limit >= lo_limit)) return false;
  DesignResult at = EvaluateDesign(scaled(lo_limit), model, noise, options);
  if (at.meets_targets) {
    *result = at;
    return true;
  }
  // Geometric steps up to the first factor that meets the targets, then
  // bisection between it and the step below (the worst ratio falls with the
  // hold until a random walk dominates, beyond which longer holds are not
  // searched).
  double lo = lo_limit, hi = lo_limit;
  DesignResult best = at;
  bool found = false;
  while (hi < hi_limit) {
    lo = hi;
    hi = std::min(hi * 1.5, hi_limit);
    const DesignResult r = EvaluateDesign(scaled(hi), model, noise, options);
    if (r.meets_targets) {
      best = r;
      found = true;
      break;
    }
    if (r.worst_ratio > best.worst_ratio) break;
    best = r;
  }
  if (!found) return false;
  for (int i = 0; i < 30 && hi - lo > 1e-3 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    const DesignResult r = EvaluateDesign(scaled(mid), model, noise, options);
    if (r.meets_targets) {
      hi = mid;
      best = r;
    } else {
      lo = mid;
    }
  }
  *result = best;
  return true;
}

std::vector<Eigen::Vector3d> Ups(const std::vector<int>& chosen,
                                 const std::vector<Eigen::Vector3d>& candidates) {
  std::vector<Eigen::Vector3d> ups;
  for (int c : chosen) ups.push_back(candidates[c]);
  return ups;
}

// Keeps `candidate` when it is better than *best: within max_time (when
// set), a design that meets the targets beats one that does not; two that
// do are ranked by time, two that do not by worst ratio (time breaks ties).
void KeepBetter(const DesignResult& candidate, const DesignOptions& options, DesignResult* best,
                bool* have) {
  const bool fits = !(options.max_time_seconds > 0.0) ||
                    candidate.total_seconds <= options.max_time_seconds * (1.0 + 1e-9);
  if (!fits || !std::isfinite(candidate.worst_ratio)) return;
  bool better = !*have;
  if (*have) {
    if (candidate.meets_targets != best->meets_targets) {
      better = candidate.meets_targets;
    } else if (candidate.meets_targets) {
      better = candidate.total_seconds < best->total_seconds;
    } else {
      better = candidate.worst_ratio < best->worst_ratio * (1.0 - 1e-9) ||
               (candidate.worst_ratio <= best->worst_ratio * (1.0 + 1e-9) &&
                candidate.total_seconds < best->total_seconds);
    }
  }
  if (better) {
    *best = candidate;
    *have = true;
  }
}

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

bool CandidateDirections(const std::string& pose_set, int count,
                         std::vector<Eigen::Vector3d>* directions) {
  directions->clear();
  if (pose_set == "free") {
    if (count < 1) return false;
    CandidateDirections("faces+45", 0, directions);
    // Fibonacci lattice: z evenly spaced, longitude by the golden angle.
    const double golden = M_PI * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < count; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / count;
      const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
      directions->emplace_back(r * std::cos(golden * i), r * std::sin(golden * i), z);
    }
    return true;
  }
  if (pose_set != "faces" && pose_set != "faces+45") return false;
  directions->clear();
  for (int a = 0; a < 3; ++a) {
    directions->push_back(Eigen::Vector3d::Unit(a));
    directions->push_back(-Eigen::Vector3d::Unit(a));
  }
  if (pose_set != "faces") {
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

bool ShortestHold(const std::vector<Eigen::Vector3d>& ups, const DesignModel& model,
                  const DesignNoise& noise, const DesignOptions& options, DesignResult* result) {
  if (ups.empty()) return false;
  return ShortestScaling(PosesAt(ups, options.min_hold_seconds), model, noise, options, result);
}

bool DesignPoses(const std::vector<Eigen::Vector3d>& candidates, const DesignModel& model,
                 const DesignNoise& noise, const DesignOptions& options, DesignResult* result) {
  *result = DesignResult();
  std::string error;
  if (!options.IsValid(model, &error)) {
    result->message = error;
    return false;
  }
  if (candidates.empty()) {
    result->message = "no candidate orientations";
    return false;
  }
  const int p = static_cast<int>(DesignParameterNames(model).size());
  const Eigen::VectorXd weights = options.targets.cwiseAbs2().cwiseInverse();
  const Eigen::MatrixXd unit_rows =
      model.known_attitude ? Eigen::MatrixXd() : UnitRows(candidates, model);
  const bool max_time_mode = options.max_time_seconds > 0.0;
  const int min_poses = p + options.redundancy;

  DesignResult best;
  bool have = false;
  // Least time first (also in max-time mode: when the targets can be met
  // within it, the fastest such design is the answer).
  auto consider_hold_search = [&](const std::vector<Eigen::Vector3d>& ups) {
    DesignResult r;
    if (!ShortestHold(ups, model, noise, options, &r)) return;
    // Repeats merged and the holds rescaled: the same information under
    // white noise with fewer overheads. Kept apart (set down again) only
    // when the merged pose would have to exceed max_hold.
    const std::vector<DesignPose> merged = MergeRepeats(r.poses, options.min_separation_deg);
    if (merged.size() < r.poses.size()) {
      if (static_cast<int>(merged.size()) < min_poses) return;
      DesignResult m;
      if (ShortestScaling(merged, model, noise, options, &m)) r = m;
    }
    KeepBetter(r, options, &best, &have);
  };
  // The best design within max_time at n poses of a common hold.
  auto consider_within = [&](const std::vector<Eigen::Vector3d>& ups) {
    const double n = static_cast<double>(ups.size());
    const double hold =
        std::min(options.max_hold_seconds, options.max_time_seconds / n - options.overhead_seconds);
    if (!(hold >= options.min_hold_seconds)) return;
    const std::vector<DesignPose> merged =
        MergeRepeats(PosesAt(ups, hold), options.min_separation_deg);
    if (static_cast<int>(merged.size()) < min_poses) return;
    KeepBetter(EvaluateDesign(merged, model, noise, options), options, &best, &have);
  };
  for (const std::vector<Eigen::Vector3d>& ups : options.reference_designs) {
    consider_hold_search(ups);
    if (max_time_mode) consider_within(ups);
  }
  if (model.known_attitude) {
    // The balanced designs (see the header): the six faces, as often as
    // max_poses allows.
    std::vector<Eigen::Vector3d> faces, repeated;
    CandidateDirections("faces", 0, &faces);
    while (true) {
      repeated.insert(repeated.end(), faces.begin(), faces.end());
      if (static_cast<int>(repeated.size()) > options.max_poses) break;
      DesignResult r;
      if (ShortestHold(repeated, model, noise, options, &r)) KeepBetter(r, options, &best, &have);
      if (max_time_mode) consider_within(repeated);
    }
  }

  double hold = options.min_hold_seconds;
  Eigen::MatrixXd rows = model.known_attitude
                             ? Eigen::MatrixXd()
                             : WhitenedRows(unit_rows, candidates, model, noise, hold);
  std::vector<int> chosen;
  for (int n = min_poses; n <= options.max_poses && !model.known_attitude; ++n) {
    const double floor = n * (options.min_hold_seconds + options.overhead_seconds);
    if (max_time_mode && floor > options.max_time_seconds) break;
    if (!max_time_mode && have && best.meets_targets && floor >= best.total_seconds) break;
    {
      Exchanger exchanger(rows, weights);
      chosen = exchanger.Select(chosen, n);
    }
    DesignResult r;
    if (ShortestHold(Ups(chosen, candidates), model, noise, options, &r)) {
      // The noise shape can change with the hold (non-white terms): design
      // again at the hold found, once.
      const double found = r.poses.front().hold_seconds;
      if (std::fabs(found - hold) > 1e-3 * hold) {
        hold = found;
        rows = WhitenedRows(unit_rows, candidates, model, noise, hold);
        Exchanger again(rows, weights);
        chosen = again.Select(chosen, n);
      }
      consider_hold_search(Ups(chosen, candidates));
    }
    if (max_time_mode) {
      const double within = std::min(options.max_hold_seconds,
                                     options.max_time_seconds / n - options.overhead_seconds);
      if (within >= options.min_hold_seconds) {
        const Eigen::MatrixXd rows_within =
            WhitenedRows(unit_rows, candidates, model, noise, within);
        Exchanger exchanger(rows_within, weights);
        consider_within(Ups(exchanger.Select(chosen, n), candidates));
      }
    }
  }
  if (!have) {
    result->message = "no design of at most " + std::to_string(options.max_poses) +
                      " poses determines every parameter within the hold and time limits";
    result->worst_ratio = kInf;
    return true;
  }
  *result = best;
  std::ostringstream s;
  s.precision(4);
  s << result->poses.size() << " poses, " << result->total_seconds
    << " s: " << (result->meets_targets ? "every target met" : "not every target met")
    << " (worst sigma / target " << result->worst_ratio << ")";
  result->message = s.str();
  return true;
}

}  // namespace gravcal
