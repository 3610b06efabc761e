#include "gravcal/methods/effect_fit.h"

#include <ceres/ceres.h>
#include <ceres/manifold.h>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "estimation/normalization.h"
#include "estimation/robust_loss.h"
#include "estimation/solver_settings.h"
#include "estimation/variance_component.h"
#include "gravcal/estimation/observability.h"
#include "gravcal/estimation/refinement.h"
#include "gravcal/residuals/accel_rotation_residual.h"
#include "gravcal/residuals/accel_trend_residual.h"
#include "gravcal/residuals/gravity_magnitude_residual.h"
#include "gravcal/residuals/gyro_static_residual.h"
#include "methods/between_pose_rotations.h"
#include "methods/within_pose_trend.h"
#include "util/statistics.h"

namespace gravcal {

using internal::ChiSquareUpperTail;
using internal::Normalization;
namespace {

// Relative tolerance of the rank test on the scaled whitened Jacobian: a
// direction this weak (condition number 1e7) is not determined in practice.
constexpr double kRankTolerance = 1e-7;

// Indices into the 6-vector of U, row-major upper triangle.
constexpr int kOffDiagonal[3] = {1, 2, 4};

bool IsAccelEffect(Effect e) { return Info(e).sensor == EffectSensor::kAccelerometer; }

ceres::Solver::Options SolverOptions(const EffectFitOptions& o) {
  return internal::SolverOptions(o.solver, ceres::DENSE_NORMAL_CHOLESKY);
}

// (J^T J)^-1 of a whitened Jacobian, with the undetermined parameters (null
// space) named and their rows and columns NaN; the rest from the
// pseudo-inverse. Also the leverage of each position (rows_per_position
// consecutive rows among the first leverage_rows).
void CovarianceFromJacobian(const Eigen::MatrixXd& jacobian, int rows_per_position,
                            int leverage_rows, SensorFitSummary* fit) {
  const ObservabilityReport obs =
      AnalyzeObservability(jacobian, fit->parameter_names, kRankTolerance);
  fit->undetermined = obs.undetermined;
  fit->rank = obs.rank;
  const int n = static_cast<int>(jacobian.cols());
  // Column scaling keeps the units out of the conditioning.
  Eigen::VectorXd scale = jacobian.colwise().norm().transpose();
  for (int j = 0; j < n; ++j) {
    if (!(scale(j) > 0.0)) scale(j) = 1.0;
  }
  const Eigen::MatrixXd scaled = jacobian * scale.cwiseInverse().asDiagonal();
  Eigen::MatrixXd inverse;
  if (obs.full_rank()) {
    const Eigen::MatrixXd gram = scaled.transpose() * scaled;
    inverse = gram.ldlt().solve(Eigen::MatrixXd::Identity(n, n));
  } else {
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinV);
    const Eigen::VectorXd s = svd.singularValues();
    Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(s.size());
    for (int i = 0; i < s.size(); ++i) {
      if (s(i) > kRankTolerance * s(0)) inv2(i) = 1.0 / (s(i) * s(i));
    }
    inverse = svd.matrixV() * inv2.asDiagonal() * svd.matrixV().transpose();
  }
  fit->covariance = scale.cwiseInverse().asDiagonal() * inverse * scale.cwiseInverse().asDiagonal();
  fit->leverage.clear();
  for (int k = 0; k * rows_per_position < leverage_rows; ++k) {
    double h = 0.0;
    for (int r = 0; r < rows_per_position; ++r) {
      const Eigen::RowVectorXd row = scaled.row(k * rows_per_position + r);
      h = std::max(h, (row * inverse * row.transpose())(0, 0));
    }
    fit->leverage.push_back(h);
  }
  for (const std::string& name : obs.undetermined) {
    const auto it = std::find(fit->parameter_names.begin(), fit->parameter_names.end(), name);
    const int i = static_cast<int>(it - fit->parameter_names.begin());
    fit->covariance.row(i).setConstant(NAN);
    fit->covariance.col(i).setConstant(NAN);
  }
}

// Inverse of the lower Cholesky factor of a covariance, with a floor on
// the diagonal so a constant (quantised) signal still has a finite weight.
Eigen::Matrix3d Whitening(const Eigen::Matrix3d& covariance) {
  Eigen::LLT<Eigen::Matrix3d> llt(covariance);
  if (llt.info() != Eigen::Success) return Eigen::Matrix3d::Constant(NAN);
  const Eigen::Matrix3d l = llt.matrixL();
  return l.inverse();
}

// The whitening of a pose's trend residual (accel_trend_residual.h), raw
// units: L^-1 of the slope's covariance, or with trend_along_gravity the
// one row n^T / sqrt(n^T cov n), n the direction of `centered_mean` (the
// pose's mean raw vector less the bias).
AccelTrendResidual::Whitening TrendWhitening(const StaticObservation& o,
                                             const Eigen::Vector3d& centered_mean) {
  if (!o.trend_along_gravity) return Whitening(o.accel_slope_cov);
  const Eigen::RowVector3d n = centered_mean.normalized().transpose();
  const double variance = n * o.accel_slope_cov * n.transpose();
  if (!(variance > 0.0)) return AccelTrendResidual::Whitening::Constant(1, 3, NAN);
  return n / std::sqrt(variance);
}

// result->accel_sigmas from the positions' own noise at `start`; false with
// the message when one is not positive and finite.
bool SetAccelSigmas(const std::vector<Position>& positions, const AccelModel& start,
                    EffectFitResult* result) {
  result->accel_sigmas = MagnitudeSigmas(positions, start);
  for (size_t k = 0; k < positions.size(); ++k) {
    const double s = result->accel_sigmas[k];
    if (!(s > 0.0) || !std::isfinite(s)) {
      std::ostringstream msg;
      msg << "position " << k << " has no usable accelerometer noise estimate (sigma = " << s
          << ")";
      result->message = msg.str();
      return false;
    }
  }
  return true;
}

// The accelerometer effects with a parameter block each, in block order.
constexpr Effect kAccelBlockEffect[4] = {Effect::kAccelQuadratic, Effect::kAccelTemperatureBias,
                                         Effect::kAccelTemperatureScale, Effect::kAccelBiasDrift};

// fit->parameter_names (the columns of the dense Jacobian); returns the
// indices of the free entries of U.
std::vector<int> SetAccelParameterNames(bool free_off_diagonal, const bool on[4], bool rotations,
                                        SensorFitSummary* fit) {
  static const char* kUpperNames[6] = {"u_xx", "u_xy", "u_xz", "u_yy", "u_yz", "u_zz"};
  fit->parameter_names = {"bias_x", "bias_y", "bias_z"};
  std::vector<int> upper_free;
  for (int i = 0; i < 6; ++i) {
    const bool off = i == 1 || i == 2 || i == 4;
    if (off && !free_off_diagonal) continue;
    upper_free.push_back(i);
    fit->parameter_names.push_back(kUpperNames[i]);
  }
  for (int b = 0; b < 4; ++b) {
    if (!on[b]) continue;
    for (const std::string& n : Info(kAccelBlockEffect[b]).parameter_names) {
      fit->parameter_names.push_back(n);
    }
  }
  if (rotations) {
    for (const char* n : {"rotation_gyro_bias_x", "rotation_gyro_bias_y", "rotation_gyro_bias_z",
                          "rotation_gyro_m_xx", "rotation_gyro_m_xy", "rotation_gyro_m_xz",
                          "rotation_gyro_m_yx", "rotation_gyro_m_yy", "rotation_gyro_m_yz",
                          "rotation_gyro_m_zx", "rotation_gyro_m_zy", "rotation_gyro_m_zz"}) {
      fit->parameter_names.push_back(n);
    }
  }
  return upper_free;
}

// Start of the warning FitEffects gives when the rotation rows exceed their
// noise (p < 0.001).
constexpr char kRotationsExceedNoise[] = "the rotations between poses exceed their noise";

// Columns of the gyroscope's nuisance parameters (b_g' 3, M_g' 9) with the
// rotations between poses.
constexpr int kRotationGyroColumns = 12;

// One residual block of the accelerometer fit: a position's magnitude (1
// row), its within-pose trend (3 rows) or a rotation between two poses (2
// rows, which also take the gyroscope's blocks b_g', M_g'). The cost
// functions are kept (not owned by the problem) to evaluate the Jacobian at
// the optimum.
struct AccelBlock {
  std::unique_ptr<ceres::CostFunction> cost;
  int rows = 1;
  int position = 0;
  bool trend = false;
  bool rotation = false;
};

// fit->chi2 (and trend_chi2), the whitened residuals (all rows, and the
// trend residuals per position) and, with
// `covariance`, the dense Jacobian of the free parameters at `params`, rows
// in block order; false when the model has no value at a position.
// params holds the six accelerometer blocks and, with rotations, b_g' and
// M_g' (their columns last).
bool EvaluateAccelFit(const std::vector<AccelBlock>& blocks, const double* const params[8],
                      const std::vector<int>& upper_free, const bool on[4], bool rotations,
                      bool covariance, Eigen::MatrixXd* jacobian, Eigen::VectorXd* residuals,
                      SensorFitSummary* fit, std::vector<Eigen::Vector3d>* trend_residuals,
                      std::vector<Eigen::Vector2d>* rotation_residuals) {
  fit->chi2 = 0.0;
  fit->trend_chi2 = 0.0;
  fit->rotation_chi2 = 0.0;
  rotation_residuals->clear();
  int row0 = 0;
  for (const AccelBlock& block : blocks) {
    double r[3];
    double jb[9], ju[18], je[4][9], jgb[9], jgm[27];
    double* jacobians[8] = {jb, ju, je[0], je[1], je[2], je[3], jgb, jgm};
    if (!block.cost->Evaluate(params, r, covariance ? jacobians : nullptr)) return false;
    for (int row = 0; row < block.rows; ++row) {
      (*residuals)(row0 + row) = r[row];
      fit->chi2 += r[row] * r[row];
      if (block.trend) fit->trend_chi2 += r[row] * r[row];
      if (block.rotation) fit->rotation_chi2 += r[row] * r[row];
      if (!covariance) continue;
      int col = 0;
      for (int i = 0; i < 3; ++i) (*jacobian)(row0 + row, col++) = jb[3 * row + i];
      for (int i : upper_free) (*jacobian)(row0 + row, col++) = ju[6 * row + i];
      for (int b = 0; b < 4; ++b) {
        if (!on[b]) continue;
        for (int i = 0; i < 3; ++i) (*jacobian)(row0 + row, col++) = je[b][3 * row + i];
      }
      if (!rotations) continue;
      for (int i = 0; i < 3; ++i) {
        (*jacobian)(row0 + row, col++) = block.rotation ? jgb[3 * row + i] : 0.0;
      }
      for (int i = 0; i < 9; ++i) {
        (*jacobian)(row0 + row, col++) = block.rotation ? jgm[9 * row + i] : 0.0;
      }
    }
    if (block.trend) {
      Eigen::Vector3d t = Eigen::Vector3d::Zero();
      for (int row = 0; row < block.rows; ++row) t(row) = r[row];
      (*trend_residuals)[block.position] = t;
    }
    if (block.rotation) rotation_residuals->push_back(Eigen::Vector2d(r[0], r[1]));
    row0 += block.rows;
  }
  return true;
}

// After the accelerometer fit: the covariance (with `covariance`, back in
// raw units), the bias standard deviations, the residuals and the forces.
// The first observations.size() rows of the Jacobian are the magnitudes.
void FinishAccel(const std::vector<StaticObservation>& observations, double gravity, double scale,
                 const Eigen::MatrixXd& jacobian, const std::vector<int>& upper_free,
                 bool covariance, const internal::RotationRows* rotations,
                 EffectFitResult* result) {
  SensorFitSummary* fit = &result->accel_fit;
  if (covariance) {
    CovarianceFromJacobian(jacobian, 1, static_cast<int>(observations.size()), fit);
    // Back to raw units: b = c + s b', U = U' / s; the effects are in SI;
    // the gyroscope's b_g = c_g + b_g' / s_g, M_g = s_g M_g'.
    Eigen::VectorXd d = Eigen::VectorXd::Ones(jacobian.cols());
    d.head<3>().setConstant(scale);
    for (size_t i = 0; i < upper_free.size(); ++i) d(3 + i) = 1.0 / scale;
    if (rotations != nullptr) {
      const int g0 = static_cast<int>(jacobian.cols()) - kRotationGyroColumns;
      d.segment<3>(g0).setConstant(1.0 / rotations->scale);
      d.segment<9>(g0 + 3).setConstant(rotations->scale);
    }
    fit->covariance = d.asDiagonal() * fit->covariance * d.asDiagonal();
    for (int i = 0; i < 3; ++i) result->accel_bias_std(i) = fit->Std(fit->parameter_names[i]);
  }

  result->accel_residuals.resize(observations.size());
  result->forces.resize(observations.size());
  for (size_t k = 0; k < observations.size(); ++k) {
    result->accel_residuals[k] =
        AccelResidual(*result, observations[k], gravity, &result->forces[k]);
  }
}

// The magnitude residual of every position, then the trend residual of
// every position that has one (with `trends`), in normalised raw units.
std::vector<AccelBlock> AccelBlocks(const std::vector<StaticObservation>& observations,
                                    const std::vector<Position>& normalized, double scale,
                                    const EffectParameters& initial_parameters, double gravity,
                                    const std::vector<double>& sigmas, bool trends) {
  std::vector<AccelBlock> blocks;
  for (size_t k = 0; k < normalized.size(); ++k) {
    const StaticObservation& o = observations[k];
    AccelBlock b;
    b.position = static_cast<int>(k);
    b.cost.reset(GravityMagnitudeResidual::CreateWithEffects(
        normalized[k].raw_mean, TemperatureOffset(initial_parameters, o.temperature()),
        o.time() - initial_parameters.reference_time, gravity, sigmas[k]));
    blocks.push_back(std::move(b));
  }
  if (!trends) return blocks;
  for (size_t k = 0; k < normalized.size(); ++k) {
    const StaticObservation& o = observations[k];
    if (!o.has_trend) continue;
    // Normalised units: the slope and its standard deviation divide by s.
    const AccelTrendResidual::Whitening whitening =
        TrendWhitening(o, normalized[k].raw_mean) * scale;
    if (!whitening.allFinite()) continue;
    AccelBlock b;
    b.position = static_cast<int>(k);
    b.rows = static_cast<int>(whitening.rows());
    b.trend = true;
    b.cost.reset(AccelTrendResidual::Create(normalized[k].raw_mean, o.accel_slope / scale,
                                            whitening, o.temperature_slope,
                                            TemperatureOffset(initial_parameters, o.temperature()),
                                            o.time() - initial_parameters.reference_time));
    blocks.push_back(std::move(b));
  }
  return blocks;
}

// The largest whitened norm |r| of the blocks at `params` (the widest scale
// of a graduated robust solve).
double LargestBlockNorm(const std::vector<AccelBlock>& blocks, const double* const params[8]) {
  double largest = 0.0;
  for (const AccelBlock& b : blocks) {
    double r[3];
    if (!b.cost->Evaluate(params, r, nullptr)) continue;
    largest = std::max(largest, Eigen::Map<const Eigen::VectorXd>(r, b.rows).norm());
  }
  return largest;
}

// With a robust loss rho at the final scale: each block's whitened rows
// (Jacobian and residual, block order) times sqrt(rho'(|r|^2)), the weight
// iteratively reweighted least squares gives the block at the optimum, so
// the covariance counts a block the loss set aside as the solve did.
void WeightRowsByLoss(const std::vector<AccelBlock>& blocks, const EffectFitOptions& options,
                      Eigen::MatrixXd* jacobian, Eigen::VectorXd* residual_rows) {
  const std::unique_ptr<ceres::LossFunction> rho(
      internal::MakeLoss(options.loss, options.loss_scale));
  int row0 = 0;
  for (const AccelBlock& b : blocks) {
    const double s = residual_rows->segment(row0, b.rows).squaredNorm();
    double values[3];
    rho->Evaluate(s, values);
    const double w = std::sqrt(std::max(0.0, values[1]));
    jacobian->middleRows(row0, b.rows) *= w;
    residual_rows->segment(row0, b.rows) *= w;
    row0 += b.rows;
  }
}

// The accelerometer part. Works in normalised raw units (normalization.h).
bool FitAccel(const std::vector<StaticObservation>& observations, const AccelModel& initial,
              const EffectParameters& initial_parameters, double gravity,
              const EffectFitOptions& options, double extra_variance,
              Eigen::MatrixXd* whitened_jacobian, Eigen::VectorXd* whitened_residuals,
              EffectFitResult* result) {
  const std::vector<Effect>& effects = options.effects;
  const bool free_off_diagonal = options.parameterization != AccelParameterization::kScale ||
                                 Contains(effects, Effect::kAccelMisalignment);
  std::vector<Position> positions;
  for (const StaticObservation& o : observations) positions.push_back(o.accel);
  AccelModel start = initial;
  if (!free_off_diagonal) {
    for (int i : kOffDiagonal) {
      const int r = i == 4 ? 1 : 0;
      const int c = i == 1 ? 1 : 2;
      start.upper(r, c) = 0.0;
    }
  }
  if (!SetAccelSigmas(positions, start, result)) return false;
  for (double& sigma : result->accel_sigmas) sigma = std::sqrt(sigma * sigma + extra_variance);
  const Normalization norm = Normalization::For(start);
  const AccelModel start_n = norm.Apply(start);
  const std::vector<Position> normalized = norm.Apply(positions);

  double bias[3] = {start_n.bias(0), start_n.bias(1), start_n.bias(2)};
  double upper[6];
  start_n.GetUpper(upper);
  double blocks[4][3];
  const Eigen::Vector3d* kInitial[4] = {
      &initial_parameters.accel_quadratic, &initial_parameters.accel_temperature_bias,
      &initial_parameters.accel_temperature_scale, &initial_parameters.accel_bias_drift};
  bool on[4];
  for (int b = 0; b < 4; ++b) {
    on[b] = Contains(effects, kAccelBlockEffect[b]);
    for (int i = 0; i < 3; ++i) blocks[b][i] = on[b] ? (*kInitial[b])(i) : 0.0;
  }

  std::vector<AccelBlock> residuals =
      AccelBlocks(observations, normalized, norm.scale, initial_parameters, gravity,
                  result->accel_sigmas, options.use_within_pose_trends);
  std::vector<double*> parameter_blocks = {bias, upper, blocks[0], blocks[1], blocks[2], blocks[3]};
  // The rotations between poses, with the gyroscope's blocks.
  internal::RotationRows rotation_rows;
  bool rotations = false;
  if (options.use_between_pose_rotations) {
    const internal::AccelBlocks held = {{bias, upper, blocks[0], blocks[1], blocks[2], blocks[3]}};
    std::string why;
    rotations = internal::PrepareRotationRows(observations, norm, initial_parameters, held,
                                              extra_variance, options.rotation_gyro_bias_variance,
                                              options.solver, &rotation_rows, &why);
    if (!rotations && std::find(result->warnings.begin(), result->warnings.end(), why) ==
                          result->warnings.end()) {
      result->warnings.push_back(why);
    }
  }
  if (rotations) {
    for (size_t j = 0; j < rotation_rows.data.size(); ++j) {
      AccelBlock b;
      b.position = rotation_rows.poses[j].second;
      b.rows = 2;
      b.rotation = true;
      b.cost.reset(AccelRotationResidual::Create(rotation_rows.data[j]));
      residuals.push_back(std::move(b));
    }
  }
  const double* params[8] = {bias,
                             upper,
                             blocks[0],
                             blocks[1],
                             blocks[2],
                             blocks[3],
                             rotation_rows.gyro_bias,
                             rotation_rows.gyro_matrix};
  const std::vector<double> scales = internal::GraduatedLossScales(
      options.loss, options.loss_scale,
      options.loss == LossType::kNone ? 0.0 : LargestBlockNorm(residuals, params));
  ceres::Problem::Options keep;
  keep.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  keep.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(keep);
  std::unique_ptr<ceres::LossFunctionWrapper> loss;
  if (options.loss != LossType::kNone) {
    loss = std::make_unique<ceres::LossFunctionWrapper>(
        internal::MakeLoss(options.loss, scales.back()), ceres::TAKE_OWNERSHIP);
  }
  int num_rows = 0, trend_rows = 0, rotation_rows_count = 0;
  for (const AccelBlock& b : residuals) {
    if (b.rotation) {
      std::vector<double*> with_gyro = parameter_blocks;
      with_gyro.push_back(rotation_rows.gyro_bias);
      with_gyro.push_back(rotation_rows.gyro_matrix);
      problem.AddResidualBlock(b.cost.get(), loss.get(), with_gyro);
    } else {
      problem.AddResidualBlock(b.cost.get(), loss.get(), parameter_blocks);
    }
    num_rows += b.rows;
    if (b.trend) trend_rows += b.rows;
    if (b.rotation) rotation_rows_count += b.rows;
  }
  if (!free_off_diagonal) {
    problem.SetManifold(upper, new ceres::SubsetManifold(6, {1, 2, 4}));
  }
  for (int b = 0; b < 4; ++b) {
    if (!on[b]) problem.SetParameterBlockConstant(blocks[b]);
  }
  // Once per loss scale, widest first (one solve without a loss).
  ceres::Solver::Summary summary;
  SensorFitSummary& fit = result->accel_fit;
  fit.iterations = 0;
  for (auto it = scales.rbegin(); it != scales.rend(); ++it) {
    if (loss) loss->Reset(internal::MakeLoss(options.loss, *it), ceres::TAKE_OWNERSHIP);
    ceres::Solve(SolverOptions(options), &problem, &summary);
    fit.iterations += static_cast<int>(summary.iterations.size()) - 1;
    if (!summary.IsSolutionUsable()) break;
  }
  fit.fitted = true;
  fit.information =
      trend_rows > 0 ? "position magnitudes + within-pose trends" : "position magnitudes";
  if (rotations) fit.information += " + rotations between poses";
  if (loss) fit.information += std::string(" (") + ToString(options.loss) + " loss)";
  fit.converged = summary.IsSolutionUsable() && summary.termination_type == ceres::CONVERGENCE;
  if (!summary.IsSolutionUsable()) {
    result->message = "accelerometer effect fit failed: " + summary.message;
    return false;
  }

  const std::vector<int> upper_free =
      SetAccelParameterNames(free_off_diagonal, on, rotations, &fit);
  const int np = static_cast<int>(fit.parameter_names.size());
  Eigen::MatrixXd jacobian(num_rows, np);
  Eigen::VectorXd residual_rows(num_rows);
  result->accel_trend_residuals.assign(observations.size(), Eigen::Vector3d::Zero());
  if (!EvaluateAccelFit(residuals, params, upper_free, on, rotations, options.compute_covariance,
                        &jacobian, &residual_rows, &fit, &result->accel_trend_residuals,
                        &result->rotation_residuals)) {
    result->message = "accelerometer effect fit: the model has no value at a position";
    return false;
  }
  if (loss && options.compute_covariance) {
    WeightRowsByLoss(residuals, options, &jacobian, &residual_rows);
  }
  fit.num_residuals = num_rows;
  fit.trend_residuals = trend_rows;
  fit.rotation_residuals = rotation_rows_count;
  fit.num_parameters = np;
  if (rotations) {
    // Turns that miss far beyond their noise: something the rotation rows
    // do not model (a gyroscope g-sensitivity, a turn cut short).
    const int rotation_dof = rotation_rows_count - kRotationGyroColumns;
    if (rotation_dof > 0 && ChiSquareUpperTail(fit.rotation_chi2, rotation_dof) < 1e-3) {
      std::ostringstream w;
      w.precision(3);
      w << kRotationsExceedNoise << " (chi2 " << fit.rotation_chi2 << " on about " << rotation_dof
        << " dof): something the turns do not model, such as a gyroscope g-sensitivity";
      result->warnings.push_back(w.str());
    }
    const Eigen::Matrix3d m =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(rotation_rows.gyro_matrix);
    result->rotation_gyro_matrix = rotation_rows.scale * m;
    result->rotation_gyro_bias =
        rotation_rows.center + Eigen::Vector3d(rotation_rows.gyro_bias) / rotation_rows.scale;
    result->rotation_poses = rotation_rows.poses;
  }

  AccelModel fitted_n = start_n;
  fitted_n.bias = Eigen::Vector3d(bias[0], bias[1], bias[2]);
  fitted_n.SetUpper(upper);
  result->accel = norm.Undo(fitted_n);
  if (options.parameterization == AccelParameterization::kScale && free_off_diagonal) {
    result->accel.parameterization = AccelParameterization::kScaleMisalignment;
  }
  result->parameters.accel_quadratic = Eigen::Vector3d(blocks[0]);
  result->parameters.accel_temperature_bias = Eigen::Vector3d(blocks[1]);
  result->parameters.accel_temperature_scale = Eigen::Vector3d(blocks[2]);
  result->parameters.accel_bias_drift = Eigen::Vector3d(blocks[3]);

  FinishAccel(observations, gravity, norm.scale, jacobian, upper_free, options.compute_covariance,
              rotations ? &rotation_rows : nullptr, result);
  *whitened_jacobian = std::move(jacobian);
  *whitened_residuals = std::move(residual_rows);
  return true;
}

// REML of one extra variance of the magnitudes (magnitude_variance_component)
// from a finished fit and its whitened Jacobian (magnitude rows first). The
// magnitude rows enter unwhitened (m/s^2, sigma_k), the trend rows whitened
// (sigma 1): s^2, of the order of sigma_k^2 (1e-7 (m/s^2)^2), is then
// immaterial beside the trend rows' unit variance, so it is the magnitudes'
// excess alone. False when the magnitudes leave no degree of freedom.
bool MagnitudeVariance(const EffectFitResult& fit, const Eigen::MatrixXd& whitened_jacobian,
                       const Eigen::VectorXd& whitened_residuals, const EffectFitOptions& options,
                       VarianceComponent* component) {
  const int n = static_cast<int>(fit.accel_sigmas.size());
  const int rows = static_cast<int>(whitened_jacobian.rows());
  // Residual directions of the magnitudes: n minus what the parameters
  // take from them beyond what the trends already determine.
  const std::vector<std::string>& names = fit.accel_fit.parameter_names;
  const int trend_rank =
      rows > n
          ? AnalyzeObservability(whitened_jacobian.bottomRows(rows - n), names, kRankTolerance).rank
          : 0;
  const int magnitude_dof = n - (fit.accel_fit.rank - trend_rank);
  if (magnitude_dof < 1 && !(options.magnitude_variance_prior_dof > 0.0)) {
    component->message =
        "the position magnitudes leave no residual degree of freedom: their extra variance is "
        "not estimated (give a prior)";
    return false;
  }
  internal::VariancePrior prior;
  prior.variance = options.magnitude_variance_prior * options.magnitude_variance_prior;
  prior.dof = options.magnitude_variance_prior_dof;
  Eigen::VectorXd r = whitened_residuals;
  Eigen::VectorXd sigmas = Eigen::VectorXd::Ones(r.size());
  Eigen::MatrixXd jacobian = whitened_jacobian;
  for (int k = 0; k < n; ++k) {
    r(k) *= fit.accel_sigmas[k];
    sigmas(k) = fit.accel_sigmas[k];
    jacobian.row(k) *= fit.accel_sigmas[k];
  }
  return internal::EstimateVarianceComponent(r, sigmas, jacobian, component, prior);
}

// Per position, L_k^-1 of the covariance of the mean reading; false with
// the message when one is not finite.
bool GyroWhitening(const std::vector<StaticObservation>& observations,
                   std::vector<Eigen::Matrix3d>* whitening, EffectFitResult* result) {
  whitening->resize(observations.size());
  for (size_t k = 0; k < observations.size(); ++k) {
    (*whitening)[k] = Whitening(observations[k].gyro_mean_cov);
    if (!(*whitening)[k].allFinite()) {
      std::ostringstream msg;
      msg << "position " << k << " has no usable gyroscope noise estimate";
      result->message = msg.str();
      return false;
    }
  }
  return true;
}

// fit->chi2 and, with `covariance`, the dense Jacobian (3 rows per
// position) of b_g and the blocks that are on (G, gamma, eta).
void EvaluateGyroFit(const std::vector<std::unique_ptr<ceres::CostFunction>>& owned,
                     const double* const params[4], const bool on[3], bool covariance,
                     Eigen::MatrixXd* jacobian, SensorFitSummary* fit) {
  fit->chi2 = 0.0;
  for (int k = 0; k < static_cast<int>(owned.size()); ++k) {
    double r[3];
    double jb[9], jg[27], jt[9], jd[9];
    double* jacobians[4] = {jb, jg, jt, jd};
    owned[k]->Evaluate(params, r, covariance ? jacobians : nullptr);
    for (int row = 0; row < 3; ++row) {
      fit->chi2 += r[row] * r[row];
      if (!covariance) continue;
      int col = 0;
      for (int i = 0; i < 3; ++i) (*jacobian)(3 * k + row, col++) = jb[3 * row + i];
      if (on[0]) {
        for (int i = 0; i < 9; ++i) (*jacobian)(3 * k + row, col++) = jg[9 * row + i];
      }
      if (on[1]) {
        for (int i = 0; i < 3; ++i) (*jacobian)(3 * k + row, col++) = jt[3 * row + i];
      }
      if (on[2]) {
        for (int i = 0; i < 3; ++i) (*jacobian)(3 * k + row, col++) = jd[3 * row + i];
      }
    }
  }
}

bool FitGyro(const std::vector<StaticObservation>& observations, const GyroModel& initial_gyro,
             const EffectParameters& initial_parameters, const EffectFitOptions& options,
             EffectFitResult* result) {
  const std::vector<Effect>& effects = options.effects;
  const int n = static_cast<int>(observations.size());
  std::vector<Eigen::Matrix3d> whitening;
  if (!GyroWhitening(observations, &whitening, result)) return false;
  double bias[3] = {initial_gyro.bias(0), initial_gyro.bias(1), initial_gyro.bias(2)};
  double g[9];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) g[3 * r + c] = initial_parameters.gyro_g_sensitivity(r, c);
  }
  double temperature_bias[3], drift[3];
  for (int i = 0; i < 3; ++i) {
    temperature_bias[i] = initial_parameters.gyro_temperature_bias(i);
    drift[i] = initial_parameters.gyro_bias_drift(i);
  }
  const bool on_g = Contains(effects, Effect::kGyroGSensitivity);
  const bool on_t = Contains(effects, Effect::kGyroTemperatureBias);
  const bool on_d = Contains(effects, Effect::kGyroBiasDrift);
  if (!on_g) std::fill(g, g + 9, 0.0);
  if (!on_t) std::fill(temperature_bias, temperature_bias + 3, 0.0);
  if (!on_d) std::fill(drift, drift + 3, 0.0);

  ceres::Problem::Options keep;
  keep.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(keep);
  std::vector<std::unique_ptr<ceres::CostFunction>> owned;
  for (int k = 0; k < n; ++k) {
    const StaticObservation& o = observations[k];
    owned.emplace_back(GyroStaticResidual::CreateWithEffects(
        o.gyro_mean, whitening[k], result->forces[k],
        TemperatureOffset(initial_parameters, o.temperature()),
        o.time() - initial_parameters.reference_time));
    problem.AddResidualBlock(owned.back().get(), nullptr, bias, g, temperature_bias, drift);
  }
  if (!on_g) problem.SetParameterBlockConstant(g);
  if (!on_t) problem.SetParameterBlockConstant(temperature_bias);
  if (!on_d) problem.SetParameterBlockConstant(drift);
  ceres::Solver::Summary summary;
  ceres::Solve(SolverOptions(options), &problem, &summary);
  SensorFitSummary& fit = result->gyro_fit;
  fit.fitted = true;
  fit.information = "static mean rates";
  fit.iterations = static_cast<int>(summary.iterations.size()) - 1;
  fit.converged = summary.IsSolutionUsable() && summary.termination_type == ceres::CONVERGENCE;
  if (!summary.IsSolutionUsable()) {
    result->message = "gyroscope effect fit failed: " + summary.message;
    return false;
  }
  fit.parameter_names = {"gyro_bias_x", "gyro_bias_y", "gyro_bias_z"};
  const Effect kGyroEffects[3] = {Effect::kGyroGSensitivity, Effect::kGyroTemperatureBias,
                                  Effect::kGyroBiasDrift};
  const bool on[3] = {on_g, on_t, on_d};
  for (int b = 0; b < 3; ++b) {
    if (!on[b]) continue;
    for (const std::string& name : Info(kGyroEffects[b]).parameter_names) {
      fit.parameter_names.push_back(name);
    }
  }
  const int np = static_cast<int>(fit.parameter_names.size());
  Eigen::MatrixXd jacobian(3 * n, np);
  const double* params[4] = {bias, g, temperature_bias, drift};
  EvaluateGyroFit(owned, params, on, options.compute_covariance, &jacobian, &fit);
  fit.num_residuals = 3 * n;
  fit.num_parameters = np;
  result->gyro.bias = Eigen::Vector3d(bias[0], bias[1], bias[2]);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) result->parameters.gyro_g_sensitivity(r, c) = g[3 * r + c];
  }
  result->parameters.gyro_temperature_bias = Eigen::Vector3d(temperature_bias);
  result->parameters.gyro_bias_drift = Eigen::Vector3d(drift);
  if (options.compute_covariance) {
    CovarianceFromJacobian(jacobian, 3, 3 * n, &fit);
    for (int i = 0; i < 3; ++i) result->gyro_bias_std(i) = fit.Std(fit.parameter_names[i]);
  }
  result->gyro_residuals.resize(n);
  result->gyro_sigmas.resize(n);
  for (int k = 0; k < n; ++k) {
    double w2 = 0.0;
    result->gyro_residuals[k] = GyroResidual(*result, observations[k], result->forces[k], &w2);
    result->gyro_sigmas[k] = observations[k].gyro_mean_cov.diagonal().cwiseSqrt();
  }
  return true;
}

