// The handheld Kalman method on a session: the filter's process noise from
// the session's noise model, then the filter (handheld_kalman.cc).
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "core/warnings.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/methods/handheld_kalman.h"

namespace gravcal {
namespace {

// The filter's process noise Q from the noise model: each density not in
// keys_set is the largest of the three axes' values. Returns the note
// saying where Q came from.
std::string NoiseModelQ(const ImuNoiseModel& m, const std::string& model_name,
                        const std::vector<std::string>& keys_set, HandheldKalmanOptions* options) {
  struct Density {
    const char* key;
    const std::array<AxisNoiseModel, 3>* axes;
    NoiseTerm AxisNoiseModel::*term;
    double* field;
  };
  const Density densities[] = {
      {"hk_accel_noise_density", &m.accel, &AxisNoiseModel::white_noise,
       &options->accel_noise_density},
      {"hk_gyro_noise_density", &m.gyro, &AxisNoiseModel::white_noise,
       &options->gyro_noise_density},
      {"hk_accel_bias_walk", &m.accel, &AxisNoiseModel::random_walk, &options->accel_bias_walk},
      {"hk_gyro_bias_walk", &m.gyro, &AxisNoiseModel::random_walk, &options->gyro_bias_walk},
  };
  std::string from_model, from_config, not_shown;
  for (const Density& d : densities) {
    const bool set = std::find(keys_set.begin(), keys_set.end(), d.key) != keys_set.end();
    const double v = AxisMaximum(*d.axes, d.term);
    if (set) {
      from_config += (from_config.empty() ? "" : ", ") + std::string(d.key);
    } else if (std::isfinite(v)) {
      *d.field = v;
      std::ostringstream s;
      s.precision(3);
      s << d.key << " " << v;
      from_model += (from_model.empty() ? "" : ", ") + s.str();
    } else {
      not_shown += (not_shown.empty() ? "" : ", ") + std::string(d.key);
    }
  }
  std::string note = "handheld filter Q: ";
  note += from_model.empty() ? "nothing" : from_model + " (largest axis)";
  note += " from the noise model " + model_name;
  if (!from_config.empty()) note += "; " + from_config + " as set in the config";
  if (!not_shown.empty()) note += "; " + not_shown + " at the default (not shown by the model)";
  return note;
}

}  // namespace

bool CalibrateHandheld(const Session& session, const HandheldKalmanMethodOptions& options,
                       Calibration* calibration) {
  HandheldKalmanOptions filter = options.filter;
  const std::string note = session.noise ? NoiseModelQ(*session.noise, session.noise_name,
                                                       options.noise_keys_set, &filter)
                                         : "";
  const bool ok = CalibrateHandheld(session.log, filter, calibration);
  if (!note.empty()) {
    internal::AddWarning(WarningCode::kNoiseModel, note, &calibration->warnings,
                         &calibration->warning_codes);
  }
  calibration->method = ToString(Method::kHandheldKalman);
  return ok;
}

}  // namespace gravcal
