// workflows/batch_run.h (private): one call of CalibrateBatch: the worker
// threads, the per-unit time limit and the stop request.
#ifndef GRAVCAL_SRC_WORKFLOWS_BATCH_RUN_H_
#define GRAVCAL_SRC_WORKFLOWS_BATCH_RUN_H_

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "gravcal/workflows/batch.h"

namespace gravcal {
namespace internal {

using SkipFunction = std::function<bool(const BatchUnit& unit, const std::string& content_hash)>;

// Reads, hashes and parses one unit, then calibrates it unless `skip` says
// its stored result is current (batch.cc).
void RunUnit(const BatchUnit& unit, const Config& base, const SkipFunction& skip, BatchResult* r);

// Runs every unit on `threads` workers. A unit over
// options.unit_timeout_seconds, or still running stop_grace_seconds after
// options.stop was set, is abandoned: its cancel flag is set (the solver and
// the log reader stop soon), a fresh worker takes its place, and the late
// worker touches nothing of the caller's when it comes back (it holds a copy
// of its unit and shares only this run's state). Units not started because
// of the stop get BatchResult::not_run.
class BatchRun {
 public:
  BatchRun(const std::vector<BatchUnit>& units, const Config& base, const BatchOptions& options,
           std::vector<BatchResult>* results);
  ~BatchRun();
  void Run(int threads);

  struct State;

 private:
  std::shared_ptr<State> state_;
};

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_BATCH_RUN_H_