void FillEstimates(EffectFitResult* result) {
  result->estimates.clear();
  for (Effect e : result->effects) {
    const EffectInfo& info = Info(e);
    EffectEstimate est;
    est.effect = e;
    est.names = info.parameter_names;
    est.unit = info.unit;
    const SensorFitSummary& fit =
        info.sensor == EffectSensor::kAccelerometer ? result->accel_fit : result->gyro_fit;
    if (e == Effect::kAccelMisalignment) {
      const Eigen::Matrix3d& u = result->accel.upper;
      est.values = {u(0, 1), u(0, 2), u(1, 2)};
    } else {
      est.values = result->parameters.Values(e);
    }
    for (const std::string& name : est.names) est.std.push_back(fit.Std(name));
    result->estimates.push_back(est);
  }
}

}  // namespace

double SensorFitSummary::Std(const std::string& name) const {
  const auto it = std::find(parameter_names.begin(), parameter_names.end(), name);
  if (it == parameter_names.end() || covariance.size() == 0) return NAN;
  const int i = static_cast<int>(it - parameter_names.begin());
  const double v = covariance(i, i);
  return v >= 0.0 ? std::sqrt(v) : NAN;
}

std::vector<StaticObservation> ObservationsFromIntervals(
    const std::vector<StaticInterval>& intervals, bool has_gyro) {
  const std::vector<Position> positions = PositionsFromIntervals(intervals);
  std::vector<StaticObservation> out(positions.size());
  for (size_t k = 0; k < positions.size(); ++k) {
    out[k].accel = positions[k];
    out[k].has_gyro = has_gyro;
    if (!has_gyro) continue;
    const StaticInterval& s = intervals[k];
    out[k].gyro_mean = s.gyro_mean;
    const double count = static_cast<double>(std::max<size_t>(1, s.count()));
    Eigen::Matrix3d cov = s.gyro_cov / count;
    // A constant (quantised) gyroscope: its mean is known to the rounding,
    // a twelfth of a step squared; the step is a count when the means are
    // integers, else about a millionth of the largest mean.
    const bool integers = (s.gyro_mean.array() == s.gyro_mean.array().round()).all();
    const double step = integers ? 1.0 : 1e-6 * std::max(1.0, s.gyro_mean.cwiseAbs().maxCoeff());
    for (int a = 0; a < 3; ++a) {
      if (!(cov(a, a) > 0.0)) cov(a, a) = step * step / 12.0 / count;
    }
    out[k].gyro_mean_cov = cov;
  }
  return out;
}

