#include "estimation/strapdown.h"

#include "util/units.h"

namespace gravcal {
namespace internal {

bool StrapdownOptions::IsValid(std::string* error) const {
  if (!(std::isfinite(gravity) && gravity > 0.0)) {
    *error = "strapdown: gravity must be positive";
    return false;
  }
  if (earth_rate && !(std::isfinite(latitude_deg) && std::fabs(latitude_deg) <= 90.0)) {
    *error = "strapdown: the Earth rate needs a latitude in [-90, 90] degrees (key 'latitude')";
    return false;
  }
  return true;
}

Eigen::Quaterniond RotationVectorToQuaternion(const Eigen::Vector3d& v) {
  const double angle2 = v.squaredNorm();
  double real, factor;
  if (angle2 < 1e-12) {
    // Taylor series to fourth order in the angle: cos(a/2), sin(a/2)/a.
    real = 1.0 - angle2 / 8.0 + angle2 * angle2 / 384.0;
    factor = 0.5 - angle2 / 48.0;
  } else {
    const double angle = std::sqrt(angle2);
    real = std::cos(0.5 * angle);
    factor = std::sin(0.5 * angle) / angle;
  }
  return Eigen::Quaterniond(real, factor * v.x(), factor * v.y(), factor * v.z());
}

Eigen::Vector3d EarthRateEnu(double latitude_deg) {
  const double lat = latitude_deg * internal::kDegToRad;
  return kEarthRate * Eigen::Vector3d(0.0, std::cos(lat), std::sin(lat));
}

Eigen::Quaterniond LevelAttitude(const Eigen::Vector3d& f) {
  const double roll = std::atan2(f.y(), f.z());
  const double pitch = std::atan2(-f.x(), std::hypot(f.y(), f.z()));
  return Eigen::Quaterniond(Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
}

Strapdown::Strapdown(const StrapdownOptions& options, const NavigationState& initial)
    : earth_rate_(options.earth_rate ? EarthRateEnu(options.latitude_deg)
                                     : Eigen::Vector3d::Zero()),
      gravity_(0.0, 0.0, -options.gravity) {
  SetState(initial);
}

void Strapdown::SetState(const NavigationState& state) {
  state_ = state;
  state_.attitude.normalize();
  c_nb_ = state_.attitude.toRotationMatrix();
}

void Strapdown::Step(double dt, const Eigen::Vector3d& f0, const Eigen::Vector3d& w0,
                     const Eigen::Vector3d& f1, const Eigen::Vector3d& w1, StrapdownStep* step) {
  const Eigen::Vector3d w = 0.5 * (w0 + w1);
  const Eigen::Matrix3d c0 = c_nb_;
  // Rotation vector of the step for a rate linear in time (Bortz equation to
  // second order): the mean rate plus the coning term w0 x w1 dt^2 / 12.
  const Eigen::Vector3d rotation = w * dt + (dt * dt / 12.0) * w0.cross(w1);
  Eigen::Quaterniond q = state_.attitude * RotationVectorToQuaternion(rotation);
  if (step != nullptr) {
    const Eigen::Quaterniond mid = state_.attitude * RotationVectorToQuaternion(0.5 * dt * w);
    step->dt = dt;
    step->attitude_mid = mid.toRotationMatrix();
    step->specific_force_mid = 0.5 * (f0 + f1);
    step->rate_mid = w;
  }
  const bool rotating_earth =
      earth_rate_.x() != 0.0 || earth_rate_.y() != 0.0 || earth_rate_.z() != 0.0;
  if (rotating_earth) q = RotationVectorToQuaternion(-dt * earth_rate_) * q;
  // Keep |q| = 1 against round-off.
  q.normalize();
  state_.attitude = q;
  c_nb_ = q.toRotationMatrix();
  Eigen::Vector3d a = 0.5 * (c0 * f0 + c_nb_ * f1) + gravity_;
  if (rotating_earth) a -= 2.0 * earth_rate_.cross(state_.velocity);
  const Eigen::Vector3d v0 = state_.velocity;
  state_.velocity += a * dt;
  state_.position += 0.5 * dt * (v0 + state_.velocity);
}

}  // namespace internal
}  // namespace gravcal
