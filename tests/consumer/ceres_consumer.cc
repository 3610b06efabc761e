// A consumer of the installed gravcal package through gravcal::ceres: builds
// its own Ceres problem from the public GravityMagnitudeResidual
// (gravcal/ceres.h), then runs the library's CalibrateFromPositions on the
// same positions. Exits 1 on any failure.
#include <ceres/ceres.h>

#include <iostream>
#include <vector>

#include "gravcal/ceres.h"
#include "gravcal/gravcal.h"
#include "known_sensor.h"

using consumer::CheckClose;
using consumer::kGravity;

int main() {
  const consumer::KnownSensor sensor;
  const std::vector<gravcal::Position> positions = sensor.Positions();

  // The consumer's own problem, sharing the bias and upper blocks.
  double bias[3] = {0.0, 0.0, 0.0};
  double upper[6] = {1.0, 0.0, 0.0, 1.0, 0.0, 1.0};
  ceres::Problem problem;
  for (const gravcal::Position& p : positions) {
    problem.AddResidualBlock(gravcal::GravityMagnitudeResidual::Create(p.raw_mean, kGravity, 0.01),
                             nullptr, bias, upper);
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 200;
  options.function_tolerance = 1e-16;
  options.gradient_tolerance = 1e-16;
  options.parameter_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  if (!summary.IsSolutionUsable()) {
    std::cerr << "consumer: own ceres::Problem failed: " << summary.BriefReport() << "\n";
    return 1;
  }
  Eigen::Matrix3d upper_estimate;
  upper_estimate << upper[0], upper[1], upper[2],  //
      0.0, upper[3], upper[4],                     //
      0.0, 0.0, upper[5];
  bool ok =
      CheckClose("own problem: bias", Eigen::Vector3d(bias[0], bias[1], bias[2]), sensor.bias);
  ok = CheckClose("own problem: U", upper_estimate, sensor.upper) && ok;

  // The library's end-to-end calibration on the same positions.
  gravcal::CalibrationOptions calibration_options;
  calibration_options.gravity.gravity = kGravity;
  gravcal::Calibration calibration;
  if (!gravcal::CalibrateFromPositions(positions, calibration_options, &calibration) ||
      !calibration.success) {
    std::cerr << "consumer: CalibrateFromPositions failed: " << calibration.message << "\n";
    return 1;
  }
  ok = CheckClose("CalibrateFromPositions: bias", calibration.accel.model.bias, sensor.bias) && ok;
  ok = CheckClose("CalibrateFromPositions: U", calibration.accel.model.upper, sensor.upper) && ok;
  if (!ok) return 1;

  std::cout << "consumer: gravcal::GravityMagnitudeResidual and CalibrateFromPositions OK ("
            << summary.iterations.size() << " Ceres iterations)\n";
  return 0;
}
