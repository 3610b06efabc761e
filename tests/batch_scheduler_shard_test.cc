// Issue 20: --shard auto takes K/N from the scheduler's job array (Slurm,
// Kubernetes Indexed Jobs, AWS Batch); the same fleet run as N processes
// with those variables set and merged equals one run.
#include "workflows/batch_scheduler_shard.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "batch_test_util.h"
#include "cli_runner.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "test_util.h"

namespace gravcal {

using internal::EnvironmentLookup;
using internal::ShardFromScheduler;
namespace {

using Env = std::map<std::string, std::string>;

EnvironmentLookup Lookup(const Env& env) {
  return [env](const std::string& name, std::string* value) {
    const auto it = env.find(name);
    if (it == env.end()) return false;
    *value = it->second;
    return true;
  };
}

struct Outcome {
  bool ok = false;
  Shard shard;
  std::string source;
  std::string error;
};

Outcome Resolve(const std::string& text, const Env& env) {
  Outcome o;
  o.ok = ShardFromScheduler(text, Lookup(env), &o.shard, &o.source, &o.error);
  return o;
}

TEST(SchedulerShard, SlurmArrayIndexFromMinMaxOrCount) {
  Outcome o = Resolve("auto", {{"SLURM_ARRAY_TASK_ID", "5"},
                               {"SLURM_ARRAY_TASK_MIN", "0"},
                               {"SLURM_ARRAY_TASK_MAX", "15"}});
  ASSERT_TRUE(o.ok) << o.error;
  EXPECT_EQ(o.shard.index, 6);
  EXPECT_EQ(o.shard.count, 16);
  EXPECT_NE(o.source.find("SLURM_ARRAY_TASK_ID=5"), std::string::npos) << o.source;
  // --array=1-4 with the count.
  o = Resolve("auto", {{"SLURM_ARRAY_TASK_ID", "4"},
                       {"SLURM_ARRAY_TASK_MIN", "1"},
                       {"SLURM_ARRAY_TASK_COUNT", "4"}});
  ASSERT_TRUE(o.ok) << o.error;
  EXPECT_EQ(o.shard.index, 4);
  EXPECT_EQ(o.shard.count, 4);
  // auto/N agreeing with the array is fine.
  o = Resolve(
      "auto/4",
      {{"SLURM_ARRAY_TASK_ID", "1"}, {"SLURM_ARRAY_TASK_MIN", "1"}, {"SLURM_ARRAY_TASK_MAX", "4"}});
  ASSERT_TRUE(o.ok) << o.error;
  EXPECT_EQ(o.shard.index, 1);
}

TEST(SchedulerShard, KubernetesAndAwsBatchIndexesAreZeroBased) {
  Outcome o = Resolve("auto/8", {{"JOB_COMPLETION_INDEX", "7"}});
  ASSERT_TRUE(o.ok) << o.error;
  EXPECT_EQ(o.shard.index, 8);
  EXPECT_EQ(o.shard.count, 8);
  o = Resolve("auto", {{"JOB_COMPLETION_INDEX", "0"}, {"JOB_COMPLETIONS", "3"}});
  ASSERT_TRUE(o.ok) << o.error;
  EXPECT_EQ(o.shard.index, 1);
  EXPECT_EQ(o.shard.count, 3);
  o = Resolve("auto", {{"AWS_BATCH_JOB_ARRAY_INDEX", "2"}, {"AWS_BATCH_JOB_ARRAY_SIZE", "10"}});
  ASSERT_TRUE(o.ok) << o.error;
  EXPECT_EQ(o.shard.index, 3);
  EXPECT_EQ(o.shard.count, 10);
}

TEST(SchedulerShard, ErrorsSayWhatIsMissingOrDisagrees) {
  struct Case {
    std::string text;
    Env env;
    std::string expect;
  };
  const std::vector<Case> cases = {
      {"auto", {}, "no scheduler's array index is set"},
      {"auto", {{"JOB_COMPLETION_INDEX", "2"}}, "give --shard auto/N"},
      {"auto/2", {{"JOB_COMPLETION_INDEX", "2"}}, "outside 1..2"},
      {"auto/5",
       {{"AWS_BATCH_JOB_ARRAY_INDEX", "1"}, {"AWS_BATCH_JOB_ARRAY_SIZE", "4"}},
       "the scheduler says 4 tasks"},
      {"auto",
       {{"SLURM_ARRAY_TASK_ID", "3"},
        {"SLURM_ARRAY_TASK_MIN", "0"},
        {"SLURM_ARRAY_TASK_MAX", "7"},
        {"JOB_COMPLETION_INDEX", "1"}},
       "the schedulers disagree"},
      {"auto",
       {{"SLURM_ARRAY_TASK_ID", "3"}, {"SLURM_ARRAY_TASK_MAX", "7"}},
       "SLURM_ARRAY_TASK_MIN is not"},
      {"auto",
       {{"SLURM_ARRAY_TASK_ID", "4"},
        {"SLURM_ARRAY_TASK_MIN", "0"},
        {"SLURM_ARRAY_TASK_MAX", "12"},
        {"SLURM_ARRAY_TASK_STEP", "4"}},
       "step 4"},
      {"auto",
       {{"SLURM_ARRAY_TASK_ID", "4"},
        {"SLURM_ARRAY_TASK_MIN", "1"},
        {"SLURM_ARRAY_TASK_MAX", "9"},
        {"SLURM_ARRAY_TASK_COUNT", "3"}},
       "cannot be split by index"},
      {"auto", {{"JOB_COMPLETION_INDEX", "x"}}, "not a whole number"},
      {"auto/0", {{"JOB_COMPLETION_INDEX", "0"}}, "must be auto, auto/N"},
      {"autox", {{"JOB_COMPLETION_INDEX", "0"}}, "must be auto, auto/N"},
  };
  for (const Case& c : cases) {
    const Outcome o = Resolve(c.text, c.env);
    EXPECT_FALSE(o.ok) << c.expect;
    EXPECT_NE(o.error.find(c.expect), std::string::npos) << o.error;
  }
}

// The scheduler's variables as the CLI sees them (the child inherits this
// process's environment).
class ScopedEnv {
 public:
  explicit ScopedEnv(const Env& env) : env_(env) {
    for (const auto& [k, v] : env_) setenv(k.c_str(), v.c_str(), 1);
  }
  ~ScopedEnv() {
    for (const auto& [k, v] : env_) unsetenv(k.c_str());
  }

