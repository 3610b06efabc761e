// YAML value readers and printers shared by the config sections.
#include <algorithm>
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
  std::vector<std::string> out;
  // A scalar with commas is the list written as on a command line
  // (--columns t,ax,ay,az): its names, split at the commas.
  if (n.IsScalar() && n.Scalar().find(',') != std::string::npos) {
    const std::string& text = n.Scalar();
    for (size_t from = 0;;) {
      const size_t comma = std::min(text.find(',', from), text.size());
      const size_t first = text.find_first_not_of(" \t", from);
      const size_t last = text.find_last_not_of(" \t", comma == 0 ? 0 : comma - 1);
      if (first >= comma || last == std::string::npos || last < first) {
        *error =
            "must be a list of names, e.g. [t, ax, ay, az] or t,ax,ay,az (an empty name at "
            "character " +
            std::to_string(from + 1) + ")";
        return false;
      }
      out.push_back(text.substr(first, last - first + 1));
      if (comma == text.size()) break;
      from = comma + 1;
    }
    *v = out;
    return true;
  }
  if (!n.IsSequence()) {
    *error = "must be a list, e.g. [t, ax, ay, az] (or t,ax,ay,az)";
    return false;
  }
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
