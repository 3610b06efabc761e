#include "gravcal/methods/known_attitude.h"

#include <ceres/ceres.h>
#include <ceres/covariance.h>
#include <glog/logging.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <array>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

#include "core/warnings.h"
#include "estimation/robust_loss.h"
#include "estimation/solver_settings.h"
#include "estimation/variance_component.h"
#include "gravcal/core/gravity.h"
#include "methods/pose_variance.h"
#include "methods/static_positions.h"
#include "util/source_prefix.h"
#include "util/statistics.h"
#include "util/units.h"

namespace gravcal {

using internal::ChiSquareUpperTail;
using internal::MakeLoss;

namespace {

// Twelve unknowns, three equations per position.
constexpr int kMinKnownPositions = 4;

// Gravity in the body frame of roll r, pitch p (static_alignment.h):
//   u(r, p) = (-sin p, sin r cos p, cos r cos p).
template <typename T>
void GravityDirection(const T& roll, const T& pitch, T* u) {
  using std::cos;
  using std::sin;
  u[0] = -sin(pitch);
  u[1] = sin(roll) * cos(pitch);
  u[2] = cos(roll) * cos(pitch);
}

// r_k = W_k ( M (v_k - b) - g u(roll_k, pitch_k) ), m/s^2 whitened.
// b: bias (3, normalised raw units); M: the 3x3 matrix, row-major (9, m/s^2
// per normalised raw unit); attitude: roll, pitch (2, rad). W_k = L_k^-1,
// L_k L_k^T the covariance of M (v_k - b) from the position's noise.
struct GravityVectorResidual {
  GravityVectorResidual(const Eigen::Vector3d& raw_mean, const Eigen::Matrix3d& whitening,
                        double gravity)
      : raw_mean_(raw_mean), whitening_(whitening), gravity_(gravity) {}

  template <typename T>
  bool operator()(const T* const bias, const T* const m, const T* const attitude,
                  T* residual) const {
    T d[3];
    for (int j = 0; j < 3; ++j) d[j] = T(raw_mean_(j)) - bias[j];
    T u[3];
    GravityDirection(attitude[0], attitude[1], u);
    T e[3];
    for (int i = 0; i < 3; ++i) {
      e[i] = m[3 * i] * d[0] + m[3 * i + 1] * d[1] + m[3 * i + 2] * d[2] - T(gravity_) * u[i];
    }
    for (int i = 0; i < 3; ++i) {
      residual[i] =
          T(whitening_(i, 0)) * e[0] + T(whitening_(i, 1)) * e[1] + T(whitening_(i, 2)) * e[2];
    }
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& raw_mean,
                                     const Eigen::Matrix3d& whitening, double gravity) {
    return new ceres::AutoDiffCostFunction<GravityVectorResidual, 3, 3, 9, 2>(
        new GravityVectorResidual(raw_mean, whitening, gravity));
  }

 private:
  const Eigen::Vector3d raw_mean_;
  const Eigen::Matrix3d whitening_;
  const double gravity_;
};

// p_k = ( (roll - roll_fix) / s_roll, (pitch - pitch_fix) / s_pitch ): the
// fixture's (or inclinometer's) word on the attitude, radians.
struct AttitudePriorResidual {
  explicit AttitudePriorResidual(const KnownAttitude& known) : known_(known) {}

  template <typename T>
  bool operator()(const T* const attitude, T* residual) const {
    residual[0] = (attitude[0] - T(known_.roll)) / T(known_.roll_std);
    residual[1] = (attitude[1] - T(known_.pitch)) / T(known_.pitch_std);
    return true;
  }

  static ceres::CostFunction* Create(const KnownAttitude& known) {
    return new ceres::AutoDiffCostFunction<AttitudePriorResidual, 2, 2>(
        new AttitudePriorResidual(known));
  }

 private:
  const KnownAttitude known_;
};

std::vector<std::string> ParameterNames() {
  std::vector<std::string> names = {"bias_x", "bias_y", "bias_z"};
  const char* axes = "xyz";
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) names.push_back(std::string("m_") + axes[r] + axes[c]);
  }
  return names;
}

