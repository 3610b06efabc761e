#include "methods/gyro_bias_wander.h"

#include <Eigen/LU>
#include <cmath>
#include <sstream>

#include "core/noise_flicker.h"
#include "core/warnings.h"
#include "gravcal/core/noise_model.h"

namespace gravcal {
namespace internal {
namespace {

// B^2 + K^2 T / 3 of one axis, (rad/s)^2 (gyro_bias_wander.h); NaN when the
// axis shows neither term. B^2 is the flicker's alone: a B read at the Allan
// curve's floor (with a tau) still holds the white noise's and the random
// walk's share there, which internal::FlickerAllanVariance (core/noise_flicker.h) takes off,
// as the model's Allan variance does; otherwise the random walk would be
// counted twice (once in B, once in K^2 T / 3).
double ModelWander(const AxisNoiseModel& axis, double seconds) {
  double v = 0.0;
  bool shown = false;
  if (axis.bias_instability.visible()) {
    v += FlickerAllanVariance(axis) / kFlickerAllanFactor;
    shown = true;
  }
  if (axis.random_walk.visible()) {
    v += axis.random_walk.value * axis.random_walk.value * seconds / 3.0;
    shown = true;
  }
  return shown ? v : NAN;
}

// The kNoiseModel warning of the header: hand-placed poses without a
// noise model. `sized`: the poses' scatter gave W.
void WarnWithoutNoiseModel(const GyroCalibrationOptions& options, bool sized,
                           GyroCalibrationResult* r) {
  if (options.noise_model != nullptr || !options.estimate_static_variance) return;
  std::ostringstream s;
  s << "no noise model (--noise): the gyroscope's standard deviations assume white noise, and "
       "its bias's wander over the session is counted ";
  if (sized) {
    s << "only as " << kWanderPerScatter << " times the static poses' scatter";
  } else {
    s << "not at all (the static poses show no scatter beyond their white noise)";
  }
  s << "; one session cannot size it, and the bias's sigma is then too small by 10-30 % "
       "(simulated hand-placed sessions); record a still log, run `gravcal noise` and pass "
       "--noise";
  AddWarning(WarningCode::kNoiseModel, s.str(), &r->warnings, &r->warning_codes);
}

}  // namespace

bool SessionBiasWander(const GyroPrepared& prep, const GyroCalibrationOptions& options,
                       const Eigen::Matrix3d& matrix, Eigen::Matrix3d* wander, std::string* note) {
  const double seconds = prep.session_seconds;
  std::ostringstream s;
  s.precision(3);
  const Eigen::Matrix3d inverse = matrix.inverse();
  if (options.noise_model != nullptr) {
    Eigen::Vector3d v;
    for (int a = 0; a < 3; ++a) v(a) = ModelWander(options.noise_model->gyro[a], seconds);
    if (v.allFinite()) {
      *wander = inverse * v.asDiagonal() * inverse.transpose();
      s << "bias wander over the session's " << seconds
        << " s from the noise model (B^2 + K^2 T / 3): " << v.cwiseSqrt().transpose()
        << " rad/s per axis, added to the bias's covariance";
      *note = s.str();
      return true;
    }
    s << "the noise model shows neither bias instability nor random walk on every gyroscope "
         "axis; ";
  }
  if (prep.static_variance > 0.0) {
    // Normalised u' = (u - c) k: raw variance s^2 / k^2 per axis.
    const double raw = prep.static_variance / (prep.scale * prep.scale);
    *wander = kWanderPerScatter * raw * Eigen::Matrix3d::Identity();
    const Eigen::Vector3d si =
        (matrix * matrix.transpose()).diagonal().cwiseSqrt() * std::sqrt(kWanderPerScatter * raw);
    s << "bias wander over the session's " << seconds << " s from the static poses' scatter ("
      << kWanderPerScatter << " s^2 as for a random walk, s^2 on " << prep.static_variance_dof
      << " dof): " << si.transpose()
      << " rad/s per axis, added to the bias's covariance (a noise model, --noise, measures it "
         "over longer times)";
    *note = s.str();
    return true;
  }
  s << "no bias wander accounted for (no noise model, and the static poses show no scatter "
       "beyond their white noise)";
  *note = s.str();
  return false;
}

void AddSessionBiasWander(const GyroPrepared& prep, const GyroCalibrationOptions& options,
                          GyroCalibrationResult* result) {
  GyroCalibrationResult& r = *result;
  if (!r.covariance_available) return;
  Eigen::Matrix3d wander;
  const bool sized = SessionBiasWander(prep, options, r.model.matrix, &wander, &r.bias_wander_note);
  WarnWithoutNoiseModel(options, sized, &r);
  if (!sized) return;
  int rows[3] = {-1, -1, -1};
  for (size_t i = 0; i < r.parameter_names.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      if (r.parameter_names[i] == std::string("bias_") + "xyz"[a]) rows[a] = static_cast<int>(i);
    }
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      if (rows[a] >= 0 && rows[b] >= 0) r.covariance(rows[a], rows[b]) += wander(a, b);
    }
    r.bias_wander_std(a) = std::sqrt(wander(a, a));
    r.bias_std(a) = std::sqrt(r.bias_std(a) * r.bias_std(a) + wander(a, a));
  }
}

}  // namespace internal
}  // namespace gravcal
