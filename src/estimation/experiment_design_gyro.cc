// The gyroscope half of the experiment design (experiment_design.h): the
// Fisher information of the gyroscope-between-poses model and the choice of
// the turns between the poses.
#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>

#include "gravcal/core/accel_model.h"
#include "gravcal/estimation/experiment_design.h"
#include "gravcal/estimation/refinement.h"
#include "gravcal/residuals/gyro_rotation_residual.h"
#include "util/numbers.h"
#include "util/units.h"

namespace gravcal {

namespace {

using internal::kInf;
// Ambient gyroscope vector: b_g (3), M_g (9, row-major).
constexpr int kGyroAmbient = 12;
// Ambient accelerometer vector of the joint residual: b_a (3), U (6).
constexpr int kAccelAmbient = 3 + kUpperSize;

// Free gyroscope columns in the ambient vector.
Eigen::MatrixXd GyroBasis(GyroParameterization p) {
  std::vector<std::vector<int>> columns = {{0}, {1}, {2}};
  if (p == GyroParameterization::kBias) {
    columns.push_back({3, 7, 11});
  } else {
    for (int i = 0; i < 9; ++i) {
      if (p == GyroParameterization::kFull || i % 4 == 0) columns.push_back({3 + i});
    }
  }
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(kGyroAmbient, columns.size());
  for (size_t j = 0; j < columns.size(); ++j) {
    for (int a : columns[j]) basis(a, j) = 1.0;
  }
  return basis;
}

// The accelerometer design's columns (MagnitudeParameterNames order) in the
// joint residual's ambient accelerometer vector.
std::vector<int> AccelColumns(AccelParameterization p) {
  std::vector<int> columns = {0, 1, 2};
  for (int i : FreeUpperIndices(p)) columns.push_back(3 + i);
  return columns;
}

// Seconds of a pose's mean (after the detector's trim and the edges given
// to the rotations).
double CoreSeconds(const DesignPose& pose, const DesignModel& model,
                   const GyroDesignModel& gyro_model) {
  return pose.hold_seconds - model.trimmed_seconds - 2.0 * gyro_model.edge_seconds;
}

// Direction covariance of a pose whose up is u: P diag(V_a) P / g^2.
Eigen::Matrix3d DirectionCovariance(const Eigen::Vector3d& u, const Eigen::Vector3d& accel_variance,
                                    double gravity) {
  const Eigen::Matrix3d p = Eigen::Matrix3d::Identity() - u * u.transpose();
  return p * accel_variance.asDiagonal() * p / (gravity * gravity);
}

// The information one rotation adds: F = J_g^T J_g (free gyroscope columns)
// and H = J_g^T J_a (accelerometer design columns).
struct RotationInformation {
  Eigen::MatrixXd fisher;
  Eigen::MatrixXd cross;
  bool ok = false;
};

RotationInformation TurnInformation(const DesignPose& from, const DesignPose& to,
                                    const DesignTurn& turn, const DesignModel& model,
                                    const GyroDesignModel& gyro_model, const DesignNoise& noise,
                                    const Eigen::MatrixXd& gyro_basis,
                                    const std::vector<int>& accel_columns) {
  RotationInformation out;
  const double rate = gyro_model.sample_rate;
  const double edge = gyro_model.edge_seconds;
  const double angle = turn.angle_deg * internal::kDegToRad;
  const int n = static_cast<int>(std::lround((turn.seconds + 2.0 * edge) * rate)) + 1;
  if (n < 4 || !(turn.seconds > 0.0)) return out;
  GyroRotationData d;
  for (int i = 0; i < n; ++i) {
    const double t = i / rate;
    const double x = (t - edge) / turn.seconds;
    const double s = x > 0.0 && x < 1.0 ? 30.0 * x * x * (1.0 - x) * (1.0 - x) : 0.0;
    d.t.push_back(t);
    d.gyro.push_back(turn.axis * (angle * s / turn.seconds));
  }
  // The nominal turn as the integrator sees it, so the residual is zero
  // at the nominal sensor.
  const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double zero[3] = {0, 0, 0};
  std::vector<double> path(4 * n);
  double dq[4];
  IntegrateGyroRotation<double>(d, zero, identity, nullptr, dq, path.data());
  const Eigen::Matrix3d rn = Eigen::Quaterniond(dq[0], dq[1], dq[2], dq[3]).toRotationMatrix();
  const Eigen::Vector3d start = from.up.normalized();
  const Eigen::Vector3d end = rn.transpose() * start;
  d.start_direction = start;
  d.end_direction = end;
  d.start_raw = model.gravity * start;
  d.end_raw = model.gravity * end;
  // Two rows perpendicular to the end direction.
  int least = 0;
  end.cwiseAbs().minCoeff(&least);
  const Eigen::Vector3d e1 = end.cross(Eigen::Vector3d::Unit(least)).normalized();
  d.tangent.row(0) = e1.transpose();
  d.tangent.row(1) = end.cross(e1).transpose();

  // Weights as the calibration's (gyro_weights.cc).
  Eigen::Matrix3d rate_cov = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 3; ++a) {
    const double density = noise.gyro[a].white_noise.value;
    if (!(density > 0.0)) return out;
    rate_cov(a, a) = density * density * rate;
  }
  Eigen::Matrix3d angle_cov = Eigen::Matrix3d::Zero();
  for (int i = 0; i < n; ++i) {
    const double before = i > 0 ? d.t[i] - d.t[i - 1] : 0.0;
    const double after = i + 1 < n ? d.t[i + 1] - d.t[i] : 0.0;
    const double c = 0.5 * (before + after);
    const Eigen::Matrix3d ri =
        Eigen::Quaterniond(path[4 * i], path[4 * i + 1], path[4 * i + 2], path[4 * i + 3])
            .toRotationMatrix();
    angle_cov += c * c * ri * rate_cov * ri.transpose();
  }
  angle_cov = rn.transpose() * angle_cov * rn;
  const Eigen::Vector3d va_from =
      StillMeanVariance(noise.accel, CoreSeconds(from, model, gyro_model));
  const Eigen::Vector3d va_to = StillMeanVariance(noise.accel, CoreSeconds(to, model, gyro_model));
  if (!va_from.allFinite() || !va_to.allFinite()) return out;
  Eigen::Matrix3d px;
  px << 0, -end(2), end(1), end(2), 0, -end(0), -end(1), end(0), 0;
  const Eigen::Matrix3d cov =
      DirectionCovariance(end, va_to, model.gravity) +
      rn.transpose() * DirectionCovariance(start, va_from, model.gravity) * rn +
      px * angle_cov * px.transpose();
  const Eigen::Matrix2d cov2 = d.tangent * cov * d.tangent.transpose();
  Eigen::LLT<Eigen::Matrix2d> llt(cov2);
  if (llt.info() != Eigen::Success) return out;
  d.sqrt_information = llt.matrixL().solve(Eigen::Matrix2d::Identity());

