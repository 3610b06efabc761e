// gravcal/residuals/accel_trend_residual.h: the per-pose Ceres residual that
// compares the trend of the raw accelerometer mean within a static pose with
// the trend the effects predict.
//
// Within pose k the sensor is still, so the true specific force s is
// constant and, by the sensor model of model_effects.h, per axis i
//
//   m_i(t) = (1 + c_i dT(t)) q_i + beta_i dT(t) + delta_i dt(t),   q_i = s_i + k2_i s_i^2,
//
// affine in dT and dt (the general form, for every registered effect, is
// AccelEffectRate in core/effect_registry.h: the offsets' rates plus the
// shapes' carried through the slopes of the shapes above them). The
// least-squares slope against time of the raw mean v(t) = b + U^-1 m(t)
// over the pose is therefore exactly
//
//   g_k = U^-1 mdot_k,   mdot_{k,i} = (c_i q_i + beta_i) Tdot_k + delta_i,
//
// with Tdot_k the least-squares slope of the temperature against time over
// the same pose (0 without a temperature column). q is read from the pose's
// mean raw vector v_k at its mean offsets (dT_k, dt_k):
//
//   q_i = ( [U (v_k - b)]_i - beta_i dT_k - delta_i dt_k ) / (1 + c_i dT_k).
//
// The residual (dimensionless, unit variance) is
//
//   r_k = W_k ( ghat_k - U^-1 mdot_k ),
//
// ghat_k the measured slope (raw units per second) and W_k its whitening:
// either W_k = L_k^-1 (3 rows), L_k L_k^T the covariance of the slope, or
// the single row W_k = n_k^T / sqrt(n_k^T L_k L_k^T n_k) with n_k the unit
// direction of the pose's raw mean, which keeps the slope along gravity
// only (a slow tilt of the placement or tremor turns the cross-gravity
// components by g dtheta but the along-gravity one only by g dtheta^2 / 2).
// A term that does not vary within a pose (the quadratic one) drops out, so
// k2 only enters through the magnitude residual; a bias, scale or
// non-orthogonality error alone predicts no trend. Blocks as
// GravityMagnitudeResidual::CreateWithEffects: b (3), U (6: u00 u01 u02 u11
// u12 u22) and the accelerometer effects' block, so both residuals of a pose
// share one parameter list. The slope is uncorrelated with the pose's mean
// (the regression is centred on the mean time), so the two residuals of a
// pose add independently to chi2.
#ifndef GRAVCAL_RESIDUALS_ACCEL_TREND_RESIDUAL_H_
#define GRAVCAL_RESIDUALS_ACCEL_TREND_RESIDUAL_H_

#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>

#include <Eigen/Core>

#include "gravcal/core/imu_model.h"

namespace gravcal {

struct AccelTrendResidual {
  // The whitening's rows: one (along gravity) to three.
  using Whitening = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor, 3, 3>;

  // raw_mean v_k, slope ghat_k (raw units/s), whitening W_k (1 to 3 rows),
  // Tdot_k (degC/s), dT_k = T_k - T_ref (0 when unknown) and
  // dt_k = t_k - t_ref.
  AccelTrendResidual(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& slope,
                     const Whitening& whitening, double temperature_slope,
                     double temperature_offset, double time_offset)
      : raw_mean_(raw_mean),
        slope_(slope),
        whitening_(whitening),
        temperature_slope_(temperature_slope),
        temperature_offset_(temperature_offset),
        time_offset_(time_offset) {}

  template <typename T>
  bool operator()(const T* const bias, const T* const upper, const T* const effects,
                  T* residual) const {
    const ImuModel<T> model(AccelBlocks<T>(bias, upper, effects));
    T m[3];
    model.SensorFrame(raw_mean_, m);
    T rate[3];
    model.EffectRate(m, temperature_offset_, time_offset_, temperature_slope_, rate);
    // U^-1 mdot.
    T predicted[3];
    model.UpperSolve(rate, predicted);
    T e[3];
    for (int i = 0; i < 3; ++i) e[i] = T(slope_(i)) - predicted[i];
    for (int r = 0; r < whitening_.rows(); ++r) {
      residual[r] =
          T(whitening_(r, 0)) * e[0] + T(whitening_(r, 1)) * e[1] + T(whitening_(r, 2)) * e[2];
    }
    return true;
  }

  // One residual per row of `whitening`.
  static ceres::CostFunction* Create(const Eigen::Vector3d& raw_mean, const Eigen::Vector3d& slope,
                                     const Whitening& whitening, double temperature_slope,
                                     double temperature_offset, double time_offset) {
    return new ceres::AutoDiffCostFunction<AccelTrendResidual, ceres::DYNAMIC, 3, 6,
                                           kAccelEffectParameters>(
        new AccelTrendResidual(raw_mean, slope, whitening, temperature_slope, temperature_offset,
                               time_offset),
        static_cast<int>(whitening.rows()));
  }

 private:
  const Eigen::Vector3d raw_mean_;
  const Eigen::Vector3d slope_;
  const Whitening whitening_;
  const double temperature_slope_;
  const double temperature_offset_;
  const double time_offset_;
};

}  // namespace gravcal

#endif  // GRAVCAL_RESIDUALS_ACCEL_TREND_RESIDUAL_H_
