// workflows/batch_scheduler_shard.h (private): a batch's shard (K/N) from the
// job array of the cluster scheduler that started the process.
//
// `--shard auto` (or `auto/N`) asks for this. Each scheduler names the
// task's place in its array with environment variables:
//   Slurm       SLURM_ARRAY_TASK_ID, with SLURM_ARRAY_TASK_MIN and
//               SLURM_ARRAY_TASK_MAX (or SLURM_ARRAY_TASK_COUNT); K = ID -
//               MIN + 1. An array with a step (--array=0-15:4) is refused.
//   Kubernetes  JOB_COMPLETION_INDEX (0-based) of an Indexed Job; N from
//               `auto/N` or JOB_COMPLETIONS (the manifest sets it from
//               .spec.completions: Kubernetes does not).
//   AWS Batch   AWS_BATCH_JOB_ARRAY_INDEX (0-based); N from `auto/N` or
//               AWS_BATCH_JOB_ARRAY_SIZE (the job definition sets it).
// It is an error when none is set, when N is unknown, when K is outside
// 1..N, and when two of them (or `auto/N`) disagree.
#ifndef GRAVCAL_SRC_WORKFLOWS_BATCH_SCHEDULER_SHARD_H_
#define GRAVCAL_SRC_WORKFLOWS_BATCH_SCHEDULER_SHARD_H_

#include <functional>
#include <string>

#include "gravcal/workflows/batch_manifest.h"

namespace gravcal {
namespace internal {

// An environment variable's value; false when it is not set.
using EnvironmentLookup = std::function<bool(const std::string& name, std::string* value)>;

// True for "auto" and "auto/N": the shard comes from the scheduler.
bool IsSchedulerShard(const std::string& text);

// Parses `text` ("auto" or "auto/N") and reads the scheduler's variables
// through `environment`. On success *shard is K/N and *source says where it
// came from ("SLURM_ARRAY_TASK_ID=4 of 0..15").
bool ShardFromScheduler(const std::string& text, const EnvironmentLookup& environment, Shard* shard,
                        std::string* source, std::string* error);

// The process's environment (getenv).
EnvironmentLookup ProcessEnvironment();

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_WORKFLOWS_BATCH_SCHEDULER_SHARD_H_