 private:
  Env env_;
};

// Seven units as a Slurm array of three tasks, a Kubernetes Indexed Job of
// three and an AWS Batch array of three, each merged: the merged summary is
// the one-process summary, row for row (times aside).
TEST(SchedulerShard, FleetRunAsArrayTasksAndMergedEqualsOneRun) {
  testing_util::ScratchDir scratch;
  const std::string config = testing_util::SourceDir() + "/configs/twelve_position.yaml";
  Config base;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(config, &base, &error)) << error;
  SimulatorOptions sim = base.simulation;
  sim.hold_seconds = 3.0;
  sim.initial_still_seconds = 3.0;
  sim.rotation_seconds = 1.5;
  const std::string fleet = scratch / "fleet";
  std::filesystem::create_directories(fleet);
  for (int k = 0; k < 7; ++k) {
    SimulatedSession s;
    ASSERT_TRUE(Simulate(sim, 40 + k, &s, &error)) << error;
    ASSERT_TRUE(WriteImuLogCsv(s.log, fleet + "/unit" + std::to_string(k) + ".csv", &error));
  }
  auto batch = [&](const std::string& out, const std::string& shard) {
    std::vector<std::string> args = {"batch",        "--input-dir", fleet,       "--config", config,
                                     "--output-dir", out,           "--threads", "1"};
    if (!shard.empty()) {
      args.push_back("--shard");
      args.push_back(shard);
    }
    return testing_util::RunCli(args, scratch);
  };
  const testing_util::CliResult one = batch(scratch / "one", "");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const std::string expected =
      testing_util::WithoutTimes(testing_util::Slurp(scratch / "one/summary.csv"));

  const std::vector<std::pair<std::string, std::vector<Env>>> schedulers = {
      {"slurm",
       {{{"SLURM_ARRAY_TASK_ID", "1"},
         {"SLURM_ARRAY_TASK_MIN", "1"},
         {"SLURM_ARRAY_TASK_MAX", "3"}},
        {{"SLURM_ARRAY_TASK_ID", "2"},
         {"SLURM_ARRAY_TASK_MIN", "1"},
         {"SLURM_ARRAY_TASK_MAX", "3"}},
        {{"SLURM_ARRAY_TASK_ID", "3"},
         {"SLURM_ARRAY_TASK_MIN", "1"},
         {"SLURM_ARRAY_TASK_MAX", "3"}}}},
      {"kubernetes",
       {{{"JOB_COMPLETION_INDEX", "0"}},
        {{"JOB_COMPLETION_INDEX", "1"}},
        {{"JOB_COMPLETION_INDEX", "2"}}}},
      {"aws",
       {{{"AWS_BATCH_JOB_ARRAY_INDEX", "0"}, {"AWS_BATCH_JOB_ARRAY_SIZE", "3"}},
        {{"AWS_BATCH_JOB_ARRAY_INDEX", "1"}, {"AWS_BATCH_JOB_ARRAY_SIZE", "3"}},
        {{"AWS_BATCH_JOB_ARRAY_INDEX", "2"}, {"AWS_BATCH_JOB_ARRAY_SIZE", "3"}}}},
  };
  for (const auto& [name, tasks] : schedulers) {
    std::vector<std::string> merge = {"merge-summaries", "--output-dir", scratch / (name + "_all")};
    for (size_t t = 0; t < tasks.size(); ++t) {
      const std::string out = scratch / (name + std::to_string(t));
      ScopedEnv env(tasks[t]);
      const testing_util::CliResult r = batch(out, name == "kubernetes" ? "auto/3" : "auto");
      ASSERT_EQ(r.exit_code, 0) << name << " task " << t << ": " << r.err;
      EXPECT_NE(r.err.find("shard " + std::to_string(t + 1) + "/3 from"), std::string::npos)
          << r.err;
      merge.push_back(out);
    }
    const testing_util::CliResult m = testing_util::RunCli(merge, scratch);
    ASSERT_EQ(m.exit_code, 0) << name << ": " << m.err;
    EXPECT_EQ(
        testing_util::WithoutTimes(testing_util::Slurp(scratch / (name + "_all/summary.csv"))),
        expected)
        << name;
  }
}

}  // namespace
}  // namespace gravcal
