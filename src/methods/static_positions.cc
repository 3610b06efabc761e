#include "methods/static_positions.h"

#include <algorithm>
#include <cmath>

#include "core/calibration_gravity.h"
#include "core/sensor_checks.h"
#include "core/warnings.h"
#include "gravcal/estimation/refinement.h"
#include "util/source_prefix.h"
#include "util/statistics.h"

namespace gravcal {
namespace internal {

bool DetectLog(const ImuLog& log, const StaticDetectorOptions& detector,
               StaticDetection* detection) {
  if (!log.Validate(&detection->message)) return false;
  if (!DetectStaticIntervals(log, detector, detection)) {
    detection->message = internal::PrefixSource(log.source, detection->message);
    return false;
  }
  return true;
}

namespace {

// The intervals and warnings of a detection of `log` (done or failed).
bool TakeIntervals(const ImuLog& log, const StaticDetection& detection, bool ok,
                   std::vector<StaticInterval>* intervals, std::string* message,
                   std::vector<std::string>* warnings) {
  if (!ok) {
    *message = detection.message;
    return false;
  }
  *intervals = detection.intervals;
  if (warnings != nullptr) {
    for (const std::string& w : SaturationWarnings(log)) {
      warnings->push_back(internal::PrefixSource(log.source, w));
    }
    for (const std::string& w : detection.warnings) {
      warnings->push_back(internal::PrefixSource(log.source, w));
    }
  }
  return true;
}

}  // namespace

bool DetectLogIntervals(const ImuLog& log, const StaticDetectorOptions& detector,
                        std::vector<StaticInterval>* intervals, std::string* message,
                        std::vector<std::string>* warnings) {
  StaticDetection detection;
  const bool ok = DetectLog(log, detector, &detection);
  return TakeIntervals(log, detection, ok, intervals, message, warnings);
}

bool SessionIntervals(const Session& session, const StaticDetectorOptions& detector,
                      std::vector<StaticInterval>* intervals, std::string* message,
                      std::vector<std::string>* warnings) {
  if (!session.detected) {
    return DetectLogIntervals(session.log, detector, intervals, message, warnings);
  }
  return TakeIntervals(session.log, session.detection, session.detection_ok, intervals, message,
                       warnings);
}

bool DetectStaticPositions(const Session& session, const CalibrationOptions& options,
                           Calibration* calibration, std::vector<StaticInterval>* intervals,
                           std::vector<Position>* positions) {
  Calibration& c = *calibration;
  if (!options.IsValid(&c.message)) return false;
  if (!ResolveCalibrationGravity(options.gravity, calibration)) return false;
  std::vector<std::string> data_warnings;
  if (!SessionIntervals(session, options.detector, intervals, &c.message, &data_warnings)) {
    return false;
  }
  for (const std::string& w : data_warnings) {
    AddWarning(WarningCode::kSensorData, w, &c.warnings, &c.warning_codes);
  }
  const bool ok =
      PosesFromIntervals(session.log, *intervals, options, positions, &c.warnings, &c.message);
  CodeNewWarnings(WarningCode::kNoiseModel, c.warnings, &c.warning_codes);
  return ok;
}

bool PosesFromIntervals(const ImuLog& log, const std::vector<StaticInterval>& intervals,
                        const CalibrationOptions& options, std::vector<Position>* positions,
                        std::vector<std::string>* notes, std::string* message) {
  *positions = PositionsFromIntervals(intervals);
  return SetPoseMeanCovariance(log, intervals, options.pose_noise, positions, notes, message);
}

double IntervalSamples(const ImuLog& log, const StaticInterval& interval, double scale,
                       double gyro_scale, std::vector<Eigen::Vector3d>* force,
                       std::vector<Eigen::Vector3d>* rate) {
  force->clear();
  rate->clear();
  for (size_t i = interval.begin; i < interval.end; ++i) {
    force->push_back(scale * log.accel[i]);
    if (log.has_gyro()) rate->push_back(gyro_scale * log.gyro[i]);
  }
  const size_t n = interval.end - interval.begin;
  return n > 1 ? (log.t[interval.end - 1] - log.t[interval.begin]) / static_cast<double>(n - 1)
               : 0.0;
}

PositionReport MakePositionReport(const Position& position, double before, double after,
                                  double sigma) {
  PositionReport r;
  r.position = position;
  const double n = static_cast<double>(std::max<size_t>(position.sample_count, 1));
  r.raw_std = (position.raw_mean_cov.diagonal() * n).cwiseSqrt();
  r.nominal_up = position.nominal_up;
  r.residual_before = before;
  r.residual_after = after;
  r.sigma = sigma;
  return r;
}

void ReportPositions(const std::vector<Position>& positions, const AccelModel& nominal,
                     const AccelModel& final_model, double gravity,
                     const std::vector<double>& sigmas, Calibration* calibration) {
  Calibration& c = *calibration;
  const std::vector<double> before = MagnitudeResiduals(positions, nominal, gravity);
  // The final model may have a rotation: |a| uses the full matrix.
  std::vector<double> after(positions.size());
  for (size_t k = 0; k < positions.size(); ++k) {
    after[k] = final_model.Apply(positions[k].raw_mean).norm() - gravity;
  }
  c.residual_nominal = {Rms(before), MaxAbs(before)};
  c.residual_refined = {Rms(after), MaxAbs(after)};
  c.positions.clear();
  for (size_t k = 0; k < positions.size(); ++k) {
    c.positions.push_back(
        MakePositionReport(positions[k], before[k], after[k], k < sigmas.size() ? sigmas[k] : NAN));
    c.positions.back().residual_nominal = before[k];
  }
}

void MeasureGyroHoldNoise(const ImuLog& log, double nominal_scale, Calibration* calibration) {
  Calibration& c = *calibration;
  if (!log.has_gyro()) return;
  Eigen::Matrix3d m;
  if (c.gyro.estimated) {
    m = c.gyro.model.matrix;
  } else if (std::isfinite(nominal_scale) && nominal_scale > 0.0) {
    m = nominal_scale * Eigen::Matrix3d::Identity();
  } else {
    return;
  }
  for (PositionReport& r : c.positions) {
    const Position& p = r.position;
    if (!std::isfinite(p.t_begin) || !std::isfinite(p.t_end)) continue;
    const auto first = std::lower_bound(log.t.begin(), log.t.end(), p.t_begin);
    auto last = std::upper_bound(first, log.t.end(), p.t_end);
    if (p.sample_count > 0 && static_cast<size_t>(last - first) > p.sample_count) {
      last = first + static_cast<std::ptrdiff_t>(p.sample_count);
    }
    const size_t begin = first - log.t.begin(), end = last - log.t.begin();
    if (end < begin + 2) continue;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (size_t i = begin; i < end; ++i) mean += log.gyro[i];
    mean /= static_cast<double>(end - begin);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (size_t i = begin; i < end; ++i) {
      const Eigen::Vector3d d = log.gyro[i] - mean;
      cov += d * d.transpose();
    }
    cov /= static_cast<double>(end - begin - 1);
    r.gyro_std = (m * cov * m.transpose()).diagonal().cwiseMax(0.0).cwiseSqrt();
  }
}

}  // namespace internal
}  // namespace gravcal
