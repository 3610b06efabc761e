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

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_IO_JSON_HELPERS_H_
