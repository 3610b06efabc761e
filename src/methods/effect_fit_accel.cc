// The accelerometer part of the effect fit (effect_fit.h): the magnitude,
// within-pose trend and between-pose rotation residuals of every pose, solved
// with a graduated robust loss, and their whitened Jacobian at the optimum.
#include <ceres/ceres.h>
#include <ceres/manifold.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "estimation/normalization.h"
#include "estimation/robust_loss.h"
#include "gravcal/estimation/refinement.h"
#include "gravcal/methods/effect_fit.h"
#include "gravcal/residuals/accel_rotation_residual.h"
#include "gravcal/residuals/accel_trend_residual.h"
#include "gravcal/residuals/gravity_magnitude_residual.h"
#include "methods/between_pose_rotations.h"
#include "methods/effect_fit_parts.h"
#include "util/statistics.h"

namespace gravcal {
namespace internal {
namespace {

// Indices into the 6-vector of U, row-major upper triangle.
constexpr int kOffDiagonal[3] = {1, 2, 4};

// The whitening of a pose's trend residual (accel_trend_residual.h), raw
// units: L^-1 of the slope's covariance, or with trend_along_gravity the
// one row n^T / sqrt(n^T cov n), n the direction of `centered_mean` (the
// pose's mean raw vector less the bias).
AccelTrendResidual::Whitening TrendWhitening(const StaticObservation& o,
                                             const Eigen::Vector3d& centered_mean) {
  if (!o.trend_along_gravity) return InverseCholesky(o.accel_slope_cov);
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

// The accelerometer effects stored in the effects' block, in block order
// (the registry's, core/effect_registry.h).
std::vector<Effect> AccelBlockEffects() {
  std::vector<Effect> out;
  for (const EffectInfo& info : EffectCatalogue()) {
    if (info.form == EffectForm::kAccelOffset || info.form == EffectForm::kAccelShape) {
      out.push_back(info.effect);
    }
  }
  return out;
}

// fit->parameter_names (the columns of the dense Jacobian); returns the
// indices of the free entries of U.
std::vector<int> SetAccelParameterNames(bool free_off_diagonal, const std::vector<int>& effect_free,
                                        bool rotations, SensorFitSummary* fit) {
  static const char* kUpperNames[6] = {"u_xx", "u_xy", "u_xz", "u_yy", "u_yz", "u_zz"};
  fit->parameter_names = {"bias_x", "bias_y", "bias_z"};
  std::vector<int> upper_free;
  for (int i = 0; i < 6; ++i) {
    const bool off = i == 1 || i == 2 || i == 4;
    if (off && !free_off_diagonal) continue;
    upper_free.push_back(i);
    fit->parameter_names.push_back(kUpperNames[i]);
  }
  for (Effect e : AccelBlockEffects()) {
    const int offset = effects::kLayout.offset[static_cast<int>(e)];
    if (std::find(effect_free.begin(), effect_free.end(), offset) == effect_free.end()) continue;
    for (const std::string& n : Info(e).parameter_names) fit->parameter_names.push_back(n);
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
// params holds the three accelerometer blocks (b', U', the effects) and,
// with rotations, b_g' and M_g' (their columns last); upper_free and
// effect_free are the free entries of U' and of the effects' block.
bool EvaluateAccelFit(const std::vector<AccelBlock>& blocks, const double* const params[5],
                      const std::vector<int>& upper_free, const std::vector<int>& effect_free,
                      bool rotations, bool covariance, Eigen::MatrixXd* jacobian,
                      Eigen::VectorXd* residuals, SensorFitSummary* fit,
                      std::vector<Eigen::Vector3d>* trend_residuals,
                      std::vector<Eigen::Vector2d>* rotation_residuals) {
  fit->chi2 = 0.0;
  fit->trend_chi2 = 0.0;
  fit->rotation_chi2 = 0.0;
  rotation_residuals->clear();
  int row0 = 0;
  for (const AccelBlock& block : blocks) {
    double r[3];
    double jb[9], ju[18], je[3 * kAccelEffectParameters], jgb[9], jgm[27];
    double* jacobians[5] = {jb, ju, je, jgb, jgm};
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
      for (int i : effect_free) {
        (*jacobian)(row0 + row, col++) = je[kAccelEffectParameters * row + i];
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
std::vector<AccelBlock> AccelResidualBlocks(const std::vector<StaticObservation>& observations,
                                            const std::vector<Position>& normalized, double scale,
                                            const EffectParameters& initial_parameters,
                                            double gravity, const std::vector<double>& sigmas,
                                            bool trends) {
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
double LargestBlockNorm(const std::vector<AccelBlock>& blocks, const double* const params[5]) {
  double largest = 0.0;
  for (const AccelBlock& b : blocks) {
    double r[3];
    if (!b.cost->Evaluate(params, r, nullptr)) continue;
    largest = std::max(largest, Eigen::Map<const Eigen::VectorXd>(r, b.rows).norm());
  }
  return largest;
}

}  // namespace

bool FitAccel(const std::vector<StaticObservation>& observations, const AccelModel& initial,
              const EffectParameters& initial_parameters, double gravity,
              const EffectFitOptions& options, double extra_variance,
              Eigen::MatrixXd* whitened_jacobian, Eigen::VectorXd* whitened_residuals,
              EffectFitResult* result) {
  const std::vector<Effect>& effects = options.effects;
  const bool free_off_diagonal = options.parameterization != AccelParameterization::kScale ||
                                 std::any_of(effects.begin(), effects.end(), [](Effect e) {
                                   return Info(e).form == EffectForm::kInUpper;
                                 });
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
  // The effects' block: the effects switched on from their initial values,
  // the others held at zero (effect_free: the entries that are fitted).
  double effect_block[kAccelEffectParameters] = {};
  std::vector<int> effect_free, effect_held;
  for (Effect e : AccelBlockEffects()) {
    const int offset = effects::kLayout.offset[static_cast<int>(e)];
    const bool on = Contains(effects, e);
    const double* initial_values = initial_parameters.Block(e);
    for (int i = 0; i < Info(e).num_parameters; ++i) {
      effect_block[offset + i] = on ? initial_values[i] : 0.0;
      (on ? effect_free : effect_held).push_back(offset + i);
    }
  }

  std::vector<AccelBlock> residuals =
      AccelResidualBlocks(observations, normalized, norm.scale, initial_parameters, gravity,
                          result->accel_sigmas, options.use_within_pose_trends);
  std::vector<double*> parameter_blocks = {bias, upper, effect_block};
  // The rotations between poses, with the gyroscope's blocks.
  internal::RotationRows rotation_rows;
  bool rotations = false;
  if (options.use_between_pose_rotations) {
    const internal::AccelBlocks held = {{bias, upper, effect_block}};
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
  const double* params[5] = {bias, upper, effect_block, rotation_rows.gyro_bias,
                             rotation_rows.gyro_matrix};
  const std::vector<double> scales = internal::GraduatedLossScales(
      options.loss, options.loss_scale,
      options.loss == LossType::kNone ? 0.0 : LargestBlockNorm(residuals, params));
  ceres::Problem problem(internal::ProblemKeepingOwnership());
  std::unique_ptr<ceres::LossFunctionWrapper> loss =
      internal::GraduatedLoss(options, scales.back());
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
  SensorFitSummary& fit = result->accel_fit;
  const ceres::Solver::Summary summary =
      SolveGraduated(options, scales, effect_block, kAccelEffectParameters, effect_free,
                     effect_held, loss.get(), &problem, &fit);
  fit.fitted = true;
  fit.information =
      trend_rows > 0 ? "position magnitudes + within-pose trends" : "position magnitudes";
  if (rotations) fit.information += " + rotations between poses";
  if (loss) fit.information += std::string(" (") + ToString(options.loss) + " loss)";
  if (!summary.IsSolutionUsable()) {
    result->message = "accelerometer effect fit failed: " + summary.message;
    return false;
  }

  const std::vector<int> upper_free =
      SetAccelParameterNames(free_off_diagonal, effect_free, rotations, &fit);
  const int np = static_cast<int>(fit.parameter_names.size());
  Eigen::MatrixXd jacobian(num_rows, np);
  Eigen::VectorXd residual_rows(num_rows);
  result->accel_trend_residuals.assign(observations.size(), Eigen::Vector3d::Zero());
  if (!EvaluateAccelFit(residuals, params, upper_free, effect_free, rotations,
                        options.compute_covariance, &jacobian, &residual_rows, &fit,
                        &result->accel_trend_residuals, &result->rotation_residuals)) {
    result->message = "accelerometer effect fit: the model has no value at a position";
    return false;
  }
  if (loss && options.compute_covariance) {
    std::vector<int> block_rows;
    for (const AccelBlock& b : residuals) block_rows.push_back(b.rows);
    WeightRowsByLoss(block_rows, options, &jacobian, &residual_rows);
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
  std::copy(effect_block, effect_block + kAccelEffectParameters, result->parameters.accel.begin());

  FinishAccel(observations, gravity, norm.scale, jacobian, upper_free, options.compute_covariance,
              rotations ? &rotation_rows : nullptr, result);
  *whitened_jacobian = std::move(jacobian);
  *whitened_residuals = std::move(residual_rows);
  return true;
}

}  // namespace internal
}  // namespace gravcal
