#include "io/c_corrector_export.h"

#include <sstream>

#include "io/export_format.h"

namespace gravcal {
namespace internal {

std::string CNumber(double v, bool f) {
  std::string s = ExactNumber(v);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s + (f ? "f" : "");
}

namespace {

// "{a, b, c}", row-major.
template <typename Derived>
std::string CArray(const Eigen::MatrixBase<Derived>& m, bool f) {
  std::string s = "{";
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) s += (r || c ? ", " : "") + CNumber(m(r, c), f);
  }
  return s + "}";
}

// One precision's coefficients and functions: `real` is double or float.
void WriteFunctions(const ImuCorrector& c, bool f, std::ostringstream* out) {
  std::ostringstream& s = *out;
  const std::string real = f ? "float" : "double";
  const std::string p = f ? "F_" : "D_";
  const std::string suffix = f ? "_f" : "";
  const std::string sqrt = f ? "sqrtf" : "sqrt";
  const EffectParameters& e = c.effects;
  const bool quadratic = Contains(c.active_effects, Effect::kAccelQuadratic);
  auto on = [&](Effect effect) -> Eigen::MatrixXd {
    const Eigen::MatrixXd value = Info(effect).num_parameters == 9
                                      ? Eigen::MatrixXd(e.Matrix(effect))
                                      : Eigen::MatrixXd(e.Vector(effect));
    return Contains(c.active_effects, effect) ? value
                                              : Eigen::MatrixXd::Zero(value.rows(), value.cols());
  };
  auto array = [&](const char* name, const Eigen::MatrixXd& m) {
    s << "static const " << real << " " << p << name << "[" << m.size() << "] = " << CArray(m, f)
      << ";\n";
  };
  array("ACCEL_BIAS", c.accel.bias);
  array("ACCEL_UPPER", c.accel.upper);
  array("ACCEL_ROTATION", c.accel.rotation);
  // Only a term the functions below use (-Wunused-const-variable).
  if (quadratic) array("ACCEL_QUADRATIC", e.Vector(Effect::kAccelQuadratic));
  array("ACCEL_TEMP_BIAS", on(Effect::kAccelTemperatureBias));
  array("ACCEL_TEMP_SCALE", on(Effect::kAccelTemperatureScale));
  array("ACCEL_DRIFT", on(Effect::kAccelBiasDrift));
  array("GYRO_BIAS", c.has_gyro ? c.gyro.bias : Eigen::Vector3d::Zero());
  array("GYRO_MATRIX", c.has_gyro ? c.gyro.matrix : Eigen::Matrix3d::Identity());
  array("GYRO_G_SENSITIVITY", on(Effect::kGyroGSensitivity));
  array("GYRO_TEMP_BIAS", on(Effect::kGyroTemperatureBias));
  array("GYRO_DRIFT", on(Effect::kGyroBiasDrift));
  // A reference the model has no term for is unused, and may be NaN (no
  // temperature column), which is no C literal: 0 then.
  s << "static const " << real << " " << p << "REFERENCE_TEMPERATURE = "
    << CNumber(c.RequiresTemperature() ? e.reference_temperature : 0.0, f) << ";\n"
    << "static const " << real << " " << p
    << "REFERENCE_TIME = " << CNumber(c.RequiresTime() ? e.reference_time : 0.0, f) << ";\n\n";
  const CPrecision precision = {f, real, p, suffix};
  s << CThermalDefinitions(c, precision);
  const std::string accel_scale = CThermalRemoveScale(c, precision, ThermalSensor::kAccel, "m");
  const std::string zero = f ? "0.0f" : "0.0";
  const std::string one = f ? "1.0f" : "1.0";
  // dT and dt: zero when the model has no such term (the argument is
  // ignored) or the temperature is NaN.
  s << "static " << real << " gravcal_temperature_offset" << suffix << "(" << real << " temp_c) {\n"
    << "  return (GRAVCAL_USES_TEMPERATURE && temp_c == temp_c) ? temp_c - " << p
    << "REFERENCE_TEMPERATURE : " << zero << ";\n}\n\n"
    << "static " << real << " gravcal_time_offset" << suffix << "(" << real << " t_s) {\n"
    << "  return GRAVCAL_USES_TIME ? t_s - " << p << "REFERENCE_TIME : " << zero << ";\n}\n\n";
  s << "void gravcal_accel_correct" << suffix << "(const " << real << " raw[3], " << real
    << " temp_c, " << real << " t_s, " << real << " out[3]) {\n"
    << "  const " << real << " dT = gravcal_temperature_offset" << suffix << "(temp_c);\n"
    << "  const " << real << " dt = gravcal_time_offset" << suffix << "(t_s);\n"
    << CThermalOffsetLine(c, precision, ThermalSensor::kAccel) << "  " << real << " d[3], m[3];\n"
    << "  int i, j;\n"
    << "  for (i = 0; i < 3; ++i) d[i] = raw[i] - " << p << "ACCEL_BIAS[i];\n"
    << CThermalBias(c, precision, ThermalSensor::kAccel, "d") << "  for (i = 0; i < 3; ++i) {\n"
    << "    m[i] = " << zero << ";\n"
    << "    for (j = i; j < 3; ++j) m[i] += " << p << "ACCEL_UPPER[3 * i + j] * d[j];\n";
  // The thermal scale acts on all of m before the effect terms.
  if (!accel_scale.empty()) s << "  }\n" << accel_scale << "  for (i = 0; i < 3; ++i) {\n";
  s << "    m[i] -= " << p << "ACCEL_TEMP_BIAS[i] * dT;\n"
    << "    m[i] -= " << p << "ACCEL_DRIFT[i] * dt;\n"
    << "    m[i] /= " << one << " + " << p << "ACCEL_TEMP_SCALE[i] * dT;\n";
  if (quadratic) {
    s << "    m[i] = " << (f ? "2.0f" : "2.0") << " * m[i] / (" << one << " + " << sqrt << "("
      << one << " + " << (f ? "4.0f" : "4.0") << " * " << p << "ACCEL_QUADRATIC[i] * m[i]));\n";
  }
  s << "  }\n"
    << "  for (i = 0; i < 3; ++i) {\n"
    << "    out[i] = " << zero << ";\n"
    << "    for (j = 0; j < 3; ++j) out[i] += " << p << "ACCEL_ROTATION[3 * i + j] * m[j];\n"
    << "  }\n}\n\n";
  s << "void gravcal_gyro_correct" << suffix << "(const " << real << " raw[3], const " << real
    << " accel[3], " << real << " temp_c, " << real << " t_s, " << real << " out[3]) {\n"
    << "  const " << real << " dT = gravcal_temperature_offset" << suffix << "(temp_c);\n"
    << "  const " << real << " dt = gravcal_time_offset" << suffix << "(t_s);\n"
    << CThermalOffsetLine(c, precision, ThermalSensor::kGyro) << "  " << real
    << " force[3], u[3];\n"
    << "  int i, j;\n"
    << "  /* The specific force in the sensor frame: R^T accel. */\n"
    << "  for (i = 0; i < 3; ++i) {\n"
    << "    force[i] = " << zero << ";\n"
    << "    for (j = 0; j < 3; ++j) force[i] += " << p << "ACCEL_ROTATION[3 * j + i] * accel[j];\n"
    << "  }\n"
    << "  for (i = 0; i < 3; ++i) {\n"
    << "    " << real << " offset = " << zero << ";\n"
    << "    for (j = 0; j < 3; ++j) offset += " << p
    << "GYRO_G_SENSITIVITY[3 * i + j] * force[j];\n"
    << "    offset += " << p << "GYRO_TEMP_BIAS[i] * dT;\n"
    << "    offset += " << p << "GYRO_DRIFT[i] * dt;\n"
    << "    u[i] = raw[i] - " << p << "GYRO_BIAS[i] - offset;\n"
    << "  }\n"
    << CThermalBias(c, precision, ThermalSensor::kGyro, "u") << "  for (i = 0; i < 3; ++i) {\n"
    << "    out[i] = " << zero << ";\n"
    << "    for (j = 0; j < 3; ++j) out[i] += " << p << "GYRO_MATRIX[3 * i + j] * u[j];\n"
    << "  }\n"
    << CThermalRemoveScale(c, precision, ThermalSensor::kGyro, "out") << "}\n\n";
}

}  // namespace

