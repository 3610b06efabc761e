// gravcal/core/gravity.h: the local value of gravity.
//
// Calibration scales the accelerometer so that a unit at rest reads the local
// gravity g. The standard value 9.80665 m/s^2 is wrong by up to 0.3 % between
// the equator and the poles, which goes straight into the scale factors, so
// use the local value: one you measured, or normal gravity from latitude and
// height (WGS84 Somigliana formula with the second-order height correction),
// good to about 1e-4 relative away from strong anomalies.
#ifndef GRAVCAL_CORE_GRAVITY_H_
#define GRAVCAL_CORE_GRAVITY_H_

#include <cmath>
#include <string>

namespace gravcal {

constexpr double kStandardGravity = 9.80665;
// Earth rotation rate, rad/s (WGS84: 7.292115e-5; the IERS value below).
constexpr double kEarthRate = 7.2921151467e-5;

// Normal gravity in m/s^2 at geodetic latitude (degrees, -90..90) and
// ellipsoidal height (metres).
double NormalGravity(double latitude_deg, double height_m);

struct GravityOptions {
  // A measured local value in m/s^2; used when > 0.
  double gravity = 0.0;
  // Geodetic latitude in degrees; used when finite and gravity is not given.
  double latitude = NAN;
  // Height above the ellipsoid, metres (only with latitude).
  double height = 0.0;

  bool IsValid(std::string* error) const;
};

// Chooses the value: gravity if given, else normal gravity from latitude and
// height, else the standard value. `source` says which ("given", "normal
// gravity at latitude 45.4 deg, height 20 m", "standard") so it can be
// reported; the standard value is worth a warning.
bool ResolveGravity(const GravityOptions& options, double* gravity, std::string* source,
                    std::string* error);

}  // namespace gravcal

#endif  // GRAVCAL_CORE_GRAVITY_H_
