// A consumer of the installed gravcal package: builds its own Ceres problem
// from the public GravityMagnitudeResidual, then runs the library's
// CalibrateFromPositions on the same positions. Exits 1 on any failure.
#include <ceres/ceres.h>

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <iostream>
#include <vector>

#include "gravcal/core/position.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/residuals/gravity_magnitude_residual.h"

namespace {

constexpr double kGravity = 9.80665;
constexpr double kTolerance = 1e-6;

// ||estimate - truth|| / ||truth||, printed and checked.
bool CheckClose(const char* what, const Eigen::MatrixXd& estimate, const Eigen::MatrixXd& truth) {
  const double error = (estimate - truth).norm() / truth.norm();
  if (!(error <= kTolerance)) {
    std::cerr << "consumer: " << what << " is off by " << error << " relative (limit " << kTolerance
              << ")\nestimate:\n"
              << estimate << "\ntruth:\n"
              << truth << "\n";
    return false;
  }
  return true;
}

}  // namespace

int main() {
  // The known sensor: a = U (v - b), R = I.
  const Eigen::Vector3d bias_true(0.12, -0.08, 0.05);
  Eigen::Matrix3d upper_true;
  upper_true << 1.01, 0.004, -0.003,  //
      0.0, 0.985, 0.006,              //
      0.0, 0.0, 1.02;

  // Twelve static directions: the six axes and six diagonals.
  std::vector<Eigen::Vector3d> directions = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},   {0, -1, 0},
                                             {0, 0, 1},  {0, 0, -1}, {1, 1, 0},   {-1, 0, 1},
                                             {0, -1, 1}, {1, 1, 1},  {-1, -1, 1}, {1, -1, -1}};
  std::vector<gravcal::Position> positions;
  const Eigen::Matrix3d upper_inverse = upper_true.inverse();
  for (const Eigen::Vector3d& d : directions) {
    gravcal::Position p;
    p.raw_mean = upper_inverse * (kGravity * d.normalized()) + bias_true;
    // No noise in the mean; a nominal covariance so sigma is defined.
    p.raw_mean_cov = 1e-8 * Eigen::Matrix3d::Identity();
    p.sample_count = 1000;
    positions.push_back(p);
  }

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
  bool ok = CheckClose("own problem: bias", Eigen::Vector3d(bias[0], bias[1], bias[2]), bias_true);
  ok = CheckClose("own problem: U", upper_estimate, upper_true) && ok;

  // The library's end-to-end calibration on the same positions.
  gravcal::CalibrationOptions calibration_options;
  calibration_options.gravity.gravity = kGravity;
  gravcal::Calibration calibration;
  if (!gravcal::CalibrateFromPositions(positions, calibration_options, &calibration) ||
      !calibration.success) {
    std::cerr << "consumer: CalibrateFromPositions failed: " << calibration.message << "\n";
    return 1;
  }
  ok = CheckClose("CalibrateFromPositions: bias", calibration.accel.model.bias, bias_true) && ok;
  ok = CheckClose("CalibrateFromPositions: U", calibration.accel.model.upper, upper_true) && ok;
  if (!ok) return 1;

  std::cout << "consumer: gravcal::GravityMagnitudeResidual and CalibrateFromPositions OK ("
            << summary.iterations.size() << " Ceres iterations)\n";
  return 0;
}
