#include "gravcal/workflows/compare.h"

#include <cmath>
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
  if (!VerifyCheckSession(positions, stored, comparison, result)) {
    *error = internal::PrefixSource(log.source, result->comparison.message);
    return false;
  }
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
