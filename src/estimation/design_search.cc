// The search of the experiment design (gravcal/estimation/experiment_design.h):
// greedy selection with Fedorov exchange of poses among candidate
// directions, the shortest common hold that meets the targets, and the
// least-time design (DesignPoses).
#include "estimation/design_search.h"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "gravcal/estimation/experiment_design.h"
#include "util/numbers.h"

namespace gravcal {
namespace {

using internal::kInf;
using internal::UnitRows;

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

}  // namespace

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
    CandidateDirections(PoseSet::kFaces, 0, &faces);
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