std::vector<Effect> CCorrectorEffects() {
  return {Effect::kAccelQuadratic, Effect::kAccelTemperatureBias, Effect::kAccelTemperatureScale,
          Effect::kAccelBiasDrift, Effect::kGyroGSensitivity,     Effect::kGyroTemperatureBias,
          Effect::kGyroBiasDrift};
}

std::vector<ExportedFile> CCorrectorFiles(const ImuCorrector& corrector,
                                          const std::vector<std::string>& comment) {
  std::string head = "/*\n";
  for (const std::string& line : comment) head += " * " + line + "\n";
  head += " */\n";
  std::ostringstream h;
  h << head << "#ifndef GRAVCAL_CORRECT_H\n#define GRAVCAL_CORRECT_H\n\n"
    << "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n"
    << "/* raw: the accelerometer reading in the calibration's raw units; temp_c: degrees C\n"
    << " * (ignored when the calibration has no temperature term; NaN = no term);\n"
    << " * t_s: the log's time in seconds (ignored without a drift term).\n"
    << " * out: specific force in m/s^2, housing frame. */\n"
    << "void gravcal_accel_correct(const double raw[3], double temp_c, double t_s, double "
       "out[3]);\n"
    << "/* raw: the gyroscope reading in raw units; accel: the corrected specific force\n"
    << " * (gravcal_accel_correct's out), for the g-sensitivity term. out: rad/s. */\n"
    << "void gravcal_gyro_correct(const double raw[3], const double accel[3], double temp_c,\n"
    << "                          double t_s, double out[3]);\n"
    << "/* The same in single precision. */\n"
    << "void gravcal_accel_correct_f(const float raw[3], float temp_c, float t_s, float out[3]);\n"
    << "void gravcal_gyro_correct_f(const float raw[3], const float accel[3], float temp_c,\n"
    << "                            float t_s, float out[3]);\n\n"
    << "#ifdef __cplusplus\n}\n#endif\n\n#endif /* GRAVCAL_CORRECT_H */\n";
  std::ostringstream c;
  c << head << "#include \"gravcal_correct.h\"\n";
  if (Contains(corrector.active_effects, Effect::kAccelQuadratic)) c << "#include <math.h>\n";
  c << "\n#define GRAVCAL_USES_TEMPERATURE " << (corrector.RequiresTemperature() ? 1 : 0) << "\n"
    << "#define GRAVCAL_USES_TIME " << (corrector.RequiresTime() ? 1 : 0) << "\n\n";
  WriteFunctions(corrector, false, &c);
  WriteFunctions(corrector, true, &c);
  return {{"gravcal_correct.h", h.str()}, {"gravcal_correct.c", c.str()}};
}

}  // namespace internal
}  // namespace gravcal
