// estimation/strapdown.h (private): strapdown inertial navigation in a local level frame.
//
// Frames and units:
// - body b: the sensor axes (after calibration);
// - navigation n: local level East-North-Up (z up), origin at the start
//   point, heading defined by the initial attitude (not north-seeking);
// - attitude q_nb (C_nb) rotates body vectors into n; velocity v^n in m/s;
//   position p^n in m relative to the start.
// Gravity is g^n = (0, 0, -g) with g the local value. The specific force is
// f^b = C_nb^T (a^n - g^n): a unit at rest reads +g on the axis that points
// up. The Earth rate w_ie^n = W (0, cos L, sin L) (latitude L) is optional
// and off by default: a consumer MEMS gyroscope's noise over a minute is far
// above 7.3e-5 rad/s.
//
// Mechanisation from sample k-1 to sample k (dt = t_k - t_{k-1}); samples
// are instantaneous values, so the trapezoidal rule is second-order accurate:
//   w   = (w_{k-1} + w_k) / 2
//   q_k = exp(-w_ie^n dt) * q_{k-1} * exp(w dt + w_{k-1} x w_k dt^2 / 12)
//         (rotation vectors; the cross product is the coning term for a
//         rate linear in time)
//   a   = (C_{k-1} f_{k-1} + C_k f_k) / 2 + g^n - 2 w_ie^n x v_{k-1}
//   v_k = v_{k-1} + a dt
//   p_k = p_{k-1} + (v_{k-1} + v_k) dt / 2
// Sculling (rotation during the step acting on the specific force) and
// higher-order coning are neglected.
#ifndef GRAVCAL_SRC_ESTIMATION_STRAPDOWN_H_
#define GRAVCAL_SRC_ESTIMATION_STRAPDOWN_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "gravcal/core/gravity.h"

namespace gravcal {
namespace internal {

struct StrapdownOptions {
  // Local gravity, m/s^2.
  double gravity = kStandardGravity;
  // Include the Earth rate in the attitude and the Coriolis term in the
  // velocity (needs latitude_deg).
  bool earth_rate = false;
  // Geodetic latitude, degrees; only used with earth_rate.
  double latitude_deg = NAN;

  bool IsValid(std::string* error) const;
};

struct NavigationState {
  Eigen::Quaterniond attitude = Eigen::Quaterniond::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
};

// What the error model of one step needs (see handheld_kalman.h): values at
// the middle of the step.
struct StrapdownStep {
  double dt = 0.0;
  // C_nb at mid-step.
  Eigen::Matrix3d attitude_mid = Eigen::Matrix3d::Identity();
  // Body specific force and rate averaged over the step.
  Eigen::Vector3d specific_force_mid = Eigen::Vector3d::Zero();
  Eigen::Vector3d rate_mid = Eigen::Vector3d::Zero();
};

// The rotation exp([v x]) of the rotation vector v (axis * angle, rad).
Eigen::Quaterniond RotationVectorToQuaternion(const Eigen::Vector3d& v);

// The Earth rate in the navigation frame (East-North-Up), rad/s.
Eigen::Vector3d EarthRateEnu(double latitude_deg);

// Coarse levelling: the attitude with zero heading whose body frame sees the
// mean specific force `f` (body, any scale, not zero) pointing up:
//   roll = atan2(f_y, f_z), pitch = atan2(-f_x, sqrt(f_y^2 + f_z^2)),
//   C_nb = R_z(0) R_y(pitch) R_x(roll).
// The tilt is only as good as the accelerometer: a bias b on a horizontal
// axis tilts the result by about b / g.
Eigen::Quaterniond LevelAttitude(const Eigen::Vector3d& f);

// The mechanisation above. Holds the navigation state; the inputs are
// already-corrected body specific force (m/s^2) and rate (rad/s).
class Strapdown {
 public:
  explicit Strapdown(const StrapdownOptions& options,
                     const NavigationState& initial = NavigationState());

  // Advances from the previous sample (f0, w0) to the current one (f1, w1)
  // over dt > 0 seconds. Fills `step` when not null.
  void Step(double dt, const Eigen::Vector3d& f0, const Eigen::Vector3d& w0,
            const Eigen::Vector3d& f1, const Eigen::Vector3d& w1, StrapdownStep* step);

  const NavigationState& state() const { return state_; }
  // For corrections from outside (the Kalman filter's feedback).
  void SetState(const NavigationState& state);
  // C_nb of the current state.
  const Eigen::Matrix3d& attitude_matrix() const { return c_nb_; }
  // w_ie^n, zero when the Earth rate is off.
  const Eigen::Vector3d& earth_rate() const { return earth_rate_; }
  const Eigen::Vector3d& gravity_vector() const { return gravity_; }

 private:
  NavigationState state_;
  Eigen::Matrix3d c_nb_;
  Eigen::Vector3d earth_rate_;
  Eigen::Vector3d gravity_;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_ESTIMATION_STRAPDOWN_H_
