#include "estimation/solver_settings.h"

#include <algorithm>
#include <thread>

#include "util/cancellation.h"

namespace gravcal {

bool SolverTolerances::IsValid(std::string* error) const {
  if (max_iterations < 1) {
    if (error) *error = "max_iterations: must be at least 1";
    return false;
  }
  if (!(function_tolerance > 0.0) || !(gradient_tolerance > 0.0) || !(parameter_tolerance > 0.0)) {
    if (error) {
      *error = "function_tolerance, gradient_tolerance, parameter_tolerance: must be positive";
    }
    return false;
  }
  return true;
}

namespace internal {
namespace {

// Aborts the solve when the work on this thread was cancelled (a batch unit
// over its time limit, util/cancellation.h).
class CancellationCallback : public ceres::IterationCallback {
 public:
  ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
    return CancelRequested() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
  }
};

}  // namespace

ceres::Solver::Options SolverOptions(const SolverTolerances& tolerances,
                                     ceres::LinearSolverType linear_solver) {
  ceres::Solver::Options options;
  options.linear_solver_type = linear_solver;
  options.max_num_iterations = tolerances.max_iterations;
  options.function_tolerance = tolerances.function_tolerance;
  options.gradient_tolerance = tolerances.gradient_tolerance;
  options.parameter_tolerance = tolerances.parameter_tolerance;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  options.num_threads = 1;
  static CancellationCallback cancellation;
  options.callbacks.push_back(&cancellation);
  return options;
}

SolverTolerances CeresDefaultTolerances(int max_iterations) {
  const ceres::Solver::Options defaults;
  SolverTolerances t;
  t.max_iterations = max_iterations;
  t.function_tolerance = defaults.function_tolerance;
  t.gradient_tolerance = defaults.gradient_tolerance;
  t.parameter_tolerance = defaults.parameter_tolerance;
  return t;
}

int SingleCalibrationThreads() {
  if (ThreadCancelFlag() != nullptr) return 1;
  const unsigned cores = std::thread::hardware_concurrency();
  return static_cast<int>(std::clamp(cores, 1u, 4u));
}

}  // namespace internal
}  // namespace gravcal
