// Config section "alignment": the ten-position method's static alignment
// (TenPositionOptions, ten_position.h) and the raw gyroscope unit it shares
// with the handheld Kalman filter.
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

namespace {

bool ReadGyroNominalScale(const YAML::Node& n, CalibrationConfig* c, std::string* e) {
  double v = 0.0;
  if (!ReadDouble(n, &v, e)) return false;
  c->ten_position.gyro_nominal_scale = v;
  c->handheld.gyro_nominal_scale = v;
  return true;
}

}  // namespace

SectionOf<CalibrationConfig> AlignmentSection() {
  return {
      "alignment",
      ConfigSectionUse::kSomeMethods,
      {
          GRAVCAL_DOUBLE("align_accel_bias_std", ten_position.alignment.accel_bias_std,
                         "prior of the accelerometer bias the static base cannot see, m/s^2"),
          GRAVCAL_DOUBLE("align_accel_matrix_std", ten_position.alignment.accel_matrix_std,
                         "prior of each scale/misalignment error entry (seen as a bias dM f)"),
          GRAVCAL_DOUBLE("align_gyro_bias_std", ten_position.alignment.gyro_bias_std,
                         "prior of the gyroscope bias, rad/s (decides gyrocompassing)"),
          GRAVCAL_DOUBLE("align_max_heading_std", ten_position.alignment.max_heading_std_deg,
                         "gyrocompass only when heading would be better than this, degrees"),
          GRAVCAL_DOUBLE("align_coarse_seconds", ten_position.alignment.coarse_seconds,
                         "coarse alignment window at the start of each position, s"),
          GRAVCAL_DOUBLE("align_zero_velocity_std", ten_position.alignment.zero_velocity_std,
                         "zero-velocity measurement standard deviation, m/s"),
          GRAVCAL_BOOL("align_use_gyro", ten_position.alignment.use_gyro,
                       "use the gyroscope in the alignment when the log has one"),
          GRAVCAL_KEY_AT("gyro_nominal_scale",
                         "rad/s per raw gyroscope unit before calibration (1 = rad/s, 0.0174533 = "
                         "deg/s), for the alignment, the handheld Kalman filter and, without a "
                         "gyroscope model, the holds' gyroscope noise (acceptance limits)",
                         ReadGyroNominalScale(n, c, e), DoubleText(c.handheld.gyro_nominal_scale),
                         &c.ten_position.gyro_nominal_scale, &c.handheld.gyro_nominal_scale),
      }};
}

}  // namespace internal
}  // namespace gravcal
