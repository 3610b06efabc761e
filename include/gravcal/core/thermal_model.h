// gravcal/core/thermal_model.h: bias, scale and misalignment of each sensor
// as polynomials in the temperature (issue 35), beside the linear
// temperature effects of the effect catalogue (model_effects.h).
//
// Temperature. T_s is the temperature the log records (degrees C). The
// sensing element may lag it; with the optional first-order lag time
// constant tau (s, >= 0) the model uses the element's temperature T_e,
// tau dT_e/dt = T_s - T_e (T_e = T_s at the log's start), written
//
//   T_e = T_s - tau r,   r = dT_e/dt
//
// so the `rate` below is the element's rate, which a filter along the log
// gives (ThermalElementRate, thermal_rate.h; for a steady ramp, once the
// transient has died away, it equals dT_s/dt). tau = 0: no lag. T_e is then
// clamped to the valid range [T_min, T_max] the calibration covered, as
// PX4's temperature compensation clamps, and enters every polynomial as
//
//   x = clamp(T_e, T_min, T_max) - T_ref.
//
// Polynomials. Each term (bias, scale, misalignment of one sensor) has one
// order n >= 0 (0 = no temperature dependence) and, per component i, the
// coefficients c_i1 .. c_in of
//
//   p_i(x) = c_i1 x + c_i2 x^2 + ... + c_in x^n      (Horner form below)
//
// The value at T_ref (the constant c_i0) is the base model's parameter
// (accel_model.h, gyro_model.h): p_i(0) = 0 keeps a calibration without a
// thermal model unchanged.
//
// The sensor model, per sensor, with the base model's b, U (accelerometer)
// or b_g, M_g (gyroscope):
//
//   accelerometer, raw v:   v = b + db(x) + U^-1 (I + D(x)) s
//   gyroscope, raw u:       u = b_g + db_g(x) + M_g^-1 (I + D_g(x)) w
//
// so the correction is
//
//   s = (I + D(x))^-1 U (v - b - db(x))            m/s^2, sensor frame
//   w = (I + D_g(x))^-1 M_g (u - b_g - db_g(x))    rad/s
//
// db: the bias term, raw units (those of b), 3 components x, y, z.
// D = diag(scale term) + the misalignment term off the diagonal, both in
// the calibrated frame: scale is the fractional change of the sensitivity
// (dimensionless; +0.001 = the sensor reads 0.1 % more), misalignment in
// rad. The accelerometer's misalignment is upper triangular like U (3
// components: D01, D02, D12), so I + D is solved by back substitution; the
// gyroscope's is the full off-diagonal (6 components, row-major: D01, D02,
// D10, D12, D20, D21). The effect catalogue's terms (model_effects.h), the
// housing rotation R and the g-sensitivity act after this correction
// (imu_corrector.h gives the whole chain).
//
// Uncertainty. Each component's coefficients [c_i0, c_i1, .., c_in] (c_i0
// the base value at T_ref) have a covariance, from which the band of p
// (or of the whole parameter c_i0 + p_i) at any T follows (Std below).
// A coefficient the session cannot determine is flagged: its value is 0 in
// the correction and it is reported as undetermined (null), never as a
// confident number.
//
// All orders 0 = no thermal model: the correction is the base model's.
#ifndef GRAVCAL_CORE_THERMAL_MODEL_H_
#define GRAVCAL_CORE_THERMAL_MODEL_H_

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace gravcal {

// The largest order any term may have (the PX4 and ArduPilot exports hold
// order 3).
constexpr int kMaxThermalOrder = 5;

// Which quantity a thermal term describes.
enum class ThermalQuantity { kBias, kScale, kMisalignment };
// "bias", "scale", "misalignment".
const char* ToString(ThermalQuantity quantity);
bool FromString(const std::string& name, ThermalQuantity* quantity);
std::string AcceptedNames(ThermalQuantity);

// Which sensor a thermal model belongs to.
enum class ThermalSensor { kAccel, kGyro };
// "accel", "gyro".
const char* ToString(ThermalSensor sensor);
bool FromString(const std::string& name, ThermalSensor* sensor);
std::string AcceptedNames(ThermalSensor);

// The number of components of a term: 3 for bias and scale, 3 for the
// accelerometer's misalignment, 6 for the gyroscope's.
int ThermalComponents(ThermalSensor sensor, ThermalQuantity quantity);
// The components' names: "x", "y", "z" or "xy", "xz", "yz" (accelerometer
// misalignment) or "xy", "xz", "yx", "yz", "zx", "zy" (gyroscope).
std::vector<std::string> ThermalComponentNames(ThermalSensor sensor, ThermalQuantity quantity);
// The unit of the coefficient of x^k: "raw/degC^k", "1/degC^k",
// "rad/degC^k" (k >= 1).
std::string ThermalUnit(ThermalQuantity quantity, int power);

// ---------------------------------------------------------------------------
// The maths, templated on the scalar so that Ceres autodiff residuals and
// the corrector evaluate the same code (as imu_model.h). `coefficients` is
// row-major, components x order: component i's c_i1 .. c_in at
// coefficients[i * order + k - 1]. A null pointer or order 0 is a term that
// is off.

// p_i(x) = x (c_i1 + x (c_i2 + ... + x c_in)) for every component.
template <typename T, typename X>
void EvaluateThermalPolynomial(const T* coefficients, int components, int order, const X& x,
                               T* out) {
  for (int i = 0; i < components; ++i) {
    out[i] = T(0.0);
    if (coefficients == nullptr || order <= 0) continue;
    T sum = coefficients[i * order + order - 1];
    for (int k = order - 1; k >= 1; --k) sum = coefficients[i * order + k - 1] + x * sum;
    out[i] = x * sum;
  }
}

// The blocks of one sensor's thermal terms.
template <typename T>
struct ThermalBlocks {
  ThermalSensor sensor = ThermalSensor::kAccel;
  const T* bias = nullptr;  // 3 x bias_order
  int bias_order = 0;
  const T* scale = nullptr;  // 3 x scale_order
  int scale_order = 0;
  const T* misalignment = nullptr;  // (3 or 6) x misalignment_order
  int misalignment_order = 0;

  // db(x), raw units.
  template <typename X>
  void BiasChange(const X& x, T* db) const {
    EvaluateThermalPolynomial(bias, 3, bias_order, x, db);
  }

  // I + D(x), row-major 3x3.
  template <typename X>
  void ScaleMatrix(const X& x, T* d) const {
    T s[3];
    EvaluateThermalPolynomial(scale, 3, scale_order, x, s);
    for (int k = 0; k < 9; ++k) d[k] = T(0.0);
    for (int i = 0; i < 3; ++i) d[4 * i] = T(1.0) + s[i];
    const int n = ThermalComponents(sensor, ThermalQuantity::kMisalignment);
    T m[6];
    EvaluateThermalPolynomial(misalignment, n, misalignment_order, x, m);
    if (sensor == ThermalSensor::kAccel) {
      d[1] += m[0];  // 01
      d[2] += m[1];  // 02
      d[5] += m[2];  // 12
    } else {
      const int slot[6] = {1, 2, 3, 5, 6, 7};
      for (int k = 0; k < 6; ++k) d[slot[k]] += m[k];
    }
  }

  // y <- (I + D(x))^-1 y, in place (3 values). Back substitution for the
  // accelerometer (I + D upper triangular), Cramer's rule for the gyroscope.
  template <typename X>
  void RemoveScale(const X& x, T* y) const {
    if ((scale == nullptr || scale_order <= 0) &&
        (misalignment == nullptr || misalignment_order <= 0)) {
      return;
    }
    T a[9];
    ScaleMatrix(x, a);
    if (sensor == ThermalSensor::kAccel) {
      y[2] = y[2] / a[8];
      y[1] = (y[1] - a[5] * y[2]) / a[4];
      y[0] = (y[0] - a[1] * y[1] - a[2] * y[2]) / a[0];
      return;
    }
    const T c0 = a[4] * a[8] - a[5] * a[7];
    const T c1 = a[5] * a[6] - a[3] * a[8];
    const T c2 = a[3] * a[7] - a[4] * a[6];
    const T det = a[0] * c0 + a[1] * c1 + a[2] * c2;
    const T r0 =
        (c0 * y[0] + (a[2] * a[7] - a[1] * a[8]) * y[1] + (a[1] * a[5] - a[2] * a[4]) * y[2]);
    const T r1 =
        (c1 * y[0] + (a[0] * a[8] - a[2] * a[6]) * y[1] + (a[2] * a[3] - a[0] * a[5]) * y[2]);
    const T r2 =
        (c2 * y[0] + (a[1] * a[6] - a[0] * a[7]) * y[1] + (a[0] * a[4] - a[1] * a[3]) * y[2]);
    y[0] = r0 / det;
    y[1] = r1 / det;
    y[2] = r2 / det;
  }

  // y <- (I + D(x)) y, in place: the forward direction (simulation).
  template <typename X>
  void ApplyScale(const X& x, T* y) const {
    T a[9];
    ScaleMatrix(x, a);
    const T y0 = y[0], y1 = y[1], y2 = y[2];
    for (int r = 0; r < 3; ++r) y[r] = a[3 * r] * y0 + a[3 * r + 1] * y1 + a[3 * r + 2] * y2;
  }
};

// ---------------------------------------------------------------------------
// The numbers.

// Row-major, so that data() is the block layout above.
using ThermalCoefficients = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// One term of one sensor: the polynomial of every component.
struct ThermalPolynomial {
  // n: 0 = no temperature dependence (the term is off).
  int order = 0;
  // The largest order the fit was allowed (0 when not fitted).
  int max_order = 0;
  // How `order` was chosen: "given" (config), "aicc", "bic", "cv" or ""
  // (not fitted).
  std::string selection;
  // components x order; column k - 1 holds the coefficient of x^k.
  ThermalCoefficients coefficients;
  // components x order; false = the session does not determine this
  // coefficient (its value is 0 and it is reported as null). Empty = all
  // determined.
  Eigen::Matrix<bool, Eigen::Dynamic, Eigen::Dynamic> determined;
  // Per component, the (order + 1) x (order + 1) covariance of
  // [c_i0, c_i1, .., c_in] (c_i0 the base model's value at T_ref). Empty =
  // not computed.
  std::vector<Eigen::MatrixXd> covariance;

  bool active() const { return order > 0 && coefficients.cols() == order; }
  // Sets order and sizes coefficients (zero) and determined (true) for
  // `components`.
  void Resize(int components, int new_order);
  bool Determined(int component, int power) const;
  // p_i(x) for component i (0 outside the term).
  double Value(int component, double x) const;
  // The standard deviation of p_i(x) (include_constant = false) or of
  // c_i0 + p_i(x) (true), from the covariance; NaN when the covariance is
  // missing or a coefficient that matters is undetermined.
  double Std(int component, double x, bool include_constant) const;
};

// One sensor's thermal terms.
struct ThermalSensorModel {
  ThermalPolynomial bias;
  ThermalPolynomial scale;
  ThermalPolynomial misalignment;

  bool active() const { return bias.active() || scale.active() || misalignment.active(); }
  const ThermalPolynomial& Term(ThermalQuantity q) const;
  ThermalPolynomial* MutableTerm(ThermalQuantity q);
};

// The whole thermal model of a calibration (Calibration::thermal, calibration
// JSON key "thermal"; docs/data_contract.md).
struct ThermalModel {
  // T_ref, degrees C.
  double reference_temperature = 25.0;
  // The valid range [T_min, T_max], degrees C: the temperatures the
  // calibration covered.
  double min_temperature = NAN;
  double max_temperature = NAN;
  // tau, s (0 = no lag term), its standard deviation (NaN = not estimated)
  // and whether it was estimated.
  double lag_time_constant = 0.0;
  double lag_time_constant_std = NAN;
  bool lag_estimated = false;
  ThermalSensorModel accel;
  ThermalSensorModel gyro;
  // What the session could and could not determine, one sentence each
  // ("one static pose: only the bias along gravity is determined").
  std::vector<std::string> notes;

  // True when any term has order > 0 or a lag is set.
  bool active() const { return accel.active() || gyro.active() || lag_time_constant != 0.0; }
  const ThermalSensorModel& Sensor(ThermalSensor s) const {
    return s == ThermalSensor::kAccel ? accel : gyro;
  }
  ThermalSensorModel* MutableSensor(ThermalSensor s) {
    return s == ThermalSensor::kAccel ? &accel : &gyro;
  }
  // True when T lies in [T_min, T_max] (a NaN range holds every T).
  bool InRange(double temperature) const;
  // T_e = T - tau r (r = dT_e/dt, the element's rate, degrees C per s; NaN = 0).
  double ElementTemperature(double temperature, double rate) const;
  // x = clamp(T_e, T_min, T_max) - T_ref; `clamped` (may be null) says
  // whether the clamp acted. A NaN temperature gives x = 0 (the base model).
  double Offset(double temperature, double rate, bool* clamped) const;
  // The blocks of one sensor, viewing this model's coefficients (valid while
  // the model lives and is not resized).
  ThermalBlocks<double> Blocks(ThermalSensor s) const;
  // Checks sizes, finiteness and the range; `error` names the key
  // ("thermal.accel.bias.coefficients: ...").
  bool IsValid(std::string* error) const;
};

// The accelerometer correction's thermal part in double:
// s = (I + D(x))^-1 U (v - b - db(x)), with U, b of the base model given.
Eigen::Vector3d CorrectAccelThermal(const ThermalModel& model, const Eigen::Vector3d& bias,
                                    const Eigen::Matrix3d& upper, const Eigen::Vector3d& raw,
                                    double x);
// w = (I + D_g(x))^-1 M_g (u - b_g - db_g(x)).
Eigen::Vector3d CorrectGyroThermal(const ThermalModel& model, const Eigen::Vector3d& bias,
                                   const Eigen::Matrix3d& matrix, const Eigen::Vector3d& raw,
                                   double x);

}  // namespace gravcal

#endif  // GRAVCAL_CORE_THERMAL_MODEL_H_
