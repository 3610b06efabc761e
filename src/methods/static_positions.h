// Private: the front end shared by the methods and workflows that start
// from a raw log (twelve_position, ten_position, known_attitude, discovery):
// log checked and static intervals detected; for the attitude-based methods
// also options checked, local gravity resolved and positions formed; and
// the position reports.
#ifndef GRAVCAL_SRC_METHODS_STATIC_POSITIONS_H_
#define GRAVCAL_SRC_METHODS_STATIC_POSITIONS_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/imu_log.h"
#include "gravcal/core/position.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/methods/session.h"
#include "gravcal/methods/twelve_position.h"

namespace gravcal {
namespace internal {

// Checks the log and detects its static intervals. Returns false with
// detection->message on an invalid log or a detector failure (naming
// log.source).
bool DetectLog(const ImuLog& log, const StaticDetectorOptions& detector,
               StaticDetection* detection);

// Checks the log and detects its static intervals. Returns false with
// *message on an invalid log or a detector failure (naming log.source).
// *warnings (when not null) gets the detector's warnings and the log's
// saturated axes (core/sensor_checks.h), each prefixed by log.source.
bool DetectLogIntervals(const ImuLog& log, const StaticDetectorOptions& detector,
                        std::vector<StaticInterval>* intervals, std::string* message,
                        std::vector<std::string>* warnings = nullptr);

// Same on a session: its detection when it has one (DetectSessionPoses),
// else detected now with `detector`.
bool SessionIntervals(const Session& session, const StaticDetectorOptions& detector,
                      std::vector<StaticInterval>* intervals, std::string* message,
                      std::vector<std::string>* warnings = nullptr);

// The positions of the intervals with the covariance of each mean chosen by
// options.pose_noise (pose_mean_covariance.h); *notes gets its fallbacks and
// warnings. False with *message only on invalid pose-noise options.
bool PosesFromIntervals(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                        const CalibrationOptions& options, std::vector<Position>* positions,
                        std::vector<std::string>* notes, std::string* message);

// Checks the options, then as SessionIntervals and PosesFromIntervals (notes
// into calibration->warnings); also fills calibration->gravity,
// gravity_source (and the standard-gravity warning). Returns false with
// calibration->message (naming log.source) on invalid options or log, or a
// detector failure.
bool DetectStaticPositions(const Session& session, const CalibrationOptions& options,
                           Calibration* calibration, std::vector<StaticInterval>* intervals,
                           std::vector<Position>* positions);

// CalibrateAccelerometer (twelve_position.h) on a session: its detection
// when it has one.
bool CalibrateAccelerometer(const Session& session, const CalibrationOptions& options,
                            Calibration* calibration, std::vector<StaticInterval>* intervals);

// Samples [begin, end) of the log, times `scale`; `rate` gets the gyroscope
// times `gyro_scale` (empty without one). Returns the mean sample period.
double IntervalSamples(const ImuLog& log, const StaticInterval& interval, double scale,
                       double gyro_scale, std::vector<Eigen::Vector3d>* force,
                       std::vector<Eigen::Vector3d>* rate);

// The report of one position: its noise per sample, nominal axis,
// residuals |a| - g before and after, and sigma.
PositionReport MakePositionReport(const Position& position, double before, double after,
                                  double sigma);

// One PositionReport per position, with residuals |a| - g before (nominal)
// and after (final) and the given sigmas.
void ReportPositions(const std::vector<Position>& positions, const AccelModel& nominal,
                     const AccelModel& final_model, double gravity,
                     const std::vector<double>& sigmas, Calibration* calibration);

// Fills each position's gyro_std (core/calibration.h) from the log's
// gyroscope samples in the hold (times t_begin to t_end, at most
// sample_count of them): through calibration->gyro.model.matrix when the
// gyroscope was estimated, else through `nominal_scale` (rad/s per raw
// unit) when it is positive; left NaN otherwise, or without a gyroscope.
void MeasureGyroHoldNoise(const ImuLog& log, double nominal_scale, Calibration* calibration);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_METHODS_STATIC_POSITIONS_H_
