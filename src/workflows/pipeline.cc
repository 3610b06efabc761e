#include "gravcal/workflows/pipeline.h"

#include "gravcal/io/noise_io.h"
#include "gravcal/workflows/method_registry.h"
#include "gravcal/workflows/rate_table_segments.h"

namespace gravcal {
namespace {

// Reads the side input `method` needs into `data`.
bool ReadSideInput(const CalibrationMethod& method, const PipelineInput& input, MethodData* data,
                   std::string* error) {
  switch (method.side_input) {
    case MethodSideInput::kNone:
      return true;
    case MethodSideInput::kAttitudes:
      data->side_input_name = input.attitudes_path;
      if (input.attitudes_path.empty()) {
        *error = method.name + " needs the attitudes file (--attitudes fixture.csv)";
        return false;
      }
      return ReadFixtureAttitudes(input.attitudes_path, &data->attitudes, error);
    case MethodSideInput::kSegments:
      data->side_input_name = input.segments_path;
      if (input.segments_path.empty()) {
        *error = method.name + " needs the segments file (--segments segments.csv)";
        return false;
      }
      return ReadRateTableSegments(input.segments_path, input.log, &data->segments, error);
  }
  return true;
}

}  // namespace

bool RunCalibration(const Config& config, const PipelineInput& input, Calibration* calibration) {
  *calibration = Calibration();
  std::string error;
  if (!config.IsValid(&error)) {
    calibration->message = error;
    return false;
  }
  const CalibrationMethod& method = *FindCalibrationMethod(config.method);
  MethodData data;
  data.log = &input.log;
  ImuNoise noise;
  if (!input.noise_path.empty()) {
    calibration->method = method.name;
    if (method.noise_model.empty()) {
      calibration->message = "method '" + method.name + "' uses no noise model (remove --noise " +
                             input.noise_path + ")";
      return false;
    }
    if (!ReadNoiseJson(input.noise_path, &noise, &calibration->message)) return false;
    data.noise = &noise.model;
    data.noise_name = input.noise_path;
  }
  if (!ReadSideInput(method, input, &data, &error)) {
    calibration->method = method.name;
    calibration->message = error;
    return false;
  }
  const bool ok = method.run(config, data, calibration);
  calibration->method = method.name;
  return ok;
}

}  // namespace gravcal
