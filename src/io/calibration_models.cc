#include "gravcal/io/calibration_models.h"

#include <vector>

#include "util/error.h"

namespace gravcal {

bool ModelsFromCalibration(const Calibration& calibration, const std::string& name,
                           LoadedCalibration* models, std::string* error) {
  LoadedCalibration out;
  std::string what;
  if (!calibration.Model(&out.corrector, &out.undetermined, &what)) {
    return internal::SetError(error, name + ": " + what);
  }
  for (const PositionReport& report : calibration.positions) {
    RecordedPosition p;
    p.raw_mean = report.position.raw_mean;
    p.time = 0.5 * (report.position.t_begin + report.position.t_end);
    p.temperature = report.position.temperature;
    out.positions.push_back(p);
  }
  out.corrector.thermal = calibration.thermal;
  out.gravity = calibration.gravity;
  out.method = calibration.method;
  out.provenance = calibration.provenance;
  if (!CheckCalibrationModels(out, name, error)) return false;
  *models = std::move(out);
  return true;
}

}  // namespace gravcal
