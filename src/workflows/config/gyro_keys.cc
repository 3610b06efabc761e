// Config section "gyro": the gyroscope from the rotations between the
// static poses (GyroCalibrationOptions, gyro_calibration.h).
#include "workflows/config/config_key.h"

namespace gravcal {
namespace internal {

SectionOf<CalibrationConfig> GyroSection() {
  return {"gyro",
          ConfigSectionUse::kSomeMethods,
          {
              GRAVCAL_ENUM("gyro_model", gyro.parameterization,
                           "gyroscope from the rotations between poses (bias has a common "
                           "scale, scale the diagonal, full misalignment too)"),
              GRAVCAL_BOOL("gyro_g_sensitivity", gyro.g_sensitivity,
                           "also estimate the gyroscope g-sensitivity G (rad/s per m/s^2)"),
              GRAVCAL_BOOL("gyro_joint", gyro.joint,
                           "refine the accelerometer's bias and U together with the gyroscope"),
              GRAVCAL_ENUM("gyro_loss", gyro.loss, "robust loss on the gyroscope residuals"),
              GRAVCAL_DOUBLE("gyro_loss_scale", gyro.loss_scale,
                             "gyroscope robust loss scale, in standard deviations"),
              GRAVCAL_DOUBLE("gyro_edge", gyro.edge_seconds,
                             "seconds at each end of a static interval integrated with the "
                             "rotations"),
              GRAVCAL_DOUBLE("gyro_max_rotation", gyro.max_rotation_seconds,
                             "longest gap between poses used as a rotation, s"),
          }};
}

}  // namespace internal
}  // namespace gravcal
