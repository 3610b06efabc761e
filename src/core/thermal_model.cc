#include "gravcal/core/thermal_model.h"

#include <cstdio>

#include "core/enum_names.h"

namespace gravcal {

namespace {
const internal::EnumName<ThermalQuantity> kThermalQuantities[] = {
    {ThermalQuantity::kBias, "bias"},
    {ThermalQuantity::kScale, "scale"},
    {ThermalQuantity::kMisalignment, "misalignment"}};
const internal::EnumName<ThermalSensor> kThermalSensors[] = {{ThermalSensor::kAccel, "accel"},
                                                             {ThermalSensor::kGyro, "gyro"}};
}  // namespace

GRAVCAL_ENUM_STRINGS(ThermalQuantity, kThermalQuantities)
GRAVCAL_ENUM_STRINGS(ThermalSensor, kThermalSensors)

int ThermalComponents(ThermalSensor sensor, ThermalQuantity quantity) {
  if (quantity == ThermalQuantity::kMisalignment && sensor == ThermalSensor::kGyro) return 6;
  return 3;
}

std::vector<std::string> ThermalComponentNames(ThermalSensor sensor, ThermalQuantity quantity) {
  if (quantity != ThermalQuantity::kMisalignment) return {"x", "y", "z"};
  if (sensor == ThermalSensor::kAccel) return {"xy", "xz", "yz"};
  return {"xy", "xz", "yx", "yz", "zx", "zy"};
}

std::string ThermalUnit(ThermalQuantity quantity, int power) {
  const char* base = quantity == ThermalQuantity::kBias    ? "raw"
                     : quantity == ThermalQuantity::kScale ? "1"
                                                           : "rad";
  std::string unit = std::string(base) + "/degC";
  if (power > 1) unit += "^" + std::to_string(power);
  return unit;
}

void ThermalPolynomial::Resize(int components, int new_order) {
  order = new_order;
  coefficients = ThermalCoefficients::Zero(components, new_order);
  determined.setConstant(components, new_order, true);
  covariance.clear();
}

bool ThermalPolynomial::Determined(int component, int power) const {
  if (power < 1 || power > order) return false;
  if (determined.size() == 0) return true;
  return determined(component, power - 1);
}

double ThermalPolynomial::Value(int component, double x) const {
  if (!active() || component < 0 || component >= coefficients.rows()) return 0.0;
  double out = 0.0;
  EvaluateThermalPolynomial(coefficients.row(component).data(), 1, order, x, &out);
  return out;
}

double ThermalPolynomial::Std(int component, double x, bool include_constant) const {
  if (component < 0 || component >= static_cast<int>(covariance.size())) return NAN;
  const Eigen::MatrixXd& c = covariance[component];
  if (c.rows() != order + 1 || c.cols() != order + 1) return NAN;
  Eigen::VectorXd phi(order + 1);
  phi(0) = include_constant ? 1.0 : 0.0;
  double power = 1.0;
  for (int k = 1; k <= order; ++k) {
    power *= x;
    phi(k) = power;
    if (!Determined(component, k) && power != 0.0) return NAN;
  }
  const double v = phi.dot(c * phi);
  return v >= 0.0 ? std::sqrt(v) : NAN;
}

const ThermalPolynomial& ThermalSensorModel::Term(ThermalQuantity q) const {
  switch (q) {
    case ThermalQuantity::kScale:
      return scale;
    case ThermalQuantity::kMisalignment:
      return misalignment;
    case ThermalQuantity::kBias:
      break;
  }
  return bias;
}

ThermalPolynomial* ThermalSensorModel::MutableTerm(ThermalQuantity q) {
  return const_cast<ThermalPolynomial*>(&Term(q));
}

bool ThermalModel::InRange(double temperature) const {
  if (std::isfinite(min_temperature) && temperature < min_temperature) return false;
  if (std::isfinite(max_temperature) && temperature > max_temperature) return false;
  return true;
}

double ThermalModel::ElementTemperature(double temperature, double rate) const {
  if (lag_time_constant == 0.0 || !std::isfinite(rate)) return temperature;
  return temperature - lag_time_constant * rate;
}

double ThermalModel::Offset(double temperature, double rate, bool* clamped) const {
  if (clamped != nullptr) *clamped = false;
  if (!std::isfinite(temperature)) return 0.0;
  double t = ElementTemperature(temperature, rate);
  if (std::isfinite(min_temperature) && t < min_temperature) {
    t = min_temperature;
    if (clamped != nullptr) *clamped = true;
  }
  if (std::isfinite(max_temperature) && t > max_temperature) {
    t = max_temperature;
    if (clamped != nullptr) *clamped = true;
  }
  return t - reference_temperature;
}

ThermalBlocks<double> ThermalModel::Blocks(ThermalSensor s) const {
  const ThermalSensorModel& m = Sensor(s);
  ThermalBlocks<double> b;
  b.sensor = s;
  auto take = [](const ThermalPolynomial& p, const double** block, int* order) {
    if (!p.active()) return;
    *block = p.coefficients.data();
    *order = p.order;
  };
  take(m.bias, &b.bias, &b.bias_order);
  take(m.scale, &b.scale, &b.scale_order);
  take(m.misalignment, &b.misalignment, &b.misalignment_order);
  return b;
}

bool ThermalModel::IsValid(std::string* error) const {
  auto fail = [error](const std::string& key, const std::string& what) {
    if (error != nullptr) *error = "thermal." + key + ": " + what;
    return false;
  };
  if (!std::isfinite(reference_temperature)) return fail("reference_temperature", "must be finite");
  if (std::isfinite(min_temperature) != std::isfinite(max_temperature)) {
    return fail("min_temperature", "min and max must both be numbers or both be absent");
  }
  if (std::isfinite(min_temperature) && !(min_temperature <= max_temperature)) {
    return fail("min_temperature", "must not exceed max_temperature");
  }
  if (!std::isfinite(lag_time_constant)) return fail("lag_time_constant", "must be finite");
  for (ThermalSensor s : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
    for (ThermalQuantity q :
         {ThermalQuantity::kBias, ThermalQuantity::kScale, ThermalQuantity::kMisalignment}) {
      const ThermalPolynomial& p = Sensor(s).Term(q);
      const std::string key = std::string(ToString(s)) + "." + ToString(q);
      if (p.order < 0 || p.order > kMaxThermalOrder) {
        return fail(key + ".order", "must be between 0 and " + std::to_string(kMaxThermalOrder));
      }
      if (p.order == 0) continue;
      const int n = ThermalComponents(s, q);
      if (p.coefficients.rows() != n || p.coefficients.cols() != p.order) {
        return fail(key + ".coefficients", "must have " + std::to_string(n) + " rows of " +
                                               std::to_string(p.order) + " numbers");
      }
      if (!p.coefficients.allFinite()) return fail(key + ".coefficients", "must be finite");
      if (p.determined.size() != 0 &&
          (p.determined.rows() != n || p.determined.cols() != p.order)) {
        return fail(key + ".determined", "must match the coefficients' shape");
      }
      if (!p.covariance.empty() && static_cast<int>(p.covariance.size()) != n) {
        return fail(key + ".covariance", "must have one matrix per component");
      }
      for (const Eigen::MatrixXd& c : p.covariance) {
        if (c.rows() != p.order + 1 || c.cols() != p.order + 1) {
          return fail(key + ".covariance", "each matrix must be (order + 1) square");
        }
      }
    }
  }
  return true;
}

namespace {

// The ThermalBlocks of one sensor with the temperature applied.
Eigen::Vector3d Corrected(const ThermalBlocks<double>& b, const Eigen::Vector3d& bias,
                          const Eigen::Matrix3d& matrix, const Eigen::Vector3d& raw, double x) {
  double db[3];
  b.BiasChange(x, db);
  const Eigen::Vector3d d = raw - bias - Eigen::Vector3d(db[0], db[1], db[2]);
  Eigen::Vector3d y = matrix * d;
  b.RemoveScale(x, y.data());
  return y;
}

}  // namespace

Eigen::Vector3d CorrectAccelThermal(const ThermalModel& model, const Eigen::Vector3d& bias,
                                    const Eigen::Matrix3d& upper, const Eigen::Vector3d& raw,
                                    double x) {
  return Corrected(model.Blocks(ThermalSensor::kAccel), bias, upper, raw, x);
}

Eigen::Vector3d CorrectGyroThermal(const ThermalModel& model, const Eigen::Vector3d& bias,
                                   const Eigen::Matrix3d& matrix, const Eigen::Vector3d& raw,
                                   double x) {
  return Corrected(model.Blocks(ThermalSensor::kGyro), bias, matrix, raw, x);
}

}  // namespace gravcal
