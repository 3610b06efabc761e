// A consumer of the installed gravcal package through the core alone
// (gravcal::gravcal, gravcal/gravcal.h): no Ceres or glog include path or
// library of its own. Calibrates known positions with CalibrateFromPositions,
// writes the result as calibration JSON and reads it back, and corrects a
// sample with the model. Exits 1 on any failure.
#include <iostream>
#include <string>
#include <vector>

#include "gravcal/gravcal.h"
#include "known_sensor.h"

#ifdef CERES_PUBLIC_CERES_H_
#error "gravcal/gravcal.h included ceres/ceres.h"
#endif

using consumer::CheckClose;
using consumer::kGravity;

int main() {
  const consumer::KnownSensor sensor;
  const std::vector<gravcal::Position> positions = sensor.Positions();

  gravcal::CalibrationOptions options;
  options.gravity.gravity = kGravity;
  gravcal::Calibration calibration;
  if (!gravcal::CalibrateFromPositions(positions, options, &calibration) || !calibration.success) {
    std::cerr << "core consumer: CalibrateFromPositions failed: " << calibration.message << "\n";
    return 1;
  }
  bool ok = CheckClose("bias", calibration.accel.model.bias, sensor.bias);
  ok = CheckClose("U", calibration.accel.model.upper, sensor.upper) && ok;

  // Written and read back as the calibration JSON the tool writes.
  const std::string json = gravcal::CalibrationToJson(calibration, /*include_covariance=*/true);
  gravcal::LoadedCalibration loaded;
  std::string error;
  if (!gravcal::CalibrationFromJson(json, "core consumer", &loaded, &error)) {
    std::cerr << "core consumer: CalibrationFromJson failed: " << error << "\n";
    return 1;
  }
  if (loaded.gravity != kGravity) {
    std::cerr << "core consumer: gravity read back as " << loaded.gravity << "\n";
    ok = false;
  }
  const Eigen::Vector3d raw = sensor.Raw(Eigen::Vector3d(0.0, 0.0, kGravity));
  const Eigen::Vector3d corrected = calibration.accel.model.Apply(raw);
  ok = CheckClose("corrected sample", corrected, Eigen::Vector3d(0.0, 0.0, kGravity)) && ok;
  if (!ok) return 1;
  std::cout << "core consumer: CalibrateFromPositions, calibration JSON round trip OK\n";
  return 0;
}