  // The residual's own Jacobian (joint form: b_g, M_g, b_a, U).
  std::unique_ptr<ceres::CostFunction> cost(GyroRotationResidual::Create(d, false, true));
  const double upper[kUpperSize] = {1, 0, 0, 1, 0, 1};
  const double* parameters[4] = {zero, identity, zero, upper};
  double residual[2];
  double jb[2 * 3], jm[2 * 9], jab[2 * 3], jau[2 * kUpperSize];
  double* jacobians[4] = {jb, jm, jab, jau};
  if (!cost->Evaluate(parameters, residual, jacobians)) return out;
  Eigen::Matrix<double, 2, kGyroAmbient> jg;
  Eigen::Matrix<double, 2, kAccelAmbient> ja;
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) jg(r, c) = jb[3 * r + c];
    for (int c = 0; c < 9; ++c) jg(r, 3 + c) = jm[9 * r + c];
    for (int c = 0; c < 3; ++c) ja(r, c) = jab[3 * r + c];
    for (int c = 0; c < kUpperSize; ++c) ja(r, 3 + c) = jau[kUpperSize * r + c];
  }
  const Eigen::MatrixXd jg_free = jg * gyro_basis;
  Eigen::MatrixXd ja_free(2, accel_columns.size());
  for (size_t c = 0; c < accel_columns.size(); ++c) ja_free.col(c) = ja.col(accel_columns[c]);
  out.fisher = jg_free.transpose() * jg_free;
  out.cross = jg_free.transpose() * ja_free;
  out.ok = out.fisher.allFinite() && out.cross.allFinite();
  return out;
}

