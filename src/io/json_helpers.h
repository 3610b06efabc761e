// io/json_helpers.h (private): numbers, vectors and matrices as JSON, the
// same way in every file the library writes. A value that is not finite (an
// undetermined parameter, a missing standard deviation) becomes null, never
// NaN, which JSON cannot hold. `Json` is nlohmann::json or
// nlohmann::ordered_json, whichever the caller builds.
#ifndef GRAVCAL_IO_JSON_HELPERS_H_
#define GRAVCAL_IO_JSON_HELPERS_H_

#include <Eigen/Core>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace gravcal {
namespace internal {

// v, or null when v is not finite.
template <typename Json = nlohmann::json>
Json JsonNumber(double v) {
  return std::isfinite(v) ? Json(v) : Json(nullptr);
}

// [v0, v1, ...], each through JsonNumber.
template <typename Json = nlohmann::json>
Json JsonArray(const std::vector<double>& values) {
  Json out = Json::array();
  for (double v : values) out.push_back(JsonNumber<Json>(v));
  return out;
}

// [x, y, z], each through JsonNumber.
template <typename Json = nlohmann::json>
Json JsonVector(const Eigen::Vector3d& v) {
  return Json::array({JsonNumber<Json>(v(0)), JsonNumber<Json>(v(1)), JsonNumber<Json>(v(2))});
}

// Row-major nested arrays [[m00, m01, ...], [m10, ...], ...].
template <typename Json = nlohmann::json, typename Derived>
Json JsonMatrix(const Eigen::MatrixBase<Derived>& m) {
  Json rows = Json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    Json row = Json::array();
    for (Eigen::Index c = 0; c < m.cols(); ++c) row.push_back(JsonNumber<Json>(m(r, c)));
    rows.push_back(row);
  }
  return rows;
}

// The first key that an object of the JSON `text` holds twice, as its path
// ("accel", "poses[].up"), or "" when none (also when `text` is not JSON:
// the parser says so). nlohmann keeps one of the two silently; a file must
// say what it means once, as a config must.
inline std::string DuplicateJsonKey(const std::string& text) {
  struct Frame {
    bool object;
    std::set<std::string> keys;
    std::string key;  // the key being read (objects)
  };
  std::vector<Frame> frames;
  std::string duplicate;
  auto path = [&frames]() {
    std::string p;
    for (const Frame& f : frames) {
      if (f.object) {
        if (!f.key.empty()) p += (p.empty() ? "" : ".") + f.key;
      } else {
        p += "[]";
      }
    }
    return p;
  };
  nlohmann::json::parser_callback_t callback = [&](int, nlohmann::json::parse_event_t event,
                                                   nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start || event == Event::array_start) {
      frames.push_back({event == Event::object_start, {}, ""});
    } else if ((event == Event::object_end || event == Event::array_end) && !frames.empty()) {
      frames.pop_back();
    } else if (event == Event::key && !frames.empty() && parsed.is_string()) {
      Frame& top = frames.back();
      top.key = parsed.get<std::string>();
      if (!top.keys.insert(top.key).second && duplicate.empty()) duplicate = path();
    }
    return true;
  };
  const nlohmann::json whole = nlohmann::json::parse(text, callback, false);
  static_cast<void>(whole);
  return duplicate;
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_IO_JSON_HELPERS_H_
