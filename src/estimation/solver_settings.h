// estimation/solver_settings.h (private): the one place a
// ceres::Solver::Options is filled for the library's small dense fits.
#ifndef GRAVCAL_ESTIMATION_SOLVER_SETTINGS_H_
#define GRAVCAL_ESTIMATION_SOLVER_SETTINGS_H_

#include <ceres/solver.h>

#include "gravcal/estimation/solver_tolerances.h"

namespace gravcal {
namespace internal {

// Options for a small dense fit: the given linear solver, the stopping rules
// of `tolerances`, silent, one thread; every other field keeps Ceres'
// default.
ceres::Solver::Options SolverOptions(const SolverTolerances& tolerances,
                                     ceres::LinearSolverType linear_solver);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_SOLVER_SETTINGS_H_
