#include "workflows/batch_scheduler_shard.h"

#include <cstdlib>
#include <vector>

namespace gravcal {
namespace internal {
namespace {

// A whole decimal number of at most 9 digits.
bool ParseCount(const std::string& s, long* v) {
  if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) {
    return false;
  }
  *v = std::atol(s.c_str());
  return true;
}

// One scheduler's reading: K (1-based) and N, N = 0 when it gave none.
struct Reading {
  std::string source;
  long index = 0;
  long count = 0;
};

// Reads `name` as a number; false (error set) when it is set and not one.
bool ReadNumber(const EnvironmentLookup& env, const std::string& name, bool* set, long* value,
                std::string* error) {
  std::string text;
  *set = env(name, &text);
  if (*set && !ParseCount(text, value)) {
    *error = "shard auto: " + name + "='" + text + "' is not a whole number";
    return false;
  }
  return true;
}

bool ReadSlurm(const EnvironmentLookup& env, std::vector<Reading>* readings, std::string* error) {
  bool has_id = false, has_min = false, has_max = false, has_count = false, has_step = false;
  long id = 0, min = 0, max = 0, count = 0, step = 1;
  if (!ReadNumber(env, "SLURM_ARRAY_TASK_ID", &has_id, &id, error)) return false;
  if (!has_id) return true;
  if (!ReadNumber(env, "SLURM_ARRAY_TASK_MIN", &has_min, &min, error) ||
      !ReadNumber(env, "SLURM_ARRAY_TASK_MAX", &has_max, &max, error) ||
      !ReadNumber(env, "SLURM_ARRAY_TASK_COUNT", &has_count, &count, error) ||
      !ReadNumber(env, "SLURM_ARRAY_TASK_STEP", &has_step, &step, error)) {
    return false;
  }
  if (!has_min) {
    *error = "shard auto: SLURM_ARRAY_TASK_ID is set but SLURM_ARRAY_TASK_MIN is not";
    return false;
  }
  if (has_step && step != 1) {
    *error = "shard auto: the Slurm array has step " + std::to_string(step) +
             " (SLURM_ARRAY_TASK_STEP); give a contiguous array (--array=0-15) or --shard K/N";
    return false;
  }
  Reading r;
  r.index = id - min + 1;
  if (has_max) r.count = max - min + 1;
  if (has_count && has_max && count != r.count) {
    *error = "shard auto: SLURM_ARRAY_TASK_COUNT=" + std::to_string(count) + " but MIN..MAX is " +
             std::to_string(min) + ".." + std::to_string(max) +
             " (an array with gaps, e.g. --array=1,4,9, cannot be split by index)";
    return false;
  }
  if (has_count) r.count = count;
  r.source = "SLURM_ARRAY_TASK_ID=" + std::to_string(id) + " of " + std::to_string(min) + ".." +
             std::to_string(min + r.count - 1);
  if (r.count == 0) {
    *error =
        "shard auto: SLURM_ARRAY_TASK_ID is set but neither SLURM_ARRAY_TASK_MAX nor "
        "SLURM_ARRAY_TASK_COUNT";
    return false;
  }
  readings->push_back(r);
  return true;
}

// A 0-based index with an optional count variable (Kubernetes, AWS Batch).
bool ReadZeroBased(const EnvironmentLookup& env, const std::string& index_name,
                   const std::string& count_name, std::vector<Reading>* readings,
                   std::string* error) {
  bool has_index = false, has_count = false;
  long index = 0, count = 0;
  if (!ReadNumber(env, index_name, &has_index, &index, error)) return false;
  if (!has_index) return true;
  if (!ReadNumber(env, count_name, &has_count, &count, error)) return false;
  Reading r;
  r.index = index + 1;
  r.count = has_count ? count : 0;
  r.source = index_name + "=" + std::to_string(index);
  if (has_count) r.source += " of " + count_name + "=" + std::to_string(count);
  readings->push_back(r);
  return true;
}

}  // namespace

bool IsSchedulerShard(const std::string& text) { return text.rfind("auto", 0) == 0; }

bool ShardFromScheduler(const std::string& text, const EnvironmentLookup& environment, Shard* shard,
                        std::string* source, std::string* error) {
  long given_count = 0;
  if (text != "auto") {
    if (text.rfind("auto/", 0) != 0 || !ParseCount(text.substr(5), &given_count) ||
        given_count < 1) {
      *error = "shard '" + text + "' must be auto, auto/N (N >= 1) or K/N";
      return false;
    }
  }
  std::vector<Reading> readings;
  if (!ReadSlurm(environment, &readings, error) ||
      !ReadZeroBased(environment, "JOB_COMPLETION_INDEX", "JOB_COMPLETIONS", &readings, error) ||
      !ReadZeroBased(environment, "AWS_BATCH_JOB_ARRAY_INDEX", "AWS_BATCH_JOB_ARRAY_SIZE",
                     &readings, error)) {
    return false;
  }
  if (readings.empty()) {
    *error =
        "shard auto: no scheduler's array index is set (SLURM_ARRAY_TASK_ID, "
        "JOB_COMPLETION_INDEX, AWS_BATCH_JOB_ARRAY_INDEX); outside a job array give --shard K/N";
    return false;
  }
  Reading chosen = readings.front();
  for (const Reading& r : readings) {
    if (r.index != chosen.index || (r.count && chosen.count && r.count != chosen.count)) {
      *error = "shard auto: the schedulers disagree: " + chosen.source + " but " + r.source;
      return false;
    }
    if (chosen.count == 0) chosen.count = r.count;
  }
  if (given_count != 0) {
    if (chosen.count != 0 && chosen.count != given_count) {
      *error = "shard " + text + ": the scheduler says " + std::to_string(chosen.count) +
               " tasks (" + chosen.source + ")";
      return false;
    }
    chosen.count = given_count;
  }
  if (chosen.count == 0) {
    *error = "shard auto: " + chosen.source +
             " gives the task's index but not the number of tasks: give --shard auto/N";
    return false;
  }
  if (chosen.index < 1 || chosen.index > chosen.count) {
    *error = "shard auto: " + chosen.source + " is task " + std::to_string(chosen.index) +
             " (1-based) of " + std::to_string(chosen.count) + ": outside 1.." +
             std::to_string(chosen.count);
    return false;
  }
  shard->index = static_cast<int>(chosen.index);
  shard->count = static_cast<int>(chosen.count);
  *source = chosen.source;
  return true;
}

EnvironmentLookup ProcessEnvironment() {
  return [](const std::string& name, std::string* value) {
    const char* v = std::getenv(name.c_str());
    if (v == nullptr) return false;
    *value = v;
    return true;
  };
}

}  // namespace internal
}  // namespace gravcal
