// gravcal/core/accel_model.h: the accelerometer error model.
//
//   a = M (v - b),   M = R U
//
// v is the raw reading (any units), b the bias in raw units, a the calibrated
// specific force in m/s^2 in the body (housing) frame. Sign convention: a
// unit at rest reads +g on the axis that points up.
//
// U is upper triangular with a positive diagonal: its diagonal holds the
// scale factors (m/s^2 per raw unit) and its off-diagonal the
// non-orthogonality of the sensor axes. R is a rotation, the alignment of the
// (orthogonalised) sensor axes in the housing. The gravity magnitude |a| does
// not depend on R, so a magnitude fit determines b and U only (9 numbers); R
// can only come from knowing how the housing was placed (nominal axes).
//
// All zero errors = unit scale, zero bias: M = I, b = 0 (identity mapping).
#ifndef GRAVCAL_CORE_ACCEL_MODEL_H_
#define GRAVCAL_CORE_ACCEL_MODEL_H_

#include <Eigen/Core>
#include <random>
#include <string>

#include "gravcal/core/types.h"

namespace gravcal {

// 6, 9 or 12.
int NumParameters(AccelParameterization p);

// The six upper-triangular entries of U, row-major: u00 u01 u02 u11 u12 u22.
constexpr int kUpperSize = 6;

struct AccelModel {
  AccelParameterization parameterization = AccelParameterization::kScaleMisalignment;
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  Eigen::Matrix3d upper = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();

  // M = R U.
  Eigen::Matrix3d matrix() const { return rotation * upper; }
  // a = M (v - b).
  Eigen::Vector3d Apply(const Eigen::Vector3d& raw) const;
  // v = M^-1 a + b.
  Eigen::Vector3d Invert(const Eigen::Vector3d& specific_force) const;

  // Packs U into / out of the 6-vector layout above.
  void GetUpper(double* u6) const;
  void SetUpper(const double* u6);

  // Builds the model from any invertible M by the QR decomposition M = R U
  // with diag(U) > 0. Returns false when M is singular or has det(M) <= 0
  // (a reflection: the axes are wired left-handed).
  static bool FromMatrix(const Eigen::Vector3d& bias, const Eigen::Matrix3d& m,
                         AccelParameterization p, AccelModel* model);

  // A random sensor for tests and simulation: scale = nominal_scale * (1 +
  // N(0, scale_std)), non-orthogonality N(0, misalignment_std) rad, rotation
  // by N(0, misalignment_std) rad about each axis, bias N(0, bias_std) in raw
  // units. Entries the parameterisation fixes stay at their identity value.
  static AccelModel Random(AccelParameterization p, double nominal_scale, double scale_std,
                           double misalignment_std, double bias_std, std::mt19937_64* rng);
};

}  // namespace gravcal

#endif  // GRAVCAL_CORE_ACCEL_MODEL_H_