// Checks the options, the gravity (resolved unless the caller did), and one
// finite attitude with positive standard deviations per position. False
// with c->message.
bool CheckInputs(const std::vector<Position>& positions,
                 const std::vector<KnownAttitude>& attitudes, const CalibrationOptions& options,
                 Calibration* c) {
  if (!options.IsValid(&c->message)) return false;
  std::string error;
  if (c->gravity_source.empty() &&
      !ResolveGravity(options.gravity, &c->gravity, &c->gravity_source, &error)) {
    c->message = error;
    return false;
  }
  const int n = static_cast<int>(positions.size());
  if (n < kMinKnownPositions) {
    std::ostringstream s;
    s << "found " << n << " static positions; the known-attitude method needs at least "
      << kMinKnownPositions << " (twelve unknowns)";
    c->message = s.str();
    return false;
  }
  if (attitudes.size() != positions.size()) {
    c->message = "known_attitude: one attitude per position is needed";
    return false;
  }
  for (int k = 0; k < n; ++k) {
    const KnownAttitude& a = attitudes[k];
    if (!std::isfinite(a.roll) || !std::isfinite(a.pitch) || !(a.roll_std > 0.0) ||
        !(a.pitch_std > 0.0) || !std::isfinite(a.roll_std) || !std::isfinite(a.pitch_std)) {
      c->message = "known_attitude: attitude " + std::to_string(k) +
                   " is not finite or has no positive standard deviation";
      return false;
    }
  }
  return true;
}

// The estimation state: parameters in normalised raw units (v_n = s0 v,
// s0 = g / mean |v|, which keeps the problem well conditioned whatever the
// raw units are), the attitudes, and the whitening of every position.
struct AttitudeFit {
  double s0 = 1.0;
  double gravity = 0.0;
  double bias[3] = {0.0, 0.0, 0.0};
  double matrix[9] = {};
  std::vector<std::array<double, 2>> attitude;
  // The linear initial M (normalised), which the whitening uses.
  Eigen::Matrix3d initial_matrix = Eigen::Matrix3d::Identity();
  std::vector<Eigen::Matrix3d> whitening;
};

// Initial value, linear: g u_k = M v_k + c_off for the fixed attitudes,
// normal equations over [v_k; 1], then b = -M^-1 c_off; and the whitening
// of every position at it. False with *error.
bool InitialFit(const std::vector<Position>& positions, const std::vector<KnownAttitude>& attitudes,
                AttitudeFit* fit, std::string* error) {
  const int n = static_cast<int>(positions.size());
  const double g = fit->gravity;
  const double s0 = fit->s0;
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  Eigen::Matrix<double, 4, 3> right = Eigen::Matrix<double, 4, 3>::Zero();
  for (int k = 0; k < n; ++k) {
    Eigen::Vector4d row;
    row << s0 * positions[k].raw_mean, 1.0;
    double u[3];
    GravityDirection(attitudes[k].roll, attitudes[k].pitch, u);
    normal += row * row.transpose();
    right += row * (g * Eigen::Vector3d(u[0], u[1], u[2])).transpose();
  }
  const Eigen::LDLT<Eigen::Matrix4d> ldlt(normal);
  const Eigen::Matrix<double, 4, 3> x = ldlt.solve(right);
  const Eigen::Matrix3d m0 = x.topRows<3>().transpose();
  if (ldlt.info() != Eigen::Success || !x.allFinite() || std::fabs(m0.determinant()) < 1e-12) {
    *error =
        "known_attitude: the positions do not determine the twelve parameters (the gravity "
        "directions must not all lie in one plane)";
    return false;
  }
  const Eigen::Vector3d b0 = -m0.inverse() * x.row(3).transpose();
  for (int i = 0; i < 3; ++i) fit->bias[i] = b0(i);
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 3; ++col) fit->matrix[3 * r + col] = m0(r, col);
  }
  fit->attitude.resize(n);
  for (int k = 0; k < n; ++k) fit->attitude[k] = {attitudes[k].roll, attitudes[k].pitch};
  fit->initial_matrix = m0;
  return true;
}

// The whitening of every position: W_k = L_k^-1, L_k L_k^T = M0 (s0^2 C_k)
// M0^T + extra I, extra the per-pose variance of the specific force
// ((m/s^2)^2, 0 = the samples' noise only). False with *error.
bool Whiten(const std::vector<Position>& positions, double extra, AttitudeFit* fit,
            std::string* error) {
  const int n = static_cast<int>(positions.size());
  const Eigen::Matrix3d& m0 = fit->initial_matrix;
  const double s0 = fit->s0;
  fit->whitening.resize(n);
  for (int k = 0; k < n; ++k) {
    Eigen::Matrix3d cov = m0 * (s0 * s0 * positions[k].raw_mean_cov) * m0.transpose();
    cov.diagonal().array() += extra;
    const Eigen::LLT<Eigen::Matrix3d> llt(cov);
    if (llt.info() != Eigen::Success) {
      *error = "known_attitude: static position " + std::to_string(k) +
               " has no usable noise estimate (its covariance is not positive definite)";
      return false;
    }
    fit->whitening[k] = llt.matrixL().solve(Eigen::Matrix3d::Identity());
  }
  return true;
}