bool WithinPoseTrendOptions::IsValid(std::string* error) const {
  if (batches < 4) {
    *error = "within-pose trends: batches must be at least 4";
    return false;
  }
  if (min_batch_samples < 1) {
    *error = "within-pose trends: min_batch_samples must be at least 1";
    return false;
  }
  if (!(min_seconds > 0.0)) {
    *error = "within-pose trends: min_seconds must be positive";
    return false;
  }
  return true;
}

std::vector<StaticObservation> ObservationsFromIntervals(
    const ImuLog& log, const std::vector<StaticInterval>& intervals,
    const WithinPoseTrendOptions& options) {
  std::string error;
  if (!options.IsValid(&error)) return {};
  std::vector<StaticObservation> out = ObservationsFromIntervals(intervals, log.has_gyro());
  const std::vector<internal::PoseTrend> trends =
      internal::WithinPoseTrends(log, intervals, options.batches, options.min_batch_samples,
                                 options.min_seconds, options.along_gravity_only);
  for (size_t k = 0; k < out.size(); ++k) {
    if (!trends[k].valid) continue;
    out[k].has_trend = true;
    out[k].accel_slope = trends[k].accel_slope;
    out[k].accel_slope_cov = trends[k].accel_slope_cov;
    out[k].temperature_slope = trends[k].temperature_slope;
    out[k].trend_along_gravity = options.along_gravity_only;
  }
  return out;
}

