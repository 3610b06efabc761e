// gravcal/estimation/observability.h: which parameters the positions determine.
//
// A parameter is determined by the data when the whitened Jacobian J of the
// residuals has full column rank; a direction in the null space of J is a
// combination of parameters that no amount of this data can fix. Rank is
// judged from the singular values of J with columns scaled to unit norm (so
// units do not matter), against a relative tolerance.
#ifndef GRAVCAL_ESTIMATION_OBSERVABILITY_H_
#define GRAVCAL_ESTIMATION_OBSERVABILITY_H_

#include <Eigen/Core>
#include <string>
#include <vector>

#include "gravcal/core/accel_model.h"
#include "gravcal/core/position.h"
#include "gravcal/core/solver_result.h"

namespace gravcal {

// relative_tolerance: singular values below this times the largest count as
// zero.
ObservabilityReport AnalyzeObservability(const Eigen::MatrixXd& jacobian,
                                         const std::vector<std::string>& names,
                                         double relative_tolerance = 1e-8);

// d|a_k|/dp of the magnitude model a = M (v - b), with the 12 columns
// (b_x, b_y, b_z, M_00, M_01, ..., M_22), rows divided by sigmas[k]. It has
// rank at most 9: |R M (v - b)| = |M (v - b)| for every rotation R.
Eigen::MatrixXd FullMagnitudeJacobian(const std::vector<Position>& positions,
                                      const Eigen::Vector3d& bias, const Eigen::Matrix3d& matrix,
                                      const std::vector<double>& sigmas);

// Names of the 12 columns above.
std::vector<std::string> FullMagnitudeParameterNames();

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_OBSERVABILITY_H_