// The Ceres problem at the fit's current values and whitening, solved.
std::unique_ptr<ceres::Problem> Solve(const std::vector<Position>& positions,
                                      const std::vector<KnownAttitude>& attitudes,
                                      const RefinementOptions& ro, AttitudeFit* fit,
                                      ceres::Solver::Summary* summary) {
  auto problem = std::make_unique<ceres::Problem>();
  for (size_t k = 0; k < positions.size(); ++k) {
    problem->AddResidualBlock(GravityVectorResidual::Create(fit->s0 * positions[k].raw_mean,
                                                            fit->whitening[k], fit->gravity),
                              MakeLoss(ro.loss, ro.loss_scale), fit->bias, fit->matrix,
                              fit->attitude[k].data());
    problem->AddResidualBlock(AttitudePriorResidual::Create(attitudes[k]), nullptr,
                              fit->attitude[k].data());
  }
  ceres::Solve(internal::SolverOptions(ro.solver, ceres::DENSE_QR), problem.get(), summary);
  return problem;
}

// Whitened sum of squares (no loss) at the current parameters.
double Chi2(const std::vector<Position>& positions, const std::vector<KnownAttitude>& attitudes,
            AttitudeFit* fit) {
  double sum = 0.0;
  for (size_t k = 0; k < positions.size(); ++k) {
    double r[3], p[2];
    const GravityVectorResidual sensor(fit->s0 * positions[k].raw_mean, fit->whitening[k],
                                       fit->gravity);
    const AttitudePriorResidual prior(attitudes[k]);
    sensor(fit->bias, fit->matrix, fit->attitude[k].data(), r);
    prior(fit->attitude[k].data(), p);
    sum += r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + p[0] * p[0] + p[1] * p[1];
  }
  return sum;
}

// The covariance of (b, M) in raw units (scale_back per parameter) into
// c->refinement and c->accel, and each attitude's standard deviations.
void ComputeCovariance(ceres::Problem* problem, const double scale_back[12], double inflation,
                       AttitudeFit* fit, std::vector<Eigen::Vector2d>* attitude_std,
                       Calibration* c) {
  RefinementResult& f = c->refinement;
  double* bias = fit->bias;
  double* matrix = fit->matrix;
  std::vector<std::array<double, 2>>& attitude = fit->attitude;
  const int n = static_cast<int>(attitude.size());
  ceres::Covariance::Options covariance_options;
  covariance_options.algorithm_type = ceres::DENSE_SVD;
  covariance_options.num_threads = 1;
  ceres::Covariance covariance(covariance_options);
  std::vector<std::pair<const double*, const double*>> blocks = {
      {bias, bias}, {bias, matrix}, {matrix, matrix}};
  for (int k = 0; k < n; ++k) blocks.push_back({attitude[k].data(), attitude[k].data()});
  if (covariance.Compute(blocks, problem)) {
    double cbb[9], cbm[27], cmm[81];
    covariance.GetCovarianceBlock(bias, bias, cbb);
    covariance.GetCovarianceBlock(bias, matrix, cbm);
    covariance.GetCovarianceBlock(matrix, matrix, cmm);
    Eigen::MatrixXd cov(12, 12);
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) cov(i, j) = cbb[3 * i + j];
      for (int j = 0; j < 9; ++j) cov(i, 3 + j) = cov(3 + j, i) = cbm[9 * i + j];
    }
    for (int i = 0; i < 9; ++i) {
      for (int j = 0; j < 9; ++j) cov(3 + i, 3 + j) = cmm[9 * i + j];
    }
    for (int i = 0; i < 12; ++i) {
      for (int j = 0; j < 12; ++j) cov(i, j) *= inflation * scale_back[i] * scale_back[j];
    }
    f.covariance = cov;
    f.covariance_available = true;
    c->accel.covariance = cov;
    c->accel.covariance_names = f.parameter_names;
    for (int i = 0; i < 3; ++i) c->accel.bias_std(i) = std::sqrt(cov(i, i));
    for (int i = 0; i < 9; ++i) c->accel.matrix_std(i / 3, i % 3) = std::sqrt(cov(3 + i, 3 + i));
    for (int k = 0; k < n; ++k) {
      double ca[4];
      covariance.GetCovarianceBlock(attitude[k].data(), attitude[k].data(), ca);
      (*attitude_std)[k] =
          Eigen::Vector2d(std::sqrt(inflation * ca[0]), std::sqrt(inflation * ca[3]));
    }
  } else {
    internal::AddWarning(WarningCode::kNoCovariance,
                         "known_attitude: the covariance could not be computed (rank deficient); "
                         "no standard deviations are reported",
                         &c->warnings, &c->warning_codes);
  }
}

