// gravcal/estimation/coarse_fit.h: closed-form starting values for the refinement.
//
// Six-position fit (Chen et al. 2012, section 2.2). With the model written as
// a = B + M v, every output axis i is fitted by linear least squares over the
// positions whose nominal up axis n_k is known:
//
//   [1 v_kx v_ky v_kz] [B_i M_i0 M_i1 M_i2]^T = g n_k,i,   k = 1..K,
//
// i.e. x_i = (G^T G)^-1 G^T y_i, solved through an LDLT factorisation of the
// normal equations. Then b = -M^-1 B. The targets assume perfect placement,
// so table tilt leaks into the result: it is only a starting value.
//
// Ellipsoid fit, for poses in arbitrary orientations. The calibrated vector
// has |U (v - b)| = g, so the raw means lie on the ellipsoid
// (v - b)^T A (v - b) = 1 with A = U^T U / g^2. The algebraic fit of the
// general quadric v^T Q v + p^T v + c = 0 (10 coefficients, least squares
// with unit norm through the SVD, on normalised data) needs 9 or more
// positions; the axis-aligned one (7 coefficients, U diagonal) needs 6 or
// more. U is the Cholesky factor of g^2 A. No initial value, whatever the
// units.
#ifndef GRAVCAL_ESTIMATION_COARSE_FIT_H_
#define GRAVCAL_ESTIMATION_COARSE_FIT_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"
#include "gravcal/core/solver_result.h"

namespace gravcal {

struct CoarseFitOptions {
  // A position counts as axis-aligned when its direction is within this many
  // degrees of a housing axis.
  double axis_tolerance_deg = 20.0;

  bool IsValid(std::string* error) const;
};

// Assigns to every position without one the housing axis (0..5) its
// direction is within `tolerance_deg` of, or -1. Directions come from
// `model` when given, else from normalising the raw means by the per-axis
// midpoint and half-range of all positions (unit-free).
void AssignNominalAxes(const std::vector<Position>& positions, const AccelModel* model,
                       double tolerance_deg, std::vector<int>* nominal_up);

// The seed's six-position least squares over positions with nominal_up >= 0.
// Returns false when fewer than 4 such positions or G^T G is singular (the
// positions do not span three dimensions).
bool SixPositionFit(const std::vector<Position>& positions, const std::vector<int>& nominal_up,
                    double gravity, Eigen::Vector3d* bias, Eigen::Matrix3d* matrix,
                    std::string* error);

// Algebraic ellipsoid fit; `diagonal` restricts U to a diagonal. R = I.
bool EllipsoidFit(const std::vector<Position>& positions, bool diagonal, double gravity,
                  AccelModel* model, std::string* error);

// Picks the method: the six-position fit when at least six positions are
// axis-aligned and span all three axes up and down, else the ellipsoid fit.
// The result is cast to `parameterization` (for kScale: diagonal U, R = I;
// for kScaleMisalignment: R = I; for kAffine: R from the fit).
bool CoarseFit(const std::vector<Position>& positions, double gravity,
               AccelParameterization parameterization, const CoarseFitOptions& options,
               CoarseFitResult* result);

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_COARSE_FIT_H_
