// methods/thermal_residual.h (private): the parameter layout and the
// residual of one window of the thermal fit (thermal_calibration.h).
#ifndef GRAVCAL_METHODS_THERMAL_RESIDUAL_H_
#define GRAVCAL_METHODS_THERMAL_RESIDUAL_H_

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/thermal_model.h"
#include "gravcal/methods/thermal_calibration.h"

namespace gravcal {
namespace internal {

// The orders of the terms and the lag switch: one point of the search.
struct ThermalOrders {
  int accel_bias = 0;
  int accel_scale = 0;
  int accel_misalignment = 0;
  int gyro_bias = 0;
  bool lag = false;
};

// Where each parameter sits in the one flat parameter vector theta:
//   b (3), U (6, accel_model.h order), [b_g (3)], [tau],
//   accel bias (3 x n), accel scale (3 x n), accel misalignment (3 x n),
//   [gyro bias (3 x n)]     (each row-major, thermal_model.h blocks)
struct ThermalLayout {
  ThermalLayout(const ThermalOrders& orders, bool has_gyro);

  ThermalOrders orders;
  bool has_gyro = false;
  int bias = 0, upper = 3, gyro_bias = -1, lag = -1;
  int accel_bias = -1, accel_scale = -1, accel_misalignment = -1, gyro_thermal_bias = -1;
  int size = 0;

  // "accel.bias.x.c0" (base), "accel.bias.y.c2", "accel.upper.u01", "lag.tau", ...
  std::vector<std::string> names;
  // Priority group of each parameter (lower = kept first; see the header).
  std::vector<int> group;
  // The thermal term (sensor, quantity, component, power) of a parameter,
  // power 0 for base parameters; quantity kBias with component 3 for tau.
  struct Slot {
    bool thermal = false;
    ThermalSensor sensor = ThermalSensor::kAccel;
    ThermalQuantity quantity = ThermalQuantity::kBias;
    int component = 0;
    int power = 0;
  };
  std::vector<Slot> slots;
};

// The sensing element's temperature T_e, a first-order lag of the recorded
// temperature T_s (tau dT_e/dt = T_s - T_e, T_e = T_s at the log's start),
// on a grid of step h: s_i the mean of T_s over bin i, T_s linear between
// grid points, for which
//
//   e_i = s_i - tau m_i + (e_{i-1} - s_{i-1} + tau m_i) a,
//   a = exp(-h / tau),  m_i = (s_i - s_{i-1}) / h
//
// is exact (tau = 0: e_i = s_i), with d e_i / d tau carried alongside.
class ThermalElementSeries {
 public:
  ThermalElementSeries(const ImuLog& log, double step);
  // The change tau makes to the mean element temperature over [t_begin,
  // t_end]: mean(e(tau)) - mean(e(0)), and its derivative in tau (tau >= 0).
  void WindowShift(double tau, double t_begin, double t_end, double* shift,
                   double* derivative) const;

 private:
  void Update(double tau) const;
  double t0_ = 0.0;
  double h_ = 1.0;
  std::vector<double> s_;
  // The last tau's series (the fit is single-threaded).
  mutable double tau_ = NAN;
  mutable std::vector<double> e_, de_;
};

// The value of a Ceres Jet (or of a double).
inline double ThermalScalar(double v) { return v; }
template <typename T, int N>
double ThermalScalar(const ceres::Jet<T, N>& v) {
  return v.a;
}

// The residual of one window (the equations in thermal_calibration.h):
// 1 accelerometer residual, then 3 gyroscope residuals when the layout has
// a gyroscope.
class ThermalWindowResidual {
 public:
  ThermalWindowResidual(const ThermalLayout& layout, const ThermalWindow& window,
                        const ThermalElementSeries* element, double reference_temperature,
                        double gravity, double accel_sigma)
      : layout_(layout),
        window_(window),
        element_(element),
        reference_temperature_(reference_temperature),
        gravity_(gravity),
        accel_sigma_(accel_sigma) {}

  int num_residuals() const { return layout_.has_gyro ? 4 : 1; }

  template <typename T>
  bool operator()(T const* const* parameters, T* residuals) const {
    const T* theta = parameters[0];
    const ThermalOrders& o = layout_.orders;
    // x = T_e - T_ref: the window's mean temperature moved by the lag
    // (exact value and first derivative in tau at tau's current value).
    T x = T(window_.temperature - reference_temperature_);
    if (layout_.lag >= 0 && element_ != nullptr) {
      const double tau = std::max(0.0, ThermalScalar(theta[layout_.lag]));
      double shift = 0.0, derivative = 0.0;
      element_->WindowShift(tau, window_.t_begin, window_.t_end, &shift, &derivative);
      x += T(shift) + T(derivative) * (theta[layout_.lag] - T(tau));
    }
    ThermalBlocks<T> accel;
    accel.sensor = ThermalSensor::kAccel;
    if (o.accel_bias > 0) accel.bias = theta + layout_.accel_bias;
    accel.bias_order = o.accel_bias;
    if (o.accel_scale > 0) accel.scale = theta + layout_.accel_scale;
    accel.scale_order = o.accel_scale;
    if (o.accel_misalignment > 0) accel.misalignment = theta + layout_.accel_misalignment;
    accel.misalignment_order = o.accel_misalignment;
    // s = (I + D(x))^-1 U (v - b - db(x)).
    T db[3];
    accel.BiasChange(x, db);
    const T* b = theta + layout_.bias;
    const T* u = theta + layout_.upper;
    T d[3];
    for (int i = 0; i < 3; ++i) d[i] = T(window_.accel_mean(i)) - b[i] - db[i];
    T s[3] = {u[0] * d[0] + u[1] * d[1] + u[2] * d[2], u[3] * d[1] + u[4] * d[2], u[5] * d[2]};
    accel.RemoveScale(x, s);
    using std::sqrt;
    residuals[0] = (sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) - T(gravity_)) / T(accel_sigma_);
    if (!layout_.has_gyro) return true;
    // e_g = (u - b_g - db_g(x)) / sigma.
    ThermalBlocks<T> gyro;
    gyro.sensor = ThermalSensor::kGyro;
    if (o.gyro_bias > 0) gyro.bias = theta + layout_.gyro_thermal_bias;
    gyro.bias_order = o.gyro_bias;
    gyro.BiasChange(x, db);
    for (int i = 0; i < 3; ++i) {
      residuals[1 + i] = (T(window_.gyro_mean(i)) - theta[layout_.gyro_bias + i] - db[i]) /
                         T(std::sqrt(window_.gyro_mean_var(i)));
    }
    return true;
  }

  // The cost function over theta (one block of layout.size).
  static ceres::CostFunction* Create(const ThermalLayout& layout, const ThermalWindow& window,
                                     const ThermalElementSeries* element,
                                     double reference_temperature, double gravity,
                                     double accel_sigma) {
    auto* f =
        new ceres::DynamicAutoDiffCostFunction<ThermalWindowResidual, 8>(new ThermalWindowResidual(
            layout, window, element, reference_temperature, gravity, accel_sigma));
    f->AddParameterBlock(layout.size);
    f->SetNumResiduals(layout.has_gyro ? 4 : 1);
    return f;
  }

 private:
  const ThermalLayout layout_;
  const ThermalWindow window_;
  const ThermalElementSeries* element_;
  const double reference_temperature_;
  const double gravity_;
  const double accel_sigma_;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_METHODS_THERMAL_RESIDUAL_H_
