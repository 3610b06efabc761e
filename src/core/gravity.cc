#include "gravcal/core/gravity.h"

#include <cstdio>

#include "util/units.h"

namespace gravcal {
namespace {

// WGS84 defining and derived constants.
constexpr double kEquatorialGravity = 9.7803253359;  // m/s^2
constexpr double kSomiglianaK = 0.00193185265241;    // (b g_p)/(a g_e) - 1
constexpr double kFirstEccentricitySq = 0.00669437999013;
constexpr double kSemiMajorAxis = 6378137.0;  // m
constexpr double kFlattening = 1.0 / 298.257223563;
constexpr double kGravityRatio = 0.00344978650684;  // omega^2 a^2 b / GM

}  // namespace

double NormalGravity(double latitude_deg, double height_m) {
  const double s = std::sin(latitude_deg * internal::kDegToRad);
  const double s2 = s * s;
  const double g0 =
      kEquatorialGravity * (1.0 + kSomiglianaK * s2) / std::sqrt(1.0 - kFirstEccentricitySq * s2);
  // Second-order expansion in height (NIMA TR8350.2, eq. 4-3).
  const double h = height_m;
  return g0 *
         (1.0 -
          2.0 / kSemiMajorAxis * (1.0 + kFlattening + kGravityRatio - 2.0 * kFlattening * s2) * h +
          3.0 * h * h / (kSemiMajorAxis * kSemiMajorAxis));
}

bool GravityOptions::IsValid(std::string* error) const {
  if (!std::isfinite(gravity) || gravity < 0.0 ||
      (gravity > 0.0 && (gravity < 9.7 || gravity > 9.9))) {
    *error = "gravity: must be a local value between 9.7 and 9.9 m/s^2 (or 0 to not give one)";
    return false;
  }
  if (!std::isnan(latitude) && (!std::isfinite(latitude) || std::fabs(latitude) > 90.0)) {
    *error = "latitude: must be between -90 and 90 degrees";
    return false;
  }
  if (!std::isfinite(height) || height < -500.0 || height > 20000.0) {
    *error = "height: must be between -500 and 20000 m";
    return false;
  }
  return true;
}

bool ResolveGravity(const GravityOptions& options, double* gravity, std::string* source,
                    std::string* error) {
  if (!options.IsValid(error)) return false;
  char buffer[128];
  if (options.gravity > 0.0) {
    *gravity = options.gravity;
    *source = "given";
  } else if (std::isfinite(options.latitude)) {
    *gravity = NormalGravity(options.latitude, options.height);
    std::snprintf(buffer, sizeof(buffer), "normal gravity at latitude %.4f deg, height %.1f m",
                  options.latitude, options.height);
    *source = buffer;
  } else {
    *gravity = kStandardGravity;
    *source = "standard";
  }
  return true;
}

}  // namespace gravcal
