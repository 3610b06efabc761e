// gravcal record's pose design (workflows/recorder.h): the information a
// hold adds, the next pose and how long to hold it, the offline plan for
// the first hold's noise, and why a parameter is still undetermined.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>

#include "util/numbers.h"
#include "util/statistics.h"
#include "util/units.h"
#include "workflows/recorder_state.h"

namespace gravcal {

namespace {

using internal::CapturedPose;
using internal::kInf;
using internal::kRadToDeg;

// A suggestion is worded as a face within this.
constexpr double kFaceWordDeg = 2.0;
// Holds on the needed-hold grid.
constexpr int kHoldGrid = 24;

std::string AxisName(int axis, bool positive) {
  static const char* kAxes[3] = {"X", "Y", "Z"};
  return std::string(positive ? "+" : "-") + kAxes[axis];
}

}  // namespace

PoseSuggestion DescribeUp(const Eigen::Vector3d& given) {
  PoseSuggestion s;
  s.up = given.normalized();
  Eigen::Index face = 0;
  s.up.cwiseAbs().maxCoeff(&face);
  const bool positive = s.up(face) > 0.0;
  s.face = AxisName(static_cast<int>(face), positive);
  s.tilt_deg = std::acos(std::min(1.0, std::abs(s.up(face)))) * kRadToDeg;
  std::ostringstream words;
  words << s.face << " up";
  if (s.tilt_deg > kFaceWordDeg) {
    // The part of up across the face: the axes that rise.
    Eigen::Vector3d across = s.up;
    across(face) = 0.0;
    across.normalize();
    for (int a = 0; a < 3; ++a) {
      if (std::abs(across(a)) > 0.3) s.toward += AxisName(a, across(a) > 0.0);
    }
    words << ", then tilt about " << std::lround(s.tilt_deg) << " degrees toward " << s.toward
          << " (" << s.toward << " rises)";
  }
  s.instruction = words.str();
  return s;
}

Eigen::RowVectorXd Recorder::State::Row(const Eigen::Vector3d& up, double kept_seconds,
                                        const Eigen::Vector3d& density) const {
  DesignNoise n = noise;
  if (!given_noise) {
    for (int a = 0; a < 3; ++a) n.accel[a].white_noise.value = density(a);
  }
  const Eigen::MatrixXd j =
      DesignJacobian({{up, kept_seconds + start.model.trimmed_seconds}}, start.model, n);
  return j.row(0);
}

double Recorder::State::Phi(const Eigen::MatrixXd& f) const {
  const Eigen::MatrixXd cov = (f + prior).ldlt().solve(Eigen::MatrixXd::Identity(p, p));
  return (weight.asDiagonal() * cov).trace();
}

bool Recorder::State::TargetsMet(const Eigen::MatrixXd& f, int pose_count) const {
  if (pose_count < static_cast<int>(p) + options.redundancy) return false;
  const Eigen::VectorXd std = DeterminedStd(f, start.limits);
  for (Eigen::Index i = 0; i < p; ++i) {
    if (start.targeted[i] && !(std(i) <= start.targets(i))) return false;
  }
  return true;
}

Eigen::Vector3d Recorder::State::TypicalDensity(const Eigen::Vector3d& fallback) const {
  if (poses.empty()) return fallback;
  Eigen::Vector3d out;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> v;
    for (const CapturedPose& c : poses) v.push_back(c.density(a));
    out(a) = internal::Median(v);
  }
  return out;
}

double Recorder::State::NeededHold(const Eigen::Vector3d& up,
                                   const Eigen::Vector3d& density) const {
  const Eigen::VectorXd std = DeterminedStd(fisher, start.limits);
  const double t0 = std.allFinite()
                        ? options.min_hold_seconds
                        : std::clamp(plan_hold, options.min_hold_seconds, options.max_hold_seconds),
               t1 = options.max_hold_seconds;
  const Eigen::RowVectorXd r1 = Row(up, t1, density);
  const double phi_now = Phi(fisher);
  const double phi_best = Phi(fisher + r1.transpose() * r1);
  const int count = static_cast<int>(poses.size()) + 1;
  for (int k = 0; k <= kHoldGrid; ++k) {
    const double t = t0 * std::pow(t1 / t0, static_cast<double>(k) / kHoldGrid);
    const Eigen::RowVectorXd r = Row(up, t, density);
    const Eigen::MatrixXd f = fisher + r.transpose() * r;
    if (Phi(f) <= phi_best + options.hold_tolerance * (phi_now - phi_best) ||
        TargetsMet(f, count)) {
      return t;
    }
  }
  return t1;
}

