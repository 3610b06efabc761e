// (name, estimate - truth, sigma) of every parameter a Calibration reports a
// covariance for, read by the covariance's own parameter names, so each
// method is checked on exactly what it says it estimated:
//   accelerometer  bias_a (raw units), u_ab (U, accel_model.h), m_ab
//                  (M = R U), rot_a (the small rotation vector of R_est
//                  R_true^T, rad)
//   gyroscope      bias_a (raw units), m_ab (M_g), g_ab (G, rad/s per
//                  m/s^2, from the extra values g_sensitivity_ab)
// sigma = sqrt of the covariance's diagonal. A name this file does not know
// gets a NaN error, so SigmaCheck counts it as missing and the test fails
// rather than skipping it.
#ifndef GRAVCAL_TESTS_PROPERTY_PARAMETER_ERRORS_H_
#define GRAVCAL_TESTS_PROPERTY_PARAMETER_ERRORS_H_

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/calibration.h"
#include "property/method_case.h"

namespace gravcal {
namespace testing_util {

// 'x', 'y', 'z' -> 0, 1, 2; anything else -> -1.
inline int AxisIndex(char c) { return c >= 'x' && c <= 'z' ? c - 'x' : -1; }

// Row and column of a two-axis suffix ("xy" -> 0, 1), false if it is not one.
inline bool AxisPair(const std::string& name, size_t at, int* r, int* c) {
  if (name.size() != at + 2) return false;
  *r = AxisIndex(name[at]);
  *c = AxisIndex(name[at + 1]);
  return *r >= 0 && *c >= 0;
}

inline double CovarianceSigma(const Eigen::MatrixXd& covariance, size_t i) {
  if (static_cast<Eigen::Index>(i) >= covariance.rows()) return NAN;
  return std::sqrt(covariance(i, i));
}

// Accelerometer parameters of `names` / `covariance`, for the estimate
// `estimate` (the model the covariance describes) against `truth`; names in
// `checked_elsewhere` (effect terms, which the caller checks against their
// own truth) are left out.
inline void AddAccelErrors(const std::string& prefix, const std::vector<std::string>& names,
                           const Eigen::MatrixXd& covariance, const AccelModel& estimate,
                           const AccelModel& truth, std::vector<ParameterError>* out,
                           const std::vector<std::string>& checked_elsewhere = {}) {
  const Eigen::AngleAxisd rotation(estimate.rotation * truth.rotation.transpose());
  const Eigen::Vector3d theta = rotation.angle() * rotation.axis();
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string& name = names[i];
    if (std::find(checked_elsewhere.begin(), checked_elsewhere.end(), name) !=
        checked_elsewhere.end()) {
      continue;
    }
    double error = NAN;
    int r = -1, c = -1;
    if (name.rfind("bias_", 0) == 0 && name.size() == 6 && AxisIndex(name[5]) >= 0) {
      error = estimate.bias(AxisIndex(name[5])) - truth.bias(AxisIndex(name[5]));
    } else if (name.rfind("u_", 0) == 0 && AxisPair(name, 2, &r, &c)) {
      error = estimate.upper(r, c) - truth.upper(r, c);
    } else if (name.rfind("m_", 0) == 0 && AxisPair(name, 2, &r, &c)) {
      error = estimate.matrix()(r, c) - truth.matrix()(r, c);
    } else if (name.rfind("rot_", 0) == 0 && name.size() == 5 && AxisIndex(name[4]) >= 0) {
      error = theta(AxisIndex(name[4]));
    }
    out->push_back({prefix + name, error, CovarianceSigma(covariance, i)});
  }
}

inline void AddAccelErrors(const std::string& prefix, const AccelCalibration& accel,
                           const AccelModel& truth, std::vector<ParameterError>* out,
                           const std::vector<std::string>& checked_elsewhere = {}) {
  AddAccelErrors(prefix, accel.covariance_names, accel.covariance, accel.model, truth, out,
                 checked_elsewhere);
}

// The truth of a gyroscope calibration in the frame the method works in.
struct GyroTruth {
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  Eigen::Matrix3d matrix = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d g_sensitivity = Eigen::Matrix3d::Zero();
};

inline void AddGyroErrors(const std::string& prefix, const GyroCalibration& gyro,
                          const GyroTruth& truth, std::vector<ParameterError>* out) {
  for (size_t i = 0; i < gyro.covariance_names.size(); ++i) {
    const std::string& name = gyro.covariance_names[i];
    double error = NAN;
    int r = -1, c = -1;
    if (name.rfind("bias_", 0) == 0 && name.size() == 6 && AxisIndex(name[5]) >= 0) {
      error = gyro.model.bias(AxisIndex(name[5])) - truth.bias(AxisIndex(name[5]));
    } else if (name.rfind("m_", 0) == 0 && AxisPair(name, 2, &r, &c)) {
      error = gyro.model.matrix(r, c) - truth.matrix(r, c);
    } else if (name.rfind("g_", 0) == 0 && AxisPair(name, 2, &r, &c)) {
      const std::string extra = "g_sensitivity_" + name.substr(2);
      for (size_t k = 0; k < gyro.extra_names.size(); ++k) {
        if (gyro.extra_names[k] == extra) error = gyro.extra_values[k] - truth.g_sensitivity(r, c);
      }
    }
    out->push_back({prefix + name, error, CovarianceSigma(gyro.covariance, i)});
  }
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_PROPERTY_PARAMETER_ERRORS_H_