WithinPoseTrendOptions GravityTrendOptions(double min_seconds) {
  WithinPoseTrendOptions o;
  o.batches = 5;
  o.along_gravity_only = true;
  o.min_seconds = min_seconds;
  return o;
}

bool EffectFitOptions::IsValid(std::string* error) const {
  if (!(magnitude_variance_prior >= 0.0) || !(magnitude_variance_prior_dof >= 0.0) ||
      !(magnitude_extra_variance >= 0.0) || !std::isfinite(magnitude_extra_variance) ||
      !(rotation_gyro_bias_variance >= 0.0) || !std::isfinite(rotation_gyro_bias_variance)) {
    *error =
        "effect fit: magnitude_extra_variance, magnitude_variance_prior and its dof and "
        "rotation_gyro_bias_variance must be >= 0";
    return false;
  }
  if (!(loss_scale > 0.0) || !std::isfinite(loss_scale)) {
    *error = "effect fit: loss_scale must be positive";
    return false;
  }
  std::string solver_error;
  if (!solver.IsValid(&solver_error)) {
    *error = "effect fit: " + solver_error;
    return false;
  }
  return true;
}

bool FitEffects(const std::vector<StaticObservation>& observations, const AccelModel& initial,
                const GyroModel& initial_gyro, const EffectParameters& initial_parameters,
                double gravity, const EffectFitOptions& options, EffectFitResult* result) {
  *result = EffectFitResult();
  std::string error;
  if (!options.IsValid(&error)) {
    result->message = error;
    return false;
  }
  if (!(gravity > 0.0)) {
    result->message = "gravity must be positive";
    return false;
  }
  result->effects = options.effects;
  result->accel = initial;
  result->gyro = initial_gyro;
  result->parameters = initial_parameters;
  const int n = static_cast<int>(observations.size());
  if (options.fit_accel) {
    int needed = options.parameterization == AccelParameterization::kScale ? 6 : 9;
    for (Effect e : options.effects) {
      if (IsAccelEffect(e) && !(e == Effect::kAccelMisalignment &&
                                options.parameterization != AccelParameterization::kScale)) {
        needed += Info(e).num_parameters;
      }
    }
    int trends = 0, trend_rows = 0;
    if (options.use_within_pose_trends) {
      for (const StaticObservation& o : observations) {
        if (!o.has_trend) continue;
        ++trends;
        trend_rows += o.trend_along_gravity ? 1 : 3;
      }
    }
    int rotation_extra = 0;
    if (options.use_between_pose_rotations) {
      const int turns = static_cast<int>(internal::TurnPairs(observations).size());
      if (turns >= internal::kMinRotations) rotation_extra = 2 * turns - kRotationGyroColumns;
    }
    if (n + trend_rows + rotation_extra < needed) {
      std::ostringstream s;
      s << "the accelerometer model with " << needed << " parameters needs at least " << needed
        << " static positions, found " << n;
      if (trends > 0) s << " (and " << trends << " within-pose trends)";
      if (rotation_extra > 0)
        s << " (and " << rotation_extra / 2 + 6 << " rotations between poses)";
      result->message = s.str();
      return false;
    }
    Eigen::MatrixXd jacobian;
    Eigen::VectorXd residuals;
    if (!FitAccel(observations, initial, initial_parameters, gravity, options,
                  options.magnitude_extra_variance, &jacobian, &residuals, result)) {
      return false;
    }
    if (options.magnitude_variance_component && options.compute_covariance) {
      VarianceComponent component;
      if (MagnitudeVariance(*result, jacobian, residuals, options, &component) &&
          component.variance > 0.0) {
        double mean_white = 0.0;
        for (double sigma : result->accel_sigmas) mean_white += sigma * sigma / n;
        EffectFitResult refit = *result;
        if (!FitAccel(observations, initial, initial_parameters, gravity, options,
                      options.magnitude_extra_variance + component.variance, &jacobian, &residuals,
                      &refit)) {
          *result = refit;
          return false;
        }
        *result = refit;
        component.absorbed = true;
        result->magnitude_variance_inflation =
            internal::StudentInflation(component, mean_white, nullptr);
        result->accel_fit.covariance *= result->magnitude_variance_inflation;
        result->accel_bias_std *= std::sqrt(result->magnitude_variance_inflation);
      }
      result->magnitude_variance = component;
    }
  } else {
    result->accel_residuals.resize(n);
    result->forces.resize(n);
    result->accel_sigmas.resize(n);
    for (int k = 0; k < n; ++k) {
      result->accel_residuals[k] =
          AccelResidual(*result, observations[k], gravity, &result->forces[k]);
      result->accel_sigmas[k] = AccelSigma(*result, observations[k]);
    }
  }
  const bool all_gyro = n > 0 && std::all_of(observations.begin(), observations.end(),
                                             [](const StaticObservation& o) { return o.has_gyro; });
  if (options.fit_gyro && all_gyro) {
    if (!FitGyro(observations, initial_gyro, initial_parameters, options, result)) return false;
  }
  FillEstimates(result);
  std::ostringstream s;
  s << "fitted " << n << " positions";
  if (result->accel_fit.fitted) {
    s << "; accelerometer chi2 " << result->accel_fit.chi2 << " on " << result->accel_fit.dof()
      << " dof";
  }
  if (result->gyro_fit.fitted) {
    s << "; gyroscope chi2 " << result->gyro_fit.chi2 << " on " << result->gyro_fit.dof() << " dof";
  }
  result->message = s.str();
  return true;
}

double AccelResidual(const EffectFitResult& fit, const StaticObservation& observation,
                     double gravity, Eigen::Vector3d* force) {
  const Eigen::Vector3d m = fit.accel.upper * (observation.accel.raw_mean - fit.accel.bias);
  Eigen::Vector3d a;
  if (!CorrectAccel(fit.parameters, fit.effects, m, observation.temperature(), observation.time(),
                    &a)) {
    a = m;
  }
  if (force != nullptr) *force = a;
  return a.norm() - gravity;
}

double AccelSigma(const EffectFitResult& fit, const StaticObservation& observation) {
  return MagnitudeSigmas({observation.accel}, fit.accel)[0];
}

Eigen::Vector3d GyroResidual(const EffectFitResult& fit, const StaticObservation& observation,
                             const Eigen::Vector3d& force, double* whitened_squared) {
  const Eigen::Vector3d e =
      observation.gyro_mean - fit.gyro.bias -
      GyroOffset(fit.parameters, fit.effects, force, observation.temperature(), observation.time());
  if (whitened_squared != nullptr) {
    *whitened_squared = e.dot(observation.gyro_mean_cov.ldlt().solve(e));
  }
  return e;
}

}  // namespace gravcal