// The information of the static poses (bias only: at rest the rate is
// zero, and the residual's derivative in M_g vanishes at the nominal sensor).
Eigen::MatrixXd StaticInformation(const std::vector<DesignPose>& poses, const DesignModel& model,
                                  const GyroDesignModel& gyro_model, const DesignNoise& noise,
                                  const Eigen::MatrixXd& gyro_basis) {
  Eigen::MatrixXd ambient = Eigen::MatrixXd::Zero(kGyroAmbient, kGyroAmbient);
  for (const DesignPose& p : poses) {
    const Eigen::Vector3d v = StillMeanVariance(noise.gyro, CoreSeconds(p, model, gyro_model));
    for (int a = 0; a < 3; ++a) {
      if (std::isfinite(v(a)) && v(a) > 0.0) ambient(a, a) += 1.0 / v(a);
    }
  }
  return gyro_basis.transpose() * ambient * gyro_basis;
}

// The accelerometer design's covariance (scale-free), or empty when the
// poses leave it singular.
Eigen::MatrixXd AccelCovariance(const std::vector<DesignPose>& poses, const DesignModel& model,
                                const DesignNoise& noise) {
  const Eigen::MatrixXd j = DesignJacobian(poses, model, noise);
  const Eigen::MatrixXd f = j.transpose() * j;
  if (!PredictedStd(f).allFinite()) return Eigen::MatrixXd();
  return f.ldlt().solve(Eigen::MatrixXd::Identity(f.rows(), f.cols()));
}

// C_g = A + A H C_a H^T A; standard deviations (infinity where the
// information leaves a parameter undetermined) and the gyroscope-only ones.
void GyroStd(const Eigen::MatrixXd& fisher, const Eigen::MatrixXd& cross,
             const Eigen::MatrixXd& accel_cov, Eigen::VectorXd* std, Eigen::VectorXd* gyro_only) {
  *gyro_only = PredictedStd(fisher);
  *std = *gyro_only;
  if (!gyro_only->allFinite()) return;
  const Eigen::MatrixXd a =
      fisher.ldlt().solve(Eigen::MatrixXd::Identity(fisher.rows(), fisher.cols()));
  Eigen::MatrixXd c = a;
  if (accel_cov.size() > 0) c += a * cross * accel_cov * cross.transpose() * a;
  *std = c.diagonal().cwiseMax(0.0).cwiseSqrt();
}

}  // namespace

std::vector<std::string> GyroDesignParameterNames(GyroParameterization p) {
  const char* axes = "xyz";
  std::vector<std::string> names;
  for (int i = 0; i < 3; ++i) names.push_back(std::string("bias_") + axes[i]);
  if (p == GyroParameterization::kBias) {
    names.push_back("scale");
    return names;
  }
  for (int i = 0; i < 9; ++i) {
    if (p == GyroParameterization::kFull || i % 4 == 0) {
      names.push_back(std::string("m_") + axes[i / 3] + axes[i % 3]);
    }
  }
  return names;
}

