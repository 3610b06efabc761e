#include "gravcal/workflows/compare.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <vector>

#include "io/json_helpers.h"
#include "methods/static_positions.h"
#include "util/source_prefix.h"

namespace gravcal {

OutputDifference CorrectedOutputDifference(const ImuCorrector& a, const ImuCorrector& b,
                                           const ImuLog& log) {
  OutputDifference out;
  out.gyro = a.has_gyro && b.has_gyro && log.has_gyro();
  double accel_sum = 0.0, gyro_sum = 0.0;
  out.accel_max = out.gyro_max = 0.0;
  for (size_t i = 0; i < log.size(); ++i) {
    const double temperature = log.has_temperature() ? log.temperature[i] : NAN;
    Eigen::Vector3d fa = log.accel[i], fb = log.accel[i];
    Eigen::Vector3d wa = out.gyro ? log.gyro[i] : Eigen::Vector3d::Zero(), wb = wa;
    if (!a.CorrectRow(temperature, log.t[i], &fa, out.gyro ? &wa : nullptr) ||
        !b.CorrectRow(temperature, log.t[i], &fb, out.gyro ? &wb : nullptr)) {
      ++out.skipped;
      continue;
    }
    ++out.samples;
    const double da = (fb - fa).norm();
    accel_sum += da * da;
    out.accel_max = std::max(out.accel_max, da);
    if (out.gyro) {
      const double dw = (wb - wa).norm();
      gyro_sum += dw * dw;
      out.gyro_max = std::max(out.gyro_max, dw);
    }
  }
  if (out.samples == 0) {
    out.accel_max = out.gyro_max = NAN;
    return out;
  }
  out.accel_rms = std::sqrt(accel_sum / out.samples);
  if (out.gyro) {
    out.gyro_rms = std::sqrt(gyro_sum / out.samples);
  } else {
    out.gyro_max = NAN;
  }
  return out;
}

std::string OutputDifferenceToJson(const OutputDifference& d) {
  using Json = nlohmann::ordered_json;
  using internal::JsonNumber;
  Json j;
  j["samples"] = d.samples;
  j["skipped"] = d.skipped;
  j["accel_rms"] = JsonNumber<Json>(d.accel_rms);
  j["accel_max"] = JsonNumber<Json>(d.accel_max);
  j["gyro_rms"] = JsonNumber<Json>(d.gyro_rms);
  j["gyro_max"] = JsonNumber<Json>(d.gyro_max);
  return j.dump();
}

namespace {

std::string VerifyDegrees(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f", v);
  return text;
}

// Issue 35: with a thermal model, each pose mean is taken to T_ref, where
// the stored base model (b, U) holds: v' = b + U^-1 s, s the thermal
// correction (I + D(x))^-1 U (v - b - db(x)) at the pose's temperature
// (clamped to the valid range, rate 0: the poses are static). Poses more
// than 0.5 degC outside the range are named in a warning, as apply does;
// a log without temperature is tested at T_ref, with a warning.
//
// The thermal coefficients' uncertainty enters the test through
// *covariance (K x K): the residual r_k = |s_k| - g depends on the
// coefficients theta_i = [c_i0 .. c_in] of every component i of every
// accelerometer term (c_i0 the base bias, zero for scale and
// misalignment), each with its stored covariance C_i, so
//
//   Cov(r) += sum_i J_i C_i J_i^T - j_i0 C_i,00 j_i0^T,   J_i = d r / d theta_i
//
// (central differences; the second part, the base bias alone, is already
// in the stored accelerometer covariance the test uses). Poses at one
// temperature share the same coefficient errors, hence a full matrix.
void ThermalCheckPoses(const ImuLog& log, const Calibration& stored,
                       std::vector<Position>* positions, std::vector<std::string>* warnings,
                       Eigen::MatrixXd* covariance) {
  const ThermalModel& th = stored.thermal;
  const int k = static_cast<int>(positions->size());
  *covariance = Eigen::MatrixXd::Zero(k, k);
  if (!th.active()) return;
  if (!log.has_temperature()) {
    warnings->push_back(log.source +
                        ": the calibration has a thermal model but the check session has no "
                        "'temp' column: tested at its reference temperature " +
                        VerifyDegrees(th.reference_temperature) + " degC");
    return;
  }
  const AccelModel& a = stored.accel.model;
  const double step_floor = 1e-9;
  bool missing = false;
  for (ThermalQuantity q :
       {ThermalQuantity::kBias, ThermalQuantity::kScale, ThermalQuantity::kMisalignment}) {
    const ThermalPolynomial& p = th.accel.Term(q);
    if (!p.active()) continue;
    for (int i = 0; i < p.coefficients.rows(); ++i) {
      if (i >= static_cast<int>(p.covariance.size()) || p.covariance[i].rows() != p.order + 1) {
        missing = true;
        continue;
      }
      const Eigen::MatrixXd& c = p.covariance[i];
      Eigen::MatrixXd j = Eigen::MatrixXd::Zero(k, p.order + 1);
      for (int power = 0; power <= p.order; ++power) {
        if (power == 0 && q != ThermalQuantity::kBias) continue;
        if (power > 0 && !p.Determined(i, power)) continue;
        const double h = std::max(step_floor, 1e-3 * std::sqrt(std::max(0.0, c(power, power))));
        for (int side = 0; side < 2; ++side) {
          ThermalModel moved = th;
          Eigen::Vector3d bias = a.bias;
          const double d = side == 0 ? h : -h;
          if (power == 0) {
            bias(i) += d;
          } else {
            moved.MutableSensor(ThermalSensor::kAccel)
                ->MutableTerm(q)
                ->coefficients(i, power - 1) += d;
          }
          for (int r = 0; r < k; ++r) {
            const Position& pose = (*positions)[r];
            if (!std::isfinite(pose.temperature)) continue;
            const Eigen::Vector3d s = CorrectAccelThermal(
                moved, bias, a.upper, pose.raw_mean, moved.Offset(pose.temperature, 0.0, nullptr));
            j(r, power) += (side == 0 ? 1.0 : -1.0) * s.norm() / (2.0 * h);
          }
        }
      }
      *covariance += j * c * j.transpose() - c(0, 0) * j.col(0) * j.col(0).transpose();
    }
  }
  if (missing) {
    warnings->push_back(log.source +
                        ": the stored thermal model has no covariance for some terms: their "
                        "uncertainty is not part of the test");
  }
  size_t outside = 0;
  double lowest = INFINITY, highest = -INFINITY;
  for (Position& p : *positions) {
    if (!std::isfinite(p.temperature)) continue;
    if (p.temperature < th.min_temperature - 0.5 || p.temperature > th.max_temperature + 0.5) {
      ++outside;
      lowest = std::min(lowest, p.temperature);
      highest = std::max(highest, p.temperature);
    }
    const Eigen::Vector3d s = CorrectAccelThermal(th, a.bias, a.upper, p.raw_mean,
                                                  th.Offset(p.temperature, 0.0, nullptr));
    p.raw_mean = a.bias + a.upper.triangularView<Eigen::Upper>().solve(s);
  }
  if (outside > 0) {
    warnings->push_back(
        log.source + ": " + std::to_string(outside) + " check poses (temperatures " +
        VerifyDegrees(lowest) + " to " + VerifyDegrees(highest) +
        " degC) lie more than 0.5 degC outside the thermal model's range [" +
        VerifyDegrees(th.min_temperature) + ", " + VerifyDegrees(th.max_temperature) +
        "] degC; the correction is clamped there and the check may see a change that is only "
        "temperature");
  }
}

// The mean scale |det M|^(1/3) of a sensor matrix, per raw unit.
double MeanScale(const Eigen::Matrix3d& m) { return std::cbrt(std::fabs(m.determinant())); }

std::string ScaleText(double v) {
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", v);
  return text;
}

// False with *error when scales `a` and `b` differ by more than a factor 2.
bool SameScale(const char* sensor, const char* unit, double a, double b, std::string* error) {
  if (a > 0.0 && b > 0.0 && std::max(a, b) <= 2.0 * std::min(a, b)) return true;
  *error = std::string("the calibrations map different raw units: ") + sensor + " scale " +
           ScaleText(a) + " against " + ScaleText(b) + " " + unit +
           " per raw unit; compare needs both made from logs in the same raw unit (the same "
           "format, columns and nominal_scale)";
  return false;
}

}  // namespace

bool SameRawUnits(const Calibration& a, const Calibration& b, std::string* error) {
  if (!SameScale("accelerometer", "m/s^2", MeanScale(a.accel.model.matrix()),
                 MeanScale(b.accel.model.matrix()), error)) {
    return false;
  }
  return !(a.gyro.estimated && b.gyro.estimated) ||
         SameScale("gyroscope", "rad/s", MeanScale(a.gyro.model.matrix),
                   MeanScale(b.gyro.model.matrix), error);
}

bool VerifyCheckLog(const ImuLog& log, const Calibration& stored, const CalibrationOptions& options,
                    const ComparisonOptions& comparison, CheckSessionResult* result,
                    std::string* error) {
  std::vector<StaticInterval> intervals;
  std::vector<Position> positions;
  std::vector<std::string> notes;
  if (!internal::DetectLogIntervals(log, options.detector, &intervals, error, nullptr) ||
      !internal::PosesFromIntervals(log, intervals, options, &positions, &notes, error)) {
    return false;
  }
  if (positions.empty()) {
    *error = internal::PrefixSource(log.source, "no static pose found in the check session");
    return false;
  }
  // The check's raw unit against the calibration's: |a| of the poses
  // through the stored model (median) near its gravity.
  std::vector<double> magnitudes;
  for (const Position& p : positions) {
    magnitudes.push_back(stored.accel.model.Apply(p.raw_mean).norm());
  }
  std::nth_element(magnitudes.begin(), magnitudes.begin() + magnitudes.size() / 2,
                   magnitudes.end());
  const double magnitude = magnitudes[magnitudes.size() / 2];
  if (!(magnitude > 0.5 * stored.gravity && magnitude < 2.0 * stored.gravity)) {
    *error = internal::PrefixSource(
        log.source, "its poses read |a| = " + ScaleText(magnitude) +
                        " m/s^2 through the stored calibration, not about " +
                        ScaleText(stored.gravity) +
                        ": the check session's raw unit is not the calibration's (read it with "
                        "the config the calibration was made with, --config)");
    return false;
  }
  std::vector<std::string> warnings;
  Eigen::MatrixXd thermal_covariance;
  ThermalCheckPoses(log, stored, &positions, &warnings, &thermal_covariance);
  if (!VerifyCheckSession(positions, stored, comparison, result, &thermal_covariance)) {
    *error = internal::PrefixSource(log.source, result->comparison.message);
    return false;
  }
  result->warnings = warnings;
  return true;
}

std::string CheckPosesToJson(const CheckSessionResult& result) {
  using Json = nlohmann::ordered_json;
  using internal::JsonNumber;
  Json poses = Json::array();
  for (const CheckPose& p : result.poses) {
    Json row;
    row["t_begin"] = p.t_begin;
    row["t_end"] = p.t_end;
    row["residual"] = JsonNumber<Json>(p.residual);
    row["noise_sigma"] = JsonNumber<Json>(p.noise_sigma);
    row["sigma"] = JsonNumber<Json>(p.sigma);
    poses.push_back(row);
  }
  return poses.dump();
}

}  // namespace gravcal
