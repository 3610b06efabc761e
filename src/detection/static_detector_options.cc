// StaticDetectorOptions::IsValid: the detector's options checked before a
// detection (gravcal/detection/static_detector.h).
#include <cmath>
#include <string>

#include "detection/static_detector_internal.h"
#include "gravcal/detection/static_detector.h"

namespace gravcal {

bool StaticDetectorOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = "StaticDetectorOptions: " + what;
    return false;
  };
  if (!(std::isfinite(window_seconds) && window_seconds > 0.0))
    return fail("window_seconds must be positive (got " + internal::DetectorNumber(window_seconds) +
                ")");
  if (!(noise_quantile > 0.0 && noise_quantile < 1.0))
    return fail("noise_quantile must be in (0, 1) (got " +
                internal::DetectorNumber(noise_quantile) + ")");
  if (!(std::isfinite(threshold_factor) && threshold_factor >= 1.0))
    return fail("threshold_factor must be at least 1 (got " +
                internal::DetectorNumber(threshold_factor) + ")");
  if (!(std::isfinite(gyro_threshold_factor) && gyro_threshold_factor >= 1.0))
    return fail("gyro_threshold_factor must be at least 1 (got " +
                internal::DetectorNumber(gyro_threshold_factor) + ")");
  if (!(std::isfinite(max_floor_ratio) && max_floor_ratio >= 0.0))
    return fail("max_floor_ratio must be 0 (off) or positive (got " +
                internal::DetectorNumber(max_floor_ratio) + ")");
  if (!(std::isfinite(min_duration_seconds) && min_duration_seconds >= 0.0))
    return fail("min_duration_seconds must be >= 0 (got " +
                internal::DetectorNumber(min_duration_seconds) + ")");
  if (!(std::isfinite(settle_seconds) && settle_seconds >= 0.0))
    return fail("settle_seconds must be >= 0 (got " + internal::DetectorNumber(settle_seconds) +
                ")");
  if (!(merge_angle_deg >= 0.0 && merge_angle_deg <= 180.0))
    return fail("merge_angle_deg must be in [0, 180] (got " +
                internal::DetectorNumber(merge_angle_deg) + ")");
  if (!(std::isfinite(merge_gap_windows) && merge_gap_windows >= 0.0))
    return fail("merge_gap_windows must be >= 0 (got " +
                internal::DetectorNumber(merge_gap_windows) + ")");
  if (!(std::isfinite(candidate_factor) && candidate_factor >= 1.0))
    return fail("candidate_factor must be at least 1 (got " +
                internal::DetectorNumber(candidate_factor) + ")");
  if (!(std::isfinite(trend_factor) && (trend_factor == 0.0 || trend_factor >= 1.0)))
    return fail("trend_factor must be 0 (off) or at least 1 (got " +
                internal::DetectorNumber(trend_factor) + ")");
  if (!(std::isfinite(spread_factor) && (spread_factor == 0.0 || spread_factor >= 1.0)))
    return fail("spread_factor must be 0 (off) or at least 1 (got " +
                internal::DetectorNumber(spread_factor) + ")");
  if (!(std::isfinite(step_factor) && (step_factor == 0.0 || step_factor >= 1.0)))
    return fail("step_factor must be 0 (off) or at least 1 (got " +
                internal::DetectorNumber(step_factor) + ")");
  if (!(step_min_deg >= 0.0 && step_min_deg <= 180.0))
    return fail("step_min_deg must be in [0, 180] (got " + internal::DetectorNumber(step_min_deg) +
                ")");
  return true;
}

}  // namespace gravcal
