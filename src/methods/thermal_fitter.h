// The thermal fit at fixed orders and its information criterion, private to
// methods/ (thermal_calibration.cc searches the orders with it).
#ifndef GRAVCAL_METHODS_THERMAL_FITTER_H_
#define GRAVCAL_METHODS_THERMAL_FITTER_H_

#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "gravcal/methods/thermal_calibration.h"
#include "methods/thermal_residual.h"

namespace ceres {
class Problem;
}  // namespace ceres

namespace gravcal {
namespace internal {

// One fit at fixed orders.
struct ThermalFit {
  bool ok = false;
  std::vector<double> theta;
  std::vector<bool> fixed;
  double chi2 = NAN;
  int free = 0;
  int residuals = 0;
  Eigen::MatrixXd covariance;  // layout.size square, zero rows for held ones
  std::string message;
  // The solver met its tolerances (not stopped by the iteration limit).
  bool converged = false;
};

class ThermalFitter {
 public:
  ThermalFitter(const std::vector<ThermalWindow>& windows, const ThermalElementSeries& element,
                const ThermalCalibrationOptions& o, bool has_gyro, double reference_temperature,
                double span);

  // Fits `orders`, starting from `start` (parameters matched by name).
  ThermalFit Run(const ThermalOrders& orders, const std::map<std::string, double>& start) const;

  // One pose direction: the magnitude sees only the component along
  // gravity (axis `single_axis_`), so everything else of the accelerometer
  // is held: U, the other axes' bias and bias terms, scale and
  // misalignment. (The linearised test would otherwise read the thermal
  // drift of the level axes as information on their base bias.)
  void SetSinglePose(int axis) { single_axis_ = axis; }
  // Only poses near the faces: the non-orthogonality (U's off-diagonal
  // and its thermal terms) enters |U d| to second order only and is held.
  void SetFacesOnly(bool faces_only) { faces_only_ = faces_only; }

  double Score(const ThermalFit& f) const;

  // Non-empty when nominal_scale did not read the poses near gravity.
  const std::string& scale_note() const { return scale_note_; }

 private:
  std::vector<bool> Held(const ThermalLayout& layout, std::vector<bool> fixed) const;

  // sigma_k of the magnitude residual: n^T U C_v U^T n at theta.
  std::vector<double> AccelSigmas(const ThermalLayout& layout,
                                  const std::vector<double>& theta) const;

  void Build(const ThermalLayout& layout, const std::vector<double>& sigmas, double* theta,
             ceres::Problem* problem) const;

  // The whitened Jacobian at theta, dense (residuals x parameters).
  Eigen::MatrixXd Jacobian(const ThermalLayout& layout, const std::vector<double>& sigmas,
                           std::vector<double> theta, Eigen::VectorXd* residual) const;

  // A plausible size of each parameter (the header's prior ranges).
  std::vector<double> PriorScale(const ThermalLayout& layout,
                                 const std::vector<double>& theta) const;

  // Modified Gram-Schmidt over the prior-scaled columns in priority order
  // (the header): true = undetermined.
  // The test is taken with U's off-diagonal at 0 (the axis-aligned U a
  // MEMS part is near): on the six faces |U d| depends on the
  // off-diagonal only to second order, so away from 0 the linearisation
  // lends it information the poses do not have, and a solve that slid
  // along that valley would confirm itself (seen on six faces plus one
  // tilted pose: U's columns turned by 70 degrees, the bias at 2000 m/s^2).
  std::vector<bool> Undetermined(const ThermalLayout& layout, std::vector<double> theta,
                                 const std::vector<double>& sigmas) const;

  bool Solve(const ThermalLayout& layout, const std::vector<double>& sigmas, ThermalFit* fit) const;

  void Covariance(const ThermalLayout& layout, const std::vector<double>& sigmas,
                  ThermalFit* fit) const;

  const std::vector<ThermalWindow>& windows_;
  const ThermalElementSeries& element_;
  const ThermalCalibrationOptions& o_;
  const bool has_gyro_;
  const double reference_;
  const double half_span_;
  double accel_range_ = 0.0;
  double start_accel_scale_ = 1.0;
  std::string scale_note_;
  double gyro_range_ = 0.0;
  int single_axis_ = -1;
  bool faces_only_ = false;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_METHODS_THERMAL_FITTER_H_