PoseSuggestion Recorder::State::Suggest(const Eigen::Vector3d& density) const {
  const double hold = std::max(options.min_hold_seconds, 10.0);
  const double phi_now = Phi(fisher);
  double best_phi = kInf;
  int best = 0;
  for (size_t c = 0; c < candidates.size(); ++c) {
    const Eigen::RowVectorXd r = Row(candidates[c], hold, density);
    const double phi = Phi(fisher + r.transpose() * r);
    const double z = candidates[c].z();
    if (phi < best_phi * (1.0 - 1e-9) ||
        (phi <= best_phi * (1.0 + 1e-9) && z > candidates[best].z())) {
      best_phi = std::min(best_phi, phi);
      best = static_cast<int>(c);
    }
  }
  PoseSuggestion s = DescribeUp(candidates[best]);
  s.hold_seconds = NeededHold(candidates[best], density);
  const Eigen::RowVectorXd r = Row(candidates[best], s.hold_seconds, density);
  s.expected_gain = phi_now > 0.0 ? 1.0 - Phi(fisher + r.transpose() * r) / phi_now : 0.0;
  return s;
}

void Recorder::State::Plan(const Eigen::Vector3d& density) {
  PlanRequest request = options.request;
  if (!given_noise) request.accel_noise_density = density.maxCoeff();
  request.min_hold_seconds = options.min_hold_seconds + start.model.trimmed_seconds;
  request.max_hold_seconds = options.max_hold_seconds + start.model.trimmed_seconds;
  RecordingPlan plan;
  std::string error;
  plan_hold = options.min_hold_seconds;
  if (!MakeRecordingPlan(config, request, &plan, &error) || plan.poses.empty()) return;
  std::vector<double> holds;
  for (const PlannedPose& pose : plan.poses) holds.push_back(pose.hold_seconds);
  plan_hold =
      std::max(options.min_hold_seconds, internal::Median(holds) - start.model.trimmed_seconds);
  plan_poses = static_cast<int>(plan.poses.size());
}

std::map<std::string, std::string> Recorder::State::Reasons(const Eigen::VectorXd& std) const {
  std::map<std::string, std::string> out;
  std::map<std::string, int> faces;
  for (const CapturedPose& c : poses) ++faces[DescribeUp(c.up).instruction];
  std::string seen;
  for (const auto& [face, count] : faces) {
    seen += (seen.empty() ? "" : ", ") + face + (count > 1 ? " x" + std::to_string(count) : "");
  }
  if (seen.empty()) seen = "none";
  // Null directions of the information in target units (S F S, S =
  // diag(target)), so that the threshold is unit-free.
  const Eigen::VectorXd t = start.targets;
  const Eigen::MatrixXd g = t.asDiagonal() * fisher * t.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(g);
  const double top = std::max(eig.eigenvalues().maxCoeff(), 1e-300);
  const std::vector<std::string>& names = start.names;
  for (Eigen::Index i = 0; i < p; ++i) {
    if (std::isfinite(std(i))) continue;
    std::set<std::string> mixed;
    bool in_null = false;
    for (Eigen::Index k = 0; k < p; ++k) {
      if (eig.eigenvalues()(k) > 1e-9 * top) continue;
      const Eigen::VectorXd v = eig.eigenvectors().col(k);
      if (std::abs(v(i)) < 0.1) continue;
      in_null = true;
      for (Eigen::Index j = 0; j < p; ++j) {
        if (j != i && std::abs(v(j)) >= 0.1) mixed.insert(names[j]);
      }
    }
    std::string why;
    if (poses.empty()) {
      why = "no pose yet";
    } else if (in_null) {
      why = "the " + std::to_string(poses.size()) + " pose(s) so far (" + seen +
            ") cannot tell it apart";
      if (!mixed.empty()) {
        why += " from ";
        size_t n = 0;
        for (const std::string& m : mixed) why += (n++ ? ", " : "") + m;
      }
      why += ": it needs poses with other up directions";
    } else {
      why = "its sigma is beyond the calibration's limit with the poses so far (" + seen + ")";
    }
    out[names[i]] = why;
  }
  return out;
}

}  // namespace gravcal
