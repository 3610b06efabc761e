// The generated C corrector (c_corrector_export.h). The effects' terms come
// from their definitions (core/effects/<name>.h, kC), so a registered
// effect is written here with no edit to this file.
#include "io/c_corrector_export.h"

#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

#include "gravcal/core/effect_registry.h"
#include "io/export_format.h"

namespace gravcal {
namespace internal {

std::string CNumber(double v, bool f) {
  std::string s = ExactNumber(v);
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s + (f ? "f" : "");
}

std::string CExpression(const char* expression, const std::string& array, const std::string& input,
                        bool single, std::set<std::string>* used) {
  std::string out;
  for (const char* c = expression; *c != '\0';) {
    if (std::isalpha(static_cast<unsigned char>(*c)) || *c == '_') {
      std::string name;
      while (std::isalnum(static_cast<unsigned char>(*c)) || *c == '_') name += *c++;
      if (used != nullptr) used->insert(name);
      if (name == "p") {
        out += array;
      } else if (name == "x") {
        out += input;
      } else if (single && (name == "sqrt" || name == "exp" || name == "log" || name == "fabs" ||
                            name == "pow")) {
        out += name + "f";
      } else {
        out += name;
      }
    } else if (std::isdigit(static_cast<unsigned char>(*c))) {
      std::string number;
      bool real = false;
      while (std::isalnum(static_cast<unsigned char>(*c)) || *c == '.' ||
             ((*c == '+' || *c == '-') && (number.back() == 'e' || number.back() == 'E'))) {
        real |= *c == '.' || *c == 'e' || *c == 'E';
        number += *c++;
      }
      out += number + (single && real ? "f" : "");
    } else {
      out += *c++;
    }
  }
  return out;
}

namespace {

// One effect term the corrector writes: its form, depth (shapes), C term
// and the name and unit of its parameters.
struct CTerm {
  Effect effect;
  EffectForm form;
  int depth = 0;
  const char* expression;
};

// The active effects with a term, in registry order; the gyroscope's only
// with a gyroscope model (as ImuCorrector::CorrectGyro).
std::vector<CTerm> Terms(const ImuCorrector& c) {
  std::vector<CTerm> terms;
  effects::ForEach([&](auto d, Effect e) {
    using D = decltype(d);
    if constexpr (D::kForm != EffectForm::kInUpper) {
      if (!Contains(c.active_effects, e)) return;
      if (D::kForm == EffectForm::kGyroOffset && !c.has_gyro) return;
      int depth = 0;
      if constexpr (D::kForm == EffectForm::kAccelShape) depth = D::kDepth;
      terms.push_back({e, D::kForm, depth, D::kC});
    }
  });
  return terms;
}

// "P_ACCEL_TEMPERATURE_BIAS" for accel_temperature_bias.
std::string ArrayOf(const CPrecision& p, Effect e) {
  std::string name = p.prefix;
  for (const char* c = ToString(e); *c; ++c) name += static_cast<char>(std::toupper(*c));
  return name;
}

// "{a, b, c}", row-major.
template <typename Derived>
std::string CArray(const Eigen::MatrixBase<Derived>& m, bool f) {
  std::string s = "{";
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) s += (r || c ? ", " : "") + CNumber(m(r, c), f);
  }
  return s + "}";
}

// The statements of one sensor's effect terms on `target`[i] inside a loop
// over i: the accelerometer's offsets removed in registry order and then
// its shapes inverted from the outermost in (effect_registry.h,
// RemoveAccelEffects); the gyroscope's offsets summed into `offset`.
std::string TermLines(const std::vector<CTerm>& terms, const CPrecision& p, bool gyro,
                      std::set<std::string>* used) {
  std::string s;
  auto line = [&](const CTerm& t, const std::string& lhs, const std::string& op,
                  const std::string& input) {
    s += "    " + lhs + " " + op + " " +
         CExpression(t.expression, ArrayOf(p, t.effect), input, p.single, used) + ";\n";
  };
  const EffectForm offset = gyro ? EffectForm::kGyroOffset : EffectForm::kAccelOffset;
  for (const CTerm& t : terms) {
    if (t.form == offset) line(t, gyro ? "offset" : "m[i]", gyro ? "+=" : "-=", "");
  }
  if (gyro) return s;
  for (int depth = effects::kLayout.max_depth; depth >= 1; --depth) {
    for (const CTerm& t : terms) {
      if (t.form == EffectForm::kAccelShape && t.depth == depth) line(t, "m[i]", "=", "m[i]");
    }
  }
  return s;
}

// The declarations of dT, dt and x a function body reads, and (void) for
// the arguments it does not.
std::string Offsets(const ImuCorrector& c, const CPrecision& p, ThermalSensor sensor,
                    const std::set<std::string>& used) {
  const std::string zero = CNumber(0.0, p.single);
  std::string s;
  if (used.count("dT")) {
    s += "  const " + p.real + " dT = isfinite(temp_c) ? temp_c - " + p.prefix +
         "REFERENCE_TEMPERATURE : " + zero + ";\n";
  } else {
    s += "  (void)temp_c;\n";
  }
  if (used.count("dt")) {
    s += "  const " + p.real + " dt = t_s - " + p.prefix + "REFERENCE_TIME;\n";
  } else {
    s += "  (void)t_s;\n";
  }
  const std::string x = CThermalOffsetLine(c, p, sensor, "element_c");
  return s + (x.empty() ? "  (void)element_c;\n" : x);
}

// One precision's coefficients and functions.
void WriteFunctions(const ImuCorrector& c, bool f, std::ostringstream* out) {
  std::ostringstream& s = *out;
  const CPrecision p = {f, f ? "float" : "double", f ? "F_" : "D_", f ? "_f" : ""};
  const std::string& real = p.real;
  const std::string zero = CNumber(0.0, f);
  const std::vector<CTerm> terms = Terms(c);
  // The bodies first, to know which offsets they read.
  std::set<std::string> accel_used, gyro_used;
  const std::string accel_terms = TermLines(terms, p, false, &accel_used);
  const std::string gyro_terms = TermLines(terms, p, true, &gyro_used);
  auto array = [&](const std::string& name, const Eigen::MatrixXd& m) {
    s << "static const " << real << " " << p.prefix << name << "[" << m.size()
      << "] = " << CArray(m, f) << ";\n";
  };
  array("ACCEL_BIAS", c.accel.bias);
  array("ACCEL_UPPER", c.accel.upper);
  array("ACCEL_ROTATION", c.accel.rotation);
  array("GYRO_BIAS", c.has_gyro ? c.gyro.bias : Eigen::Vector3d::Zero());
  array("GYRO_MATRIX", c.has_gyro ? c.gyro.matrix : Eigen::Matrix3d::Identity());
  for (const CTerm& t : terms) {
    const EffectInfo& info = Info(t.effect);
    std::string names;
    for (const std::string& n : info.parameter_names) names += (names.empty() ? "" : ", ") + n;
    const std::vector<double> v = c.effects.Values(t.effect);
    s << "/* " << info.name << ": " << names << " (" << info.unit << ") */\n";
    array(ArrayOf(p, t.effect).substr(p.prefix.size()),
          Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
  }
  if (accel_used.count("dT") || gyro_used.count("dT")) {
    s << "static const " << real << " " << p.prefix
      << "REFERENCE_TEMPERATURE = " << CNumber(c.effects.reference_temperature, f) << ";\n";
  }
  if (accel_used.count("dt") || gyro_used.count("dt")) {
    s << "static const " << real << " " << p.prefix
      << "REFERENCE_TIME = " << CNumber(c.effects.reference_time, f) << ";\n";
  }
  s << "\n" << CThermalDefinitions(c, p);
  // The accelerometer: temp_c for the effects' dT, element_c (the sensing
  // element's temperature, = temp_c without a lag) for the thermal model.
  s << "static void gravcal_accel_at" << p.suffix << "(const " << real << " raw[3], " << real
    << " temp_c, " << real << " element_c, " << real << " t_s, " << real << " out[3]) {\n"
    << Offsets(c, p, ThermalSensor::kAccel, accel_used) << "  " << real << " d[3], m[3];\n"
    << "  int i, j;\n"
    << "  for (i = 0; i < 3; ++i) d[i] = raw[i] - " << p.prefix << "ACCEL_BIAS[i];\n"
    << CThermalBias(c, p, ThermalSensor::kAccel, "d") << "  for (i = 0; i < 3; ++i) {\n"
    << "    m[i] = " << zero << ";\n"
    << "    for (j = i; j < 3; ++j) m[i] += " << p.prefix << "ACCEL_UPPER[3 * i + j] * d[j];\n"
    << "  }\n"
    << CThermalRemoveScale(c, p, ThermalSensor::kAccel, "m");
  if (!accel_terms.empty()) s << "  for (i = 0; i < 3; ++i) {\n" << accel_terms << "  }\n";
  s << "  for (i = 0; i < 3; ++i) {\n"
    << "    out[i] = " << zero << ";\n"
    << "    for (j = 0; j < 3; ++j) out[i] += " << p.prefix << "ACCEL_ROTATION[3 * i + j] * m[j];\n"
    << "  }\n}\n\n";
  // The gyroscope.
  const bool force = gyro_used.count("force") > 0;
  s << "static void gravcal_gyro_at" << p.suffix << "(const " << real << " raw[3], const " << real
    << " accel[3], " << real << " temp_c, " << real << " element_c, " << real << " t_s, " << real
    << " out[3]) {\n"
    << Offsets(c, p, ThermalSensor::kGyro, gyro_used) << "  " << real
    << (force ? " force[3], u[3];\n" : " u[3];\n") << "  int i, j;\n";
  if (force) {
    s << "  /* The specific force in the sensor frame: R^T accel. */\n"
      << "  for (i = 0; i < 3; ++i) {\n"
      << "    force[i] = " << zero << ";\n"
      << "    for (j = 0; j < 3; ++j) force[i] += " << p.prefix
      << "ACCEL_ROTATION[3 * j + i] * accel[j];\n"
      << "  }\n";
  } else {
    s << "  (void)accel;\n";
  }
  s << "  for (i = 0; i < 3; ++i) {\n";
  if (gyro_terms.empty()) {
    s << "    u[i] = raw[i] - " << p.prefix << "GYRO_BIAS[i];\n";
  } else {
    s << "    " << real << " offset = " << zero << ";\n"
      << gyro_terms << "    u[i] = raw[i] - " << p.prefix << "GYRO_BIAS[i] - offset;\n";
  }
  s << "  }\n"
    << CThermalBias(c, p, ThermalSensor::kGyro, "u") << "  for (i = 0; i < 3; ++i) {\n"
    << "    out[i] = " << zero << ";\n"
    << "    for (j = 0; j < 3; ++j) out[i] += " << p.prefix << "GYRO_MATRIX[3 * i + j] * u[j];\n"
    << "  }\n"
    << CThermalRemoveScale(c, p, ThermalSensor::kGyro, "out") << "}\n\n";
  // The entry points: without the lag, and with it (the state).
  s << "void gravcal_accel_correct" << p.suffix << "(const " << real << " raw[3], " << real
    << " temp_c, " << real << " t_s, " << real << " out[3]) {\n"
    << "  gravcal_accel_at" << p.suffix << "(raw, temp_c, temp_c, t_s, out);\n}\n\n"
    << "void gravcal_gyro_correct" << p.suffix << "(const " << real << " raw[3], const " << real
    << " accel[3], " << real << " temp_c, " << real << " t_s, " << real << " out[3]) {\n"
    << "  gravcal_gyro_at" << p.suffix << "(raw, accel, temp_c, temp_c, t_s, out);\n}\n\n"
    << CLagFunctions(c, p) << "void gravcal_correct_sample" << p.suffix << "(gravcal_lag_state"
    << p.suffix << "* lag, const " << real << " accel_raw[3], const " << real << " gyro_raw[3], "
    << real << " temp_c, " << real << " t_s, " << real << " accel_out[3], " << real
    << " gyro_out[3]) {\n"
    << "  const " << real << " element_c = gravcal_lag_element" << p.suffix
    << "(lag, t_s, temp_c);\n"
    << "  gravcal_accel_at" << p.suffix << "(accel_raw, temp_c, element_c, t_s, accel_out);\n"
    << "  if (gyro_raw != 0) {\n"
    << "    gravcal_gyro_at" << p.suffix
    << "(gyro_raw, accel_out, temp_c, element_c, t_s, gyro_out);\n"
    << "  }\n}\n\n";
}

// The header's declarations of one precision.
std::string Declarations(const std::string& real, const std::string& suffix) {
  const std::string r = real + " ";
  return "void gravcal_accel_correct" + suffix + "(const " + r + "raw[3], " + r + "temp_c, " + r +
         "t_s, " + r + "out[3]);\n" + "void gravcal_gyro_correct" + suffix + "(const " + r +
         "raw[3], const " + r + "accel[3], " + r + "temp_c,\n    " + r + "t_s, " + r +
         "out[3]);\n" + "typedef struct {\n  int started;\n  " + r + "last_t, last_temp_c, " +
         "element_c, rate;\n} gravcal_lag_state" + suffix + ";\n" + "void gravcal_lag_init" +
         suffix + "(gravcal_lag_state" + suffix + "* lag);\n" + "void gravcal_correct_sample" +
         suffix + "(gravcal_lag_state" + suffix + "* lag, const " + r +
         "accel_raw[3],\n    const " + r + "gyro_raw[3], " + r + "temp_c, " + r + "t_s, " + r +
         "accel_out[3],\n    " + r + "gyro_out[3]);\n";
}

}  // namespace

std::vector<ExportedFile> CCorrectorFiles(const ImuCorrector& corrector,
                                          const std::vector<std::string>& comment) {
  std::string head = "/*\n";
  for (const std::string& line : comment) head += " * " + line + "\n";
  head += " */\n";
  std::ostringstream h;
  h << head << "#ifndef GRAVCAL_CORRECT_H\n#define GRAVCAL_CORRECT_H\n\n"
    << "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n"
    << "/* gravcal_accel_correct: raw, the accelerometer reading in the calibration's raw\n"
    << " * units; temp_c, degrees C (ignored when the calibration has no temperature term;\n"
    << " * NaN = no term); t_s, the log's time in seconds (ignored without a drift term).\n"
    << " * out: specific force in m/s^2, housing frame.\n"
    << " * gravcal_gyro_correct: raw, the gyroscope reading in raw units; accel, the\n"
    << " * corrected specific force (gravcal_accel_correct's out), for the g-sensitivity\n"
    << " * term. out: rad/s.\n"
    << " * These two take the sensing element at the recorded temperature (no thermal lag).\n"
    << " * gravcal_correct_sample corrects one sample of a log as gravcal apply does, with\n"
    << " * the thermal lag: the element's temperature follows temp_c through the\n"
    << " * first-order lag, held in `lag` (gravcal_lag_init before the first sample; then\n"
    << " * every sample in time order). gyro_raw may be 0 (null): accelerometer only.\n"
    << " * The _f functions are the same in single precision. */\n"
    << Declarations("double", "") << Declarations("float", "_f") << "\n"
    << "#ifdef __cplusplus\n}\n#endif\n\n#endif /* GRAVCAL_CORRECT_H */\n";
  std::ostringstream c;
  c << head << "#include \"gravcal_correct.h\"\n#include <math.h>\n"
    << "\n#define GRAVCAL_USES_TEMPERATURE "
    << (corrector.RequiresTemperature() || CThermalActive(corrector) ? 1 : 0) << "\n"
    << "#define GRAVCAL_USES_TIME " << (corrector.RequiresTime() ? 1 : 0) << "\n\n";
  WriteFunctions(corrector, false, &c);
  WriteFunctions(corrector, true, &c);
  return {{"gravcal_correct.h", h.str()}, {"gravcal_correct.c", c.str()}};
}

}  // namespace internal
}  // namespace gravcal
