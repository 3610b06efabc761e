// gravcal/estimation/solver_tolerances.h: when a Ceres solve stops, the four
// settings every fit of the library exposes (an options struct embeds one,
// with its own defaults).
#ifndef GRAVCAL_ESTIMATION_SOLVER_TOLERANCES_H_
#define GRAVCAL_ESTIMATION_SOLVER_TOLERANCES_H_

#include <string>

namespace gravcal {

struct SolverTolerances {
  // Iteration limit of the Levenberg-Marquardt solve.
  int max_iterations = 100;
  // Relative change of the cost, of the gradient's max norm and of the
  // parameters below which the solve stops (ceres::Solver::Options).
  double function_tolerance = 1e-14;
  double gradient_tolerance = 1e-14;
  double parameter_tolerance = 1e-12;

  // False, with the offending field named in *error, when max_iterations < 1
  // or a tolerance is not positive.
  bool IsValid(std::string* error) const;
};

}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_SOLVER_TOLERANCES_H_
