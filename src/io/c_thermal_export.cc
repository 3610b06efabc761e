// The thermal model in the generated C corrector (c_corrector_export.h):
// coefficient arrays, the clamped temperature offset, the polynomials in
// Horner form and the (I + D(x))^-1 solve, in one precision.
#include <cctype>
#include <cmath>
#include <sstream>
#include <vector>

#include "io/c_corrector_export.h"

namespace gravcal {
namespace internal {

namespace {

// "P_THERMAL_ACCEL_BIAS" etc.
std::string ArrayName(const CPrecision& p, ThermalSensor s, ThermalQuantity q) {
  std::string name = p.prefix + "THERMAL_" + (s == ThermalSensor::kAccel ? "ACCEL_" : "GYRO_");
  for (const char* c = ToString(q); *c; ++c) name += static_cast<char>(std::toupper(*c));
  return name;
}

// The value of term q of sensor s for component `i` (a C expression), or ""
// when the term is off.
std::string TermValue(const ThermalModel& m, const CPrecision& p, ThermalSensor s,
                      ThermalQuantity q, const std::string& i) {
  const ThermalPolynomial& t = m.Sensor(s).Term(q);
  if (!t.active()) return "";
  return "gravcal_thermal_poly" + p.suffix + "(&" + ArrayName(p, s, q) + "[" +
         std::to_string(t.order) + " * " + i + "], " + std::to_string(t.order) + ", x)";
}

bool HasScale(const ThermalSensorModel& s) { return s.scale.active() || s.misalignment.active(); }

}  // namespace

bool CThermalActive(const ImuCorrector& c) {
  return c.thermal.accel.active() || (c.has_gyro && c.thermal.gyro.active());
}

std::string CThermalDefinitions(const ImuCorrector& c, const CPrecision& p) {
  if (!CThermalActive(c)) return "";
  const ThermalModel& m = c.thermal;
  const bool f = p.single;
  std::ostringstream s;
  for (ThermalSensor sensor : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
    if (sensor == ThermalSensor::kGyro && !c.has_gyro) continue;
    for (ThermalQuantity q :
         {ThermalQuantity::kBias, ThermalQuantity::kScale, ThermalQuantity::kMisalignment}) {
      const ThermalPolynomial& t = m.Sensor(sensor).Term(q);
      if (!t.active()) continue;
      // Component i's c_i1 .. c_in, row after row (thermal_model.h layout).
      s << "static const " << p.real << " " << ArrayName(p, sensor, q) << "["
        << t.coefficients.size() << "] = {";
      for (Eigen::Index r = 0; r < t.coefficients.rows(); ++r) {
        for (Eigen::Index k = 0; k < t.coefficients.cols(); ++k) {
          s << (r || k ? ", " : "") << CNumber(t.coefficients(r, k), f);
        }
      }
      s << "};\n";
    }
  }
  s << "static const " << p.real << " " << p.prefix
    << "THERMAL_REFERENCE = " << CNumber(m.reference_temperature, f) << ";\n";
  const bool clamp = std::isfinite(m.min_temperature) && std::isfinite(m.max_temperature);
  if (clamp) {
    s << "static const " << p.real << " " << p.prefix
      << "THERMAL_MIN = " << CNumber(m.min_temperature, f) << ";\n"
      << "static const " << p.real << " " << p.prefix
      << "THERMAL_MAX = " << CNumber(m.max_temperature, f) << ";\n";
  }
  s << "\n/* x = clamp(T, T_min, T_max) - T_ref; 0 for a NaN temperature. */\n"
    << "static " << p.real << " gravcal_thermal_x" << p.suffix << "(" << p.real << " temp_c) {\n"
    << "  if (temp_c != temp_c) return " << CNumber(0.0, f) << ";\n";
  if (clamp) {
    s << "  if (temp_c < " << p.prefix << "THERMAL_MIN) temp_c = " << p.prefix << "THERMAL_MIN;\n"
      << "  if (temp_c > " << p.prefix << "THERMAL_MAX) temp_c = " << p.prefix << "THERMAL_MAX;\n";
  }
  s << "  return temp_c - " << p.prefix << "THERMAL_REFERENCE;\n}\n\n"
    << "/* c[0] x + c[1] x^2 + ... + c[n-1] x^n in Horner form. */\n"
    << "static " << p.real << " gravcal_thermal_poly" << p.suffix << "(const " << p.real
    << "* c, int n, " << p.real << " x) {\n"
    << "  " << p.real << " sum = c[n - 1];\n"
    << "  int k;\n"
    << "  for (k = n - 2; k >= 0; --k) sum = c[k] + x * sum;\n"
    << "  return x * sum;\n}\n\n";
  return s.str();
}

std::string CThermalBias(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor,
                         const std::string& target) {
  if (sensor == ThermalSensor::kGyro && !c.has_gyro) return "";
  const std::string v = TermValue(c.thermal, p, sensor, ThermalQuantity::kBias, "i");
  if (v.empty()) return "";
  return "  for (i = 0; i < 3; ++i) " + target + "[i] -= " + v + ";\n";
}

std::string CThermalRemoveScale(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor,
                                const std::string& y) {
  if (sensor == ThermalSensor::kGyro && !c.has_gyro) return "";
  const ThermalSensorModel& model = c.thermal.Sensor(sensor);
  if (!HasScale(model)) return "";
  const bool f = p.single;
  std::ostringstream s;
  s << "  {\n    /* (I + D(x))^-1 " << y << ": D = diag(scale) + misalignment. */\n"
    << "    " << p.real << " a[9] = {" << CNumber(1.0, f) << ", " << CNumber(0.0, f) << ", "
    << CNumber(0.0, f) << ", " << CNumber(0.0, f) << ", " << CNumber(1.0, f) << ", "
    << CNumber(0.0, f) << ", " << CNumber(0.0, f) << ", " << CNumber(0.0, f) << ", "
    << CNumber(1.0, f) << "};\n";
  if (model.scale.active()) {
    s << "    for (i = 0; i < 3; ++i) a[4 * i] += "
      << TermValue(c.thermal, p, sensor, ThermalQuantity::kScale, "i") << ";\n";
  }
  if (model.misalignment.active()) {
    // Accelerometer: 01, 02, 12; gyroscope: 01, 02, 10, 12, 20, 21.
    const std::vector<int> slots = sensor == ThermalSensor::kAccel
                                       ? std::vector<int>{1, 2, 5}
                                       : std::vector<int>{1, 2, 3, 5, 6, 7};
    for (size_t k = 0; k < slots.size(); ++k) {
      s << "    a[" << slots[k] << "] += "
        << TermValue(c.thermal, p, sensor, ThermalQuantity::kMisalignment, std::to_string(k))
        << ";\n";
    }
  }
  if (sensor == ThermalSensor::kAccel) {
    // Upper triangular: back substitution.
    s << "    " << y << "[2] = " << y << "[2] / a[8];\n"
      << "    " << y << "[1] = (" << y << "[1] - a[5] * " << y << "[2]) / a[4];\n"
      << "    " << y << "[0] = (" << y << "[0] - a[1] * " << y << "[1] - a[2] * " << y
      << "[2]) / a[0];\n";
  } else {
    // Cramer's rule with the cofactors of a.
    s << "    const " << p.real << " c0 = a[4] * a[8] - a[5] * a[7];\n"
      << "    const " << p.real << " c1 = a[5] * a[6] - a[3] * a[8];\n"
      << "    const " << p.real << " c2 = a[3] * a[7] - a[4] * a[6];\n"
      << "    const " << p.real << " det = a[0] * c0 + a[1] * c1 + a[2] * c2;\n"
      << "    const " << p.real << " y0 = " << y << "[0], y1 = " << y << "[1], y2 = " << y
      << "[2];\n"
      << "    " << y << "[0] = (c0 * y0 + (a[2] * a[7] - a[1] * a[8]) * y1 + "
      << "(a[1] * a[5] - a[2] * a[4]) * y2) / det;\n"
      << "    " << y << "[1] = (c1 * y0 + (a[0] * a[8] - a[2] * a[6]) * y1 + "
      << "(a[2] * a[3] - a[0] * a[5]) * y2) / det;\n"
      << "    " << y << "[2] = (c2 * y0 + (a[1] * a[6] - a[0] * a[7]) * y1 + "
      << "(a[0] * a[4] - a[1] * a[3]) * y2) / det;\n";
  }
  s << "  }\n";
  return s.str();
}

std::string CThermalOffsetLine(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor,
                               const std::string& temperature) {
  if (sensor == ThermalSensor::kGyro && !c.has_gyro) return "";
  if (!c.thermal.Sensor(sensor).active()) return "";
  return "  const " + p.real + " x = gravcal_thermal_x" + p.suffix + "(" + temperature + ");\n";
}

std::string CLagFunctions(const ImuCorrector& c, const CPrecision& p) {
  const std::string& r = p.real;
  const std::string zero = CNumber(0.0, p.single);
  const std::string state = "gravcal_lag_state" + p.suffix;
  std::ostringstream s;
  s << "void gravcal_lag_init" << p.suffix << "(" << state << "* lag) {\n"
    << "  lag->started = 0;\n"
    << "  lag->last_t = lag->last_temp_c = lag->element_c = lag->rate = " << zero << ";\n}\n\n";
  const double tau = c.thermal.lag_time_constant;
  if (!CThermalActive(c) || !(tau > 0.0)) {
    s << "/* No thermal lag: the element is at the recorded temperature. */\n"
      << "static " << r << " gravcal_lag_element" << p.suffix << "(" << state << "* lag, " << r
      << " t_s, " << r << " temp_c) {\n"
      << "  (void)lag;\n  (void)t_s;\n  return temp_c;\n}\n\n";
    return s.str();
  }
  // ThermalElementRate::Add (core/thermal_rate.h) and
  // ThermalModel::ElementTemperature, step for step.
  const std::string tau_name = p.prefix + "THERMAL_LAG";
  s << "static const " << r << " " << tau_name << " = " << CNumber(tau, p.single) << ";\n\n"
    << "/* The sensing element's temperature T_e at this sample: tau dT_e/dt = T - T_e,\n"
    << " * T_e = T at the first sample, T linear between samples (the step is exact);\n"
    << " * a sample without a finite time or temperature keeps the last rate. */\n"
    << "static " << r << " gravcal_lag_element" << p.suffix << "(" << state << "* lag, " << r
    << " t_s, " << r << " temp_c) {\n"
    << "  if (isfinite(temp_c) && isfinite(t_s)) {\n"
    << "    if (!lag->started || !(t_s > lag->last_t)) {\n"
    << "      if (!lag->started) lag->element_c = temp_c;\n"
    << "      lag->started = 1;\n"
    << "    } else {\n"
    << "      const " << r << " dt = t_s - lag->last_t;\n"
    << "      const " << r << " m = (temp_c - lag->last_temp_c) / dt;\n"
    << "      const " << r << " a = " << (p.single ? "expf" : "exp") << "(-dt / " << tau_name
    << ");\n"
    << "      lag->element_c = temp_c - " << tau_name
    << " * m + (lag->element_c - lag->last_temp_c + " << tau_name << " * m) * a;\n"
    << "    }\n"
    << "    lag->last_t = t_s;\n"
    << "    lag->last_temp_c = temp_c;\n"
    << "    lag->rate = (temp_c - lag->element_c) / " << tau_name << ";\n"
    << "  }\n"
    << "  return temp_c - " << tau_name << " * lag->rate;\n}\n\n";
  return s.str();
}

}  // namespace internal
}  // namespace gravcal