bool GyroDesignModel::IsValid(std::string* error) const {
  if (parameterization == GyroParameterization::kNone) {
    *error = "GyroDesignModel.parameterization: none (no gyroscope to plan)";
    return false;
  }
  if (!(edge_seconds >= 0.0 && std::isfinite(edge_seconds)) ||
      !(sample_rate >= 10.0 && sample_rate <= 10000.0)) {
    *error = "GyroDesignModel: edge_seconds >= 0 and sample_rate 10..10000 Hz";
    return false;
  }
  return true;
}

std::vector<DesignTurn> CandidateTurns(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                                       int free_axes, double seconds_per_180) {
  const Eigen::Vector3d u = from.normalized(), v = to.normalized();
  std::vector<Eigen::Vector3d> axes;
  const Eigen::Vector3d shortest = v.cross(u);
  if (shortest.norm() > 1e-9) axes.push_back(shortest.normalized());
  if ((u + v).norm() > 1e-9 && free_axes > 0) axes.push_back((u + v).normalized());
  // The family: axes perpendicular to u - v (every axis when u = v, which
  // a design does not ask for).
  const Eigen::Vector3d w = (u - v).norm() > 1e-9 ? (u - v).normalized() : u;
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(w(a)) < 1e-9) axes.push_back(Eigen::Vector3d::Unit(a));
  }
  if (free_axes > 0) {
    const Eigen::Vector3d p = w.unitOrthogonal(), q = w.cross(p);
    for (int k = 0; k < free_axes; ++k) {
      const double phi = M_PI * k / free_axes;
      axes.push_back(std::cos(phi) * p + std::sin(phi) * q);
    }
  }
  std::vector<DesignTurn> turns;
  for (Eigen::Vector3d a : axes) {
    // Turning by t about a takes up to R(a, -t) up: t is minus the signed
    // angle from u to v about a, measured in the plane perpendicular to a.
    const Eigen::Vector3d up = u - a.dot(u) * a, vp = v - a.dot(v) * a;
    if (up.norm() < 1e-6 || vp.norm() < 1e-6) continue;
    double t = -std::atan2(a.dot(up.cross(vp)), up.dot(vp));
    if (t < 0.0) {
      a = -a;
      t = -t;
    }
    if (t < 1e-6) continue;
    DesignTurn turn;
    turn.axis = a;
    for (int i = 0; i < 3; ++i) turn.axis(i) = std::fabs(a(i)) < 1e-12 ? 0.0 : a(i);
    turn.angle_deg = t * internal::kRadToDeg;
    turn.seconds = seconds_per_180 * std::max(0.5, turn.angle_deg / 180.0);
    const bool repeat = std::any_of(turns.begin(), turns.end(), [&](const DesignTurn& o) {
      return (o.axis - turn.axis).norm() < 1e-6;
    });
    if (!repeat) turns.push_back(turn);
  }
  return turns;
}

GyroDesignResult EvaluateRotations(const std::vector<DesignPose>& poses,
                                   const std::vector<DesignTurn>& turns, const DesignModel& model,
                                   const GyroDesignModel& gyro_model, const DesignNoise& noise,
                                   const Eigen::VectorXd& gyro_targets) {
  GyroDesignResult result;
  result.parameter_names = GyroDesignParameterNames(gyro_model.parameterization);
  result.poses = poses;
  result.turns = turns;
  const Eigen::MatrixXd basis = GyroBasis(gyro_model.parameterization);
  const std::vector<int> accel_columns = AccelColumns(model.parameterization);
  Eigen::MatrixXd fisher = StaticInformation(poses, model, gyro_model, noise, basis);
  Eigen::MatrixXd cross = Eigen::MatrixXd::Zero(basis.cols(), accel_columns.size());
  for (size_t k = 0; k + 1 < poses.size() && k < turns.size(); ++k) {
    const RotationInformation r = TurnInformation(poses[k], poses[k + 1], turns[k], model,
                                                  gyro_model, noise, basis, accel_columns);
    if (!r.ok) continue;
    fisher += r.fisher;
    cross += r.cross;
  }
  GyroStd(fisher, cross, AccelCovariance(poses, model, noise), &result.predicted_std,
          &result.predicted_std_gyro_only);
  result.worst_ratio = gyro_targets.size() == result.predicted_std.size()
                           ? (result.predicted_std.array() / gyro_targets.array()).maxCoeff()
                           : kInf;
  result.meets_targets = result.worst_ratio <= 1.0;
  result.message =
      result.meets_targets ? "every gyroscope target met" : "not every gyroscope target met";
  return result;
}

