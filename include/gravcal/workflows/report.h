// gravcal/workflows/report.h: the HTML reports a person reads (`--report` of
// calibrate, batch and noise): one self-contained file each, plots as inline
// SVG, nothing fetched from a network. docs/workflows/reports.md says what
// each shows.
//
// - CalibrationToHtml: a verdict in plain words (good / look at these /
//   record again, and why), the raw accelerometer and gyroscope against time
//   with every static interval shaded and numbered (and, given the
//   detection, every stretch the detector rejected, with why), the pose directions on
//   the sphere, per pose the residual |a| - g before, after the coarse fit
//   and after refinement (in sigma, with +-3 sigma bands), the parameters
//   with their standard deviations and where each came from, the
//   correlation matrix, the gyroscope's rotation residuals, the handheld
//   filter's convergence, and every warning with the action that fixes it.
// - FleetToHtml: per parameter a histogram with the median and the robust
//   spread, the outliers with their unit ids and reasons, the failed units
//   with their messages, and the throughput.
// - NoiseToHtml: the Allan deviation of every axis (log-log, confidence
//   bars) with the fitted noise terms as labelled lines.
//
// Long signals are drawn as min/max envelopes: a one-hour 200 Hz session's
// report is a few hundred kilobytes.
#ifndef GRAVCAL_WORKFLOWS_REPORT_H_
#define GRAVCAL_WORKFLOWS_REPORT_H_

#include <string>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/imu_log.h"
#include "gravcal/detection/static_detector.h"
#include "gravcal/estimation/noise_characterisation.h"
#include "gravcal/estimation/recording_plan.h"
#include "gravcal/workflows/fleet_summary.h"

namespace gravcal {

// The calibration of `log` (the log RunCalibration was given, raw units) as
// an HTML page; also for a failed calibration, whose verdict is then
// "record again" with the message. `source` names the log.
std::string CalibrationToHtml(const Calibration& calibration, const ImuLog& log,
                              const std::string& source);

// As above, with the static detection of the same log (DetectStaticIntervals
// with the detector options the calibration used): the stretches it
// rejected are shaded too, each with its reason in the legend and tooltip.
std::string CalibrationToHtml(const Calibration& calibration, const ImuLog& log,
                              const std::string& source, const StaticDetection& detection);

// How fast a batch ran (the batch command measures it).
struct BatchThroughput {
  double elapsed_seconds = 0.0;
  // Units calibrated in this run, and units whose stored result was reused.
  size_t computed = 0;
  size_t skipped = 0;
  // Summed over the computed units (BatchTimings).
  double read_seconds = 0.0;
  double detect_seconds = 0.0;
  double solve_seconds = 0.0;
};

// The fleet of a batch as an HTML page: `rows` are the summary rows the
// statistics were computed from.
std::string FleetToHtml(const FleetStatistics& statistics, const std::vector<SummaryRow>& rows,
                        const BatchThroughput& throughput);

// The noise model of a still log as an HTML page.
std::string NoiseToHtml(const ImuNoise& noise, const std::string& source);

// Issue 15: a recording plan (gravcal plan --report) as an HTML page: the
// poses in order, each as a small picture of the housing lying as it should
// with its instruction and hold, the turn between each two, the up
// directions on the sphere, the predicted standard deviations against the
// targets (accelerometer and, when planned, gyroscope) and the fixed
// schemes' times.
std::string PlanToHtml(const RecordingPlan& plan);

}  // namespace gravcal

#endif  // GRAVCAL_WORKFLOWS_REPORT_H_
