// Private: the start shared by the attitude-based methods (ten_position,
// known_attitude): options and log checked, local gravity resolved, static
// intervals detected.
#ifndef GRAVCAL_SRC_METHODS_STATIC_POSITIONS_H_
#define GRAVCAL_SRC_METHODS_STATIC_POSITIONS_H_

#include <Eigen/Core>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/position.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {

// Fills calibration->gravity, gravity_source (and the standard-gravity
// warning). Returns false with calibration->message (naming log.source) on
// invalid options or log, or a detector failure.
bool DetectStaticPositions(const ImuLog& log, const CalibrationOptions& options,
                           Calibration* calibration, std::vector<StaticInterval>* intervals,
                           std::vector<Position>* positions);

// Samples [begin, end) of the log, times `scale`; `rate` gets the gyroscope
// times `gyro_scale` (empty without one). Returns the mean sample period.
double IntervalSamples(const ImuLog& log, const StaticInterval& interval, double scale,
                       double gyro_scale, std::vector<Eigen::Vector3d>* force,
                       std::vector<Eigen::Vector3d>* rate);

// One PositionReport per position, with residuals |a| - g before (nominal)
// and after (final) and the given sigmas.
void ReportPositions(const std::vector<Position>& positions, const AccelModel& nominal,
                     const AccelModel& final_model, double gravity,
                     const std::vector<double>& sigmas, Calibration* calibration);

}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_STATIC_POSITIONS_H_
