// YAML value readers and printers shared by the config sections.
#include <cmath>
#include <sstream>

#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

std::string DoubleText(double v) {
  if (std::isnan(v)) return "null";
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string ListText(const std::vector<std::string>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + v[i];
  return s + "]";
}

bool ReadDouble(const YAML::Node& n, double* v, std::string* error) {
  if (n.IsNull()) {
    *v = NAN;
    return true;
  }
  try {
    if (!n.IsScalar()) throw YAML::Exception(YAML::Mark::null_mark(), "");
    *v = n.as<double>();
  } catch (const YAML::Exception&) {
    *error = "must be a number";
    return false;
  }
  if (!std::isfinite(*v)) {
    *error = "must be finite";
    return false;
  }
  return true;
}

bool ReadInt(const YAML::Node& n, int* v, std::string* error) {
  try {
    if (!n.IsScalar()) throw YAML::Exception(YAML::Mark::null_mark(), "");
    *v = n.as<int>();
  } catch (const YAML::Exception&) {
    *error = "must be an integer";
    return false;
  }
  return true;
}

bool ReadBool(const YAML::Node& n, bool* v, std::string* error) {
  try {
    if (!n.IsScalar()) throw YAML::Exception(YAML::Mark::null_mark(), "");
    *v = n.as<bool>();
  } catch (const YAML::Exception&) {
    *error = "must be true or false";
    return false;
  }
  return true;
}

bool ReadString(const YAML::Node& n, std::string* v, std::string* error) {
  if (!n.IsScalar()) {
    *error = "must be a string";
    return false;
  }
  *v = n.Scalar();
  return true;
}

bool ReadStringList(const YAML::Node& n, std::vector<std::string>* v, std::string* error) {
  if (n.IsNull()) {
    v->clear();
    return true;
  }
  if (!n.IsSequence()) {
    *error = "must be a list, e.g. [t, ax, ay, az]";
    return false;
  }
  std::vector<std::string> out;
  for (const YAML::Node& e : n) {
    if (!e.IsScalar()) {
      *error = "must be a list of names";
      return false;
    }
    out.push_back(e.Scalar());
  }
  *v = out;
  return true;
}

}  // namespace internal
}  // namespace gravcal