// The whitened residuals (sensor and prior, no loss) and their Jacobian
// over (b, M, attitudes) at the solution, and the shape of a per-pose
// specific-force variance s^2 I in them: W_k W_k^T on position k's sensor
// rows, zero on the priors (estimation/variance_component.h).
void WhitenedSystem(ceres::Problem* problem, AttitudeFit* fit, Eigen::VectorXd* residuals,
                    Eigen::MatrixXd* jacobian, Eigen::MatrixXd* shape) {
  const int n = static_cast<int>(fit->attitude.size());
  ceres::Problem::EvaluateOptions evaluate;
  evaluate.apply_loss_function = false;
  evaluate.parameter_blocks = {fit->bias, fit->matrix};
  for (int k = 0; k < n; ++k) evaluate.parameter_blocks.push_back(fit->attitude[k].data());
  double cost = 0.0;
  std::vector<double> r;
  ceres::CRSMatrix crs;
  problem->Evaluate(evaluate, &cost, &r, nullptr, &crs);
  *residuals = Eigen::Map<const Eigen::VectorXd>(r.data(), r.size());
  *jacobian = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row) {
    for (int i = crs.rows[row]; i < crs.rows[row + 1]; ++i) {
      (*jacobian)(row, crs.cols[i]) = crs.values[i];
    }
  }
  *shape = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_rows);
  for (int k = 0; k < n; ++k) {
    shape->block<3, 3>(5 * k, 5 * k) = fit->whitening[k] * fit->whitening[k].transpose();
  }
}

// What the samples of each position cannot show (placement disturbances,
// tremor, mount flex): one extra specific-force variance s^2 per position,
// estimated by REML (with the prior of pose_disturbance_prior) from the
// fit's residuals, added to every position's covariance and the fit
// repeated; the covariance then carries the Student-t factor of an
// estimated s^2 (*inflation), as in twelve_position (methods/pose_variance.h).
// Replaces *problem and *summary by the re-weighted fit's when absorbed.
void AccountForPoseVariance(const std::vector<Position>& positions,
                            const std::vector<KnownAttitude>& attitudes,
                            const RefinementOptions& ro, AttitudeFit* fit,
                            std::unique_ptr<ceres::Problem>* problem,
                            ceres::Solver::Summary* summary, double* inflation, Calibration* c) {
  VarianceComponent& vc = c->accel.pose_variance;
  vc = VarianceComponent();
  *inflation = 1.0;
  if (!ro.estimate_pose_variance) {
    vc.message = "not estimated (pose_variance: false)";
    return;
  }
  if (!summary->IsSolutionUsable()) {
    vc.message = "not estimated: the fit did not converge";
    return;
  }
  Eigen::VectorXd residuals;
  Eigen::MatrixXd jacobian, shape;
  WhitenedSystem(problem->get(), fit, &residuals, &jacobian, &shape);
  internal::VariancePrior prior;
  prior.variance = ro.pose_disturbance_prior * ro.pose_disturbance_prior;
  prior.dof = ro.pose_disturbance_prior_dof;
  VarianceComponent estimate;
  double known = 0.0;
  if (!internal::EstimateWhitenedVarianceComponent(residuals, jacobian, shape, &estimate, prior,
                                                   &known)) {
    vc.message = "not estimated: " + estimate.message;
    return;
  }
  vc = estimate;
  if (vc.at_boundary) return;
  std::string error;
  if (!Whiten(positions, vc.variance, fit, &error)) {
    vc.message += "; not absorbed: " + error;
    return;
  }
  ceres::Solver::Summary again;
  std::unique_ptr<ceres::Problem> reweighted = Solve(positions, attitudes, ro, fit, &again);
  *problem = std::move(reweighted);
  *summary = again;
  double effective_dof = INFINITY;
  // The known variance per residual direction (sensor noise and the
  // attitudes' uncertainty) beside s^2 (variance_component.h).
  *inflation = internal::StudentInflation(vc, known, &effective_dof);
  vc.absorbed = true;
  std::ostringstream t;
  t.precision(3);
  t << "; added to every position's variance, covariance x " << *inflation << " (Student t, "
    << effective_dof << " effective dof)";
  vc.message += t.str();
  internal::WarnPoseVariance(vc, effective_dof, ro, &c->warnings, &c->warning_codes);
}

