// Calibration::BriefReport and FullReport: the result's own text, as Ceres's
// Solver::Summary has (the CLI prints it, Python's str(calibration) is it).
#include <cmath>
#include <cstdio>
#include <string>

#include "gravcal/core/calibration.h"

namespace gravcal {
namespace {

// printf into a std::string.
template <typename... Args>
std::string Format(const char* format, Args... args) {
  char buffer[512];
  std::snprintf(buffer, sizeof(buffer), format, args...);
  return buffer;
}

// "1.234 +- 0.005" or "1.234 (fixed or not determined)".
std::string WithStd(double value, double std) {
  return std::isfinite(std) ? Format("%.6g +- %.2g", value, std)
                            : Format("%.6g (fixed or not determined)", value);
}

// A vector's entries with their standard deviations, one line.
std::string VectorLine(const char* name, const Eigen::Vector3d& v, const Eigen::Vector3d& std) {
  return Format("%-14s", name) + WithStd(v(0), std(0)) + ", " + WithStd(v(1), std(1)) + ", " +
         WithStd(v(2), std(2)) + "\n";
}

// A matrix, one line per row.
std::string MatrixLines(const char* name, const Eigen::Matrix3d& m, const Eigen::Matrix3d& std) {
  std::string text;
  for (int r = 0; r < 3; ++r) {
    text += VectorLine(r == 0 ? name : "", m.row(r).transpose(), std.row(r).transpose());
  }
  return text;
}

}  // namespace

std::string Calibration::BriefReport() const {
  // Raw counts read without a nominal scale give a "before" residual in
  // counts minus m/s^2, which means nothing: then only the fitted one.
  if (residual_nominal.rms > 0.5 * gravity) {
    return message + Format(
                         "; |a| - g rms %.5f m/s^2 (raw data unscaled: set nominal_scale for a "
                         "'before' figure)",
                         residual_refined.rms);
  }
  return message +
         Format("; |a| - g rms %.5f -> %.5f m/s^2", residual_nominal.rms, residual_refined.rms);
}

std::string Calibration::FullReport() const {
  std::string text = "gravcal calibration (" + method + "): " + message + "\n";
  text += Format("gravity %.6f m/s^2 (%s), %zu positions\n", gravity, gravity_source.c_str(),
                 positions.size());
  text += "accelerometer: a = M (v - b)\n";
  text += VectorLine("  bias b", accel.model.bias, accel.bias_std);
  text += MatrixLines("  matrix M", accel.model.matrix(), accel.matrix_std);
  if (gyro.estimated) {
    text += "gyroscope: w = M_g (u - b_g)\n";
    text += VectorLine("  bias b_g", gyro.model.bias, gyro.bias_std);
    text += MatrixLines("  matrix M_g", gyro.model.matrix, gyro.matrix_std);
  }
  text += Format(
      "|a| - g over positions, m/s^2: before rms %.4g max %.4g; coarse rms %.4g; after rms %.4g "
      "max %.4g\n",
      residual_nominal.rms, residual_nominal.max, residual_coarse.rms, residual_refined.rms,
      residual_refined.max);
  if (refinement.iterations > 0) {
    text += Format("solver: %s, %d iterations, %s; chi2 %.2f on %d dof\n", solver_name.c_str(),
                   refinement.iterations, refinement.termination.c_str(), refinement.chi2,
                   refinement.dof);
  }
  // Issue 35: the thermal terms, each coefficient with its standard
  // deviation or "not determined".
  if (thermal.active() || !thermal.notes.empty()) {
    text += Format("thermal: x = T - %.2f degC, valid %.2f to %.2f degC, lag %.3g s\n",
                   thermal.reference_temperature, thermal.min_temperature, thermal.max_temperature,
                   thermal.lag_time_constant);
    for (ThermalSensor s : {ThermalSensor::kAccel, ThermalSensor::kGyro}) {
      for (ThermalQuantity q :
           {ThermalQuantity::kBias, ThermalQuantity::kScale, ThermalQuantity::kMisalignment}) {
        const ThermalPolynomial& p = thermal.Sensor(s).Term(q);
        if (!p.active()) continue;
        const std::vector<std::string> names = ThermalComponentNames(s, q);
        for (int i = 0; i < p.coefficients.rows(); ++i) {
          text += Format("  %s %s %-3s", ToString(s), ToString(q), names[i].c_str());
          for (int k = 1; k <= p.order; ++k) {
            const bool known = p.Determined(i, k);
            const double sd = known && i < static_cast<int>(p.covariance.size())
                                  ? std::sqrt(p.covariance[i](k, k))
                                  : NAN;
            text += Format(" c%d ", k) +
                    (known ? WithStd(p.coefficients(i, k - 1), sd) : std::string("not determined"));
            text += k < p.order ? ";" : "";
          }
          text += " (" + ThermalUnit(q, 1) + "...)\n";
        }
      }
    }
    for (const std::string& n : thermal.notes) text += "  note: " + n + "\n";
  }
  for (const std::string& w : warnings) text += "warning: " + w + "\n";
  return text;
}

}  // namespace gravcal
