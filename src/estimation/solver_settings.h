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

// Ceres' own default stopping rules (read from ceres::Solver::Options) with
// `max_iterations`: for fits whose options give only an iteration limit
// (the thermal fits, the multi-IMU joint fit).
SolverTolerances CeresDefaultTolerances(int max_iterations);

// Threads for the solver of a single calibration: the machine's (at most 4)
// when called from a thread of its own, 1 inside a batch worker (a thread
// with a cancellation flag, util/cancellation.h), which already runs one
// unit per core.
int SingleCalibrationThreads();

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_ESTIMATION_SOLVER_SETTINGS_H_