// Warnings on the fit's degrees of freedom and chi-square.
void WarnFit(const RefinementResult& f, Calibration* c) {
  if (f.dof <= 0) {
    internal::AddWarning(WarningCode::kExactFit,
                         "known_attitude: as many equations as unknowns; the fit cannot show "
                         "whether the attitudes or the noise estimate are right: record more "
                         "positions",
                         &c->warnings, &c->warning_codes);
  } else if (ChiSquareUpperTail(f.chi2, f.dof) < 1e-3) {
    std::ostringstream s;
    s.precision(3);
    s << "known_attitude: residuals are " << std::sqrt(f.chi2 / f.dof)
      << " times what the sensor noise and the stated attitude uncertainties allow (chi2 = "
      << f.chi2 << " on " << f.dof
      << " dof): an attitude is wrong or too confident, or a position was disturbed; the "
         "standard deviations are too small by about that factor";
    internal::AddWarning(WarningCode::kResidualsAboveNoise, s.str(), &c->warnings,
                         &c->warning_codes);
  }
}

}  // namespace

bool CalibrateFromKnownAttitudes(const std::vector<Position>& positions,
                                 const std::vector<KnownAttitude>& attitudes,
                                 const CalibrationOptions& options, Calibration* calibration) {
  CHECK(calibration != nullptr);
  Calibration& c = *calibration;
  c.method = ToString(Method::kKnownAttitude);
  if (!CheckInputs(positions, attitudes, options, &c)) return false;
  const int n = static_cast<int>(positions.size());
  const double g = c.gravity;
  AttitudeFit fit;
  fit.gravity = g;
  double mean_norm = 0.0;
  for (const Position& p : positions) mean_norm += p.raw_mean.norm();
  fit.s0 = g * n / mean_norm;
  const double s0 = fit.s0;
  if (!InitialFit(positions, attitudes, &fit, &c.message) ||
      !Whiten(positions, 0.0, &fit, &c.message)) {
    return false;
  }

  const RefinementOptions& ro = options.refinement;
  RefinementResult& f = c.refinement;
  f.initial_cost = 0.5 * Chi2(positions, attitudes, &fit);
  ceres::Solver::Summary summary;
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<ceres::Problem> problem = Solve(positions, attitudes, ro, &fit, &summary);
  int iterations = static_cast<int>(summary.iterations.size()) - 1;
  double inflation = 1.0;
  AccountForPoseVariance(positions, attitudes, ro, &fit, &problem, &summary, &inflation, &c);
  if (c.accel.pose_variance.absorbed) iterations += static_cast<int>(summary.iterations.size()) - 1;
  f.solve_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  f.iterations = iterations;
  f.termination = ceres::TerminationTypeToString(summary.termination_type);
  f.converged = summary.termination_type == ceres::CONVERGENCE;
  f.chi2 = Chi2(positions, attitudes, &fit);
  f.final_cost = 0.5 * f.chi2;
  f.num_residuals = 5 * n;
  f.num_parameters = 12;
  f.dof = 3 * n - 12;
  f.parameter_names = ParameterNames();
  c.solver_name = "ceres_levenberg_marquardt (known attitudes)";

  const double scale_back[12] = {1 / s0, 1 / s0, 1 / s0, s0, s0, s0, s0, s0, s0, s0, s0, s0};
  Eigen::Vector3d b;
  Eigen::Matrix3d m;
  for (int i = 0; i < 3; ++i) b(i) = fit.bias[i] * scale_back[i];
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = fit.matrix[i] * s0;
  if (!summary.IsSolutionUsable() || !b.allFinite() || !m.allFinite() ||
      !AccelModel::FromMatrix(b, m, AccelParameterization::kAffine, &c.accel.model)) {
    c.not_converged = true;
    c.message = "known_attitude: the solve failed (" + summary.message + ")";
    return false;
  }
  f.model = c.accel.model;

  std::vector<Eigen::Vector2d> attitude_std(n, Eigen::Vector2d::Constant(NAN));
  if (ro.compute_covariance) {
    ComputeCovariance(problem.get(), scale_back, inflation, &fit, &attitude_std, &c);
  }
  WarnFit(f, &c);

  AccelModel nominal;
  nominal.upper = s0 * Eigen::Matrix3d::Identity();
  internal::ReportPositions(positions, nominal, c.accel.model, g, {}, &c);
  c.residual_coarse = c.residual_nominal;
  for (int k = 0; k < n; ++k) {
    PositionReport& r = c.positions[k];
    r.roll_deg = fit.attitude[k][0] * internal::kRadToDeg;
    r.pitch_deg = fit.attitude[k][1] * internal::kRadToDeg;
    r.roll_std_deg = attitude_std[k](0) * internal::kRadToDeg;
    r.pitch_std_deg = attitude_std[k](1) * internal::kRadToDeg;
  }
  std::ostringstream s;
  s << (f.converged ? "converged" : "did not converge") << " after " << f.iterations
    << " iterations (" << f.termination << ")";
  f.message = s.str();
  if (!f.converged) {
    c.not_converged = true;
    c.message = "known_attitude: the solve " + f.message + ": " + summary.message;
    return false;
  }
  c.success = true;
  std::ostringstream done;
  done.precision(3);
  done << "calibrated 'known_attitude' (all 12 parameters) from " << n << " positions ("
       << f.message << ", chi2 " << f.chi2 << " on " << f.dof << " dof)";
  c.message = done.str();
  return true;
}