bool RotationDesignOptions::IsValid(const GyroDesignModel& model, std::string* error) const {
  if (!model.IsValid(error)) return false;
  const size_t p = GyroDesignParameterNames(model.parameterization).size();
  if (static_cast<size_t>(targets.size()) != p || !targets.allFinite() ||
      !(targets.minCoeff() > 0.0)) {
    *error = "RotationDesignOptions.targets: one positive target per gyroscope parameter (" +
             std::to_string(p) + ")";
    return false;
  }
  if (free_axes < 0 || !(seconds_per_180 > 0.0) || !(extra_hold_seconds > 0.0) ||
      max_extra_poses < 0) {
    *error =
        "RotationDesignOptions: free_axes >= 0, seconds_per_180 > 0, extra_hold_seconds > 0, "
        "max_extra_poses >= 0";
    return false;
  }
  return true;
}

bool DesignRotations(const std::vector<DesignPose>& poses, const DesignModel& model,
                     const GyroDesignModel& gyro_model, const DesignNoise& noise,
                     const RotationDesignOptions& options, GyroDesignResult* result) {
  *result = GyroDesignResult();
  std::string error;
  if (!model.IsValid(&error) || !options.IsValid(gyro_model, &error)) {
    result->message = error;
    return false;
  }
  for (const AxisNoiseModel& axis : noise.gyro) {
    if (!(axis.white_noise.value > 0.0)) {
      result->message = "no gyroscope white noise to plan the rotations with";
      return false;
    }
  }
  if (poses.size() < 2) {
    result->message = "a rotation design needs at least two poses";
    return false;
  }
  const Eigen::MatrixXd basis = GyroBasis(gyro_model.parameterization);
  const std::vector<int> accel_columns = AccelColumns(model.parameterization);
  const Eigen::Index p = basis.cols();
  const Eigen::Index na = static_cast<Eigen::Index>(accel_columns.size());
  auto information = [&](const DesignPose& a, const DesignPose& b, const DesignTurn& t) {
    return TurnInformation(a, b, t, model, gyro_model, noise, basis, accel_columns);
  };
  struct Choice {
    std::vector<DesignTurn> turns;
    std::vector<RotationInformation> info;
    int chosen = 0;
  };

  std::vector<DesignPose> all = poses;
  std::vector<Choice> pairs;
  for (size_t k = 0; k + 1 < all.size(); ++k) {
    Choice c;
    for (const DesignTurn& t :
         CandidateTurns(all[k].up, all[k + 1].up, options.free_axes, options.seconds_per_180)) {
      RotationInformation r = information(all[k], all[k + 1], t);
      if (!r.ok) continue;
      c.turns.push_back(t);
      c.info.push_back(std::move(r));
    }
    if (c.turns.empty()) {
      result->message = "no turn between poses " + std::to_string(k) + " and " +
                        std::to_string(k + 1) + " has usable information";
      return false;
    }
    pairs.push_back(std::move(c));
  }
  Eigen::MatrixXd accel_cov = AccelCovariance(all, model, noise);
  Eigen::MatrixXd static_info = StaticInformation(all, model, gyro_model, noise, basis);
  auto phi_of = [&](const Eigen::MatrixXd& f, const Eigen::MatrixXd& h) {
    Eigen::VectorXd std, gyro_only;
    GyroStd(f, h, accel_cov, &std, &gyro_only);
    // Undetermined parameters count by a large finite penalty, so that a
    // turn determining one more is always preferred.
    double phi = 0.0;
    for (Eigen::Index i = 0; i < std.size(); ++i) {
      phi += std::isfinite(std(i)) ? std::pow(std(i) / options.targets(i), 2) : 1e12;
    }
    return phi;
  };
  auto totals = [&](Eigen::MatrixXd* f, Eigen::MatrixXd* h) {
    *f = static_info;
    *h = Eigen::MatrixXd::Zero(p, na);
    for (const Choice& c : pairs) {
      *f += c.info[c.chosen].fisher;
      *h += c.info[c.chosen].cross;
    }
  };
  // Coordinate descent over the pairs, starting from the shortest turns.
  Eigen::MatrixXd f, h;
  totals(&f, &h);
  double phi = phi_of(f, h);
  for (int pass = 0; pass < 6; ++pass) {
    bool changed = false;
    for (Choice& c : pairs) {
      const Eigen::MatrixXd f0 = f - c.info[c.chosen].fisher;
      const Eigen::MatrixXd h0 = h - c.info[c.chosen].cross;
      for (size_t j = 0; j < c.turns.size(); ++j) {
        if (static_cast<int>(j) == c.chosen) continue;
        const double trial = phi_of(f0 + c.info[j].fisher, h0 + c.info[j].cross);
        if (trial < phi * (1.0 - 1e-9)) {
          phi = trial;
          c.chosen = static_cast<int>(j);
          f = f0 + c.info[j].fisher;
          h = h0 + c.info[j].cross;
          changed = true;
        }
      }
    }
    if (!changed) break;
  }
  // Extra poses while a target is not met.
  auto worst = [&]() {
    Eigen::VectorXd std, gyro_only;
    GyroStd(f, h, accel_cov, &std, &gyro_only);
    return (std.array() / options.targets.array()).maxCoeff();
  };
  int extra = 0;
  while (!(worst() <= 1.0) && extra < options.max_extra_poses &&
         !options.extra_candidates.empty()) {
    const DesignPose& last = all.back();
    double best_phi = kInf;
    Choice best;
    DesignPose best_pose;
    for (const Eigen::Vector3d& up : options.extra_candidates) {
      if (up.normalized().dot(last.up) > std::cos(10.0 * internal::kDegToRad)) continue;
      const DesignPose pose{up.normalized(), options.extra_hold_seconds};
      const Eigen::MatrixXd f_pose = f + StaticInformation({pose}, model, gyro_model, noise, basis);
      const std::vector<DesignTurn> turns =
          CandidateTurns(last.up, pose.up, options.free_axes, options.seconds_per_180);
      for (const DesignTurn& t : turns) {
        RotationInformation r = information(last, pose, t);
        if (!r.ok) continue;
        const double trial = phi_of(f_pose + r.fisher, h + r.cross);
        if (trial < best_phi) {
          best_phi = trial;
          best.turns = {t};
          best.info = {r};
          best.chosen = 0;
          best_pose = pose;
        }
      }
    }
    if (best.turns.empty()) break;
    f += StaticInformation({best_pose}, model, gyro_model, noise, basis) + best.info[0].fisher;
    h += best.info[0].cross;
    all.push_back(best_pose);
    pairs.push_back(best);
    ++extra;
  }
  std::vector<DesignTurn> turns;
  for (const Choice& c : pairs) turns.push_back(c.turns[c.chosen]);
  *result = EvaluateRotations(all, turns, model, gyro_model, noise, options.targets);
  result->extra_poses = extra;
  std::ostringstream s;
  s.precision(4);
  s << turns.size() << " turns";
  if (extra > 0) s << " (" << extra << " extra poses for the gyroscope)";
  s << ": " << result->message << " (worst sigma / target " << result->worst_ratio << ")";
  result->message = s.str();
  return true;
}

}  // namespace gravcal
