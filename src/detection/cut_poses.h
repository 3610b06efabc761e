// Poses published with the motion cut out (issue 33): holds that touch with
// a step and nothing between, often shorter than a hand-placed session's.
#ifndef GRAVCAL_DETECTION_CUT_POSES_H_
#define GRAVCAL_DETECTION_CUT_POSES_H_

#include <string>

#include "gravcal/core/imu_log.h"
#include "gravcal/detection/static_detector.h"

namespace gravcal {
namespace internal {

// When `log` is poses published with the motion cut out and its holds are
// too short for `options` to keep one, shrinks the detector's time scales
// to the holds. The log is such poses when its accelerometer changes from
// one sample to the next by more than kCutPoseJumpFactor times the median
// change (squared norms) only at isolated single samples: at least
// kCutPoseMinSteps such steps, and at least kCutPoseIsolatedFraction of all
// the large changes (a motion makes runs of them). A hold is the median
// spacing of the steps (L seconds, `dt` the median time step); it is too
// short when L - 2 settle < min_duration or L < 2 windows. Then window =
// 0.3 L, min_duration = 0.5 L, settle = 0.05 L (each only ever shortened)
// and threshold_factor is at least kCutPoseThresholdFactor: with no motion
// in the log, the variance threshold has nothing to reject and would only
// drop the noisier holds; the steps alone separate them (the step split).
// Measured on ../shared/data/real: ck_explorer_poses 155 isolated steps of
// 155 large changes; every other recording at most 57 % isolated.
// Returns what it changed, in words ("" when nothing).
std::string FitToCutPoses(const ImuLog& log, double dt, StaticDetectorOptions* options);

constexpr double kCutPoseJumpFactor = 100.0;
constexpr int kCutPoseMinSteps = 10;
constexpr double kCutPoseIsolatedFraction = 0.9;
constexpr double kCutPoseThresholdFactor = 1000.0;
// Holds shorter than this many samples are not fitted (too few for a window).
constexpr int kCutPoseMinHoldSamples = 20;

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_DETECTION_CUT_POSES_H_