bool CalibrateKnownAttitude(const ImuLog& log, const std::string& attitudes_path,
                            const CalibrationOptions& options, Calibration* calibration) {
  CHECK(calibration != nullptr);
  *calibration = Calibration();
  calibration->method = ToString(Method::kKnownAttitude);
  if (attitudes_path.empty()) {
    calibration->message = "known_attitude needs the attitudes file (--attitudes fixture.csv)";
    return false;
  }
  std::vector<FixtureAttitude> rows;
  if (!ReadFixtureAttitudes(attitudes_path, &rows, &calibration->message)) return false;
  return CalibrateKnownAttitude(log, rows, attitudes_path, options, calibration);
}

bool CalibrateKnownAttitude(const ImuLog& log, const std::vector<FixtureAttitude>& rows,
                            const std::string& attitudes_name, const CalibrationOptions& options,
                            Calibration* calibration) {
  Session session;
  session.log = log;
  session.attitudes = rows;
  session.attitudes_name = attitudes_name;
  return CalibrateKnownAttitude(session, {options}, calibration);
}

bool CalibrateKnownAttitude(const Session& session, const KnownAttitudeMethodOptions& method,
                            Calibration* calibration) {
  CHECK(calibration != nullptr);
  *calibration = Calibration();
  Calibration& c = *calibration;
  c.method = ToString(Method::kKnownAttitude);
  CalibrationOptions options = method.accel;
  if (session.noise) options.pose_noise.model = session.noise_model();
  std::vector<StaticInterval> intervals;
  std::vector<Position> positions;
  if (!internal::DetectStaticPositions(session, options, &c, &intervals, &positions)) return false;
  std::vector<int> row_of_position;
  std::string error;
  const std::vector<FixtureAttitude>& rows = session.attitudes;
  if (!MatchFixtureAttitudes(rows, intervals, session.attitudes_name, &row_of_position, &error)) {
    c.message = error;
    return false;
  }
  std::vector<KnownAttitude> attitudes;
  for (int row : row_of_position) {
    const FixtureAttitude& r = rows[row];
    attitudes.push_back({r.roll_deg * internal::kDegToRad, r.pitch_deg * internal::kDegToRad,
                         r.roll_std_deg * internal::kDegToRad,
                         r.pitch_std_deg * internal::kDegToRad});
  }
  const bool ok = CalibrateFromKnownAttitudes(positions, attitudes, options, &c);
  if (!ok) c.message = internal::PrefixSource(session.log.source, c.message);
  return ok;
}

}  // namespace gravcal
