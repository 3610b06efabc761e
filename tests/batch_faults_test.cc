// Issue 20: faults during a batch. The output disk fills up, the output
// folder becomes unwritable, a unit's file changes while it is read, a unit
// runs away (--unit-timeout), SIGTERM arrives. In every case nothing already
// written is lost or corrupted, the summary (or the error line) says what
// happened, and running the same command again resumes to the result of a
// clean run.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "batch_test_util.h"
#include "cli_runner.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "test_util.h"
#include "util/cancellation.h"

namespace gravcal {
namespace {

using testing_util::CliResult;
using testing_util::Slurp;
using testing_util::WithoutTimes;

constexpr int kUnits = 6;

// Every finished JSON file in `folder` (and its batch_state) parses, and no
// temporary file is left.
void ExpectIntactFolder(const std::string& folder) {
  for (const std::string& f : {folder, folder + "/batch_state"}) {
    EXPECT_EQ(testing_util::CountNames(f, ".gravcal-tmp."), 0u) << f;
    for (const auto& [name, id] : testing_util::JsonFiles(f)) {
      const std::string text = Slurp(f + "/" + name);
      EXPECT_TRUE(nlohmann::json::accept(text)) << f << "/" << name << " is not whole JSON";
    }
  }
}

class BatchFaultsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new testing_util::ScratchDir();
    Config base;
    std::string error;
    ASSERT_TRUE(LoadConfigFile(ConfigPath(), &base, &error)) << error;
    SimulatorOptions sim = base.simulation;
    sim.hold_seconds = 3.0;
    sim.initial_still_seconds = 3.0;
    sim.rotation_seconds = 1.5;
    std::filesystem::create_directories(Fleet());
    for (int k = 0; k < kUnits; ++k) {
      SimulatedSession s;
      ASSERT_TRUE(Simulate(sim, 60 + k, &s, &error)) << error;
      ASSERT_TRUE(WriteImuLogCsv(s.log, UnitPath(k), &error)) << error;
    }
    const CliResult clean = RunBatch(*scratch_ / "clean");
    ASSERT_EQ(clean.exit_code, 0) << clean.err;
    clean_summary_ = new std::string(WithoutTimes(Slurp(*scratch_ / "clean/summary.csv")));
  }
  // Unit "hang" (a new FIFO at `fifo` that nobody writes: a hung network
  // file system looks the same), then unit1 .. unit<count - 1> of the
  // fleet; *base is the fleet's config. Failures are the test's.
  static std::vector<BatchUnit> HangThenUnits(const std::string& fifo, int count, Config* base) {
    EXPECT_EQ(mkfifo(fifo.c_str(), 0644), 0) << fifo;
    std::string error;
    EXPECT_TRUE(LoadConfigFile(ConfigPath(), base, &error)) << error;
    std::vector<BatchUnit> units(count);
    units[0].id = "hang";
    units[0].path = fifo;
    for (int k = 1; k < count; ++k) {
      units[k].id = "unit" + std::to_string(k);
      units[k].path = UnitPath(k);
    }
    return units;
  }
  static void TearDownTestSuite() {
    delete scratch_;
    delete clean_summary_;
  }

  static std::string ConfigPath() {
    return testing_util::SourceDir() + "/configs/twelve_position.yaml";
  }
  static std::string Fleet() { return *scratch_ / "fleet"; }
  static std::string UnitPath(int k) { return Fleet() + "/unit" + std::to_string(k) + ".csv"; }
  static std::vector<std::string> BatchArgs(const std::string& out,
                                            const std::vector<std::string>& extra = {}) {
    std::vector<std::string> args = {"batch",    "--input-dir", Fleet(),
                                     "--config", ConfigPath(),  "--output-dir",
                                     out,        "--threads",   "1"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  }
  static CliResult RunBatch(const std::string& out, const std::vector<std::string>& extra = {}) {
    return testing_util::RunCli(BatchArgs(out, extra), *scratch_);
  }
  // Runs again and expects the clean run's summary.
  static void ExpectResumesToCleanResult(const std::string& out) {
    const CliResult again = RunBatch(out);
    EXPECT_EQ(again.exit_code, 0) << again.err;
    EXPECT_EQ(WithoutTimes(Slurp(out + "/summary.csv")), *clean_summary_);
    ExpectIntactFolder(out);
  }

  static testing_util::ScratchDir* scratch_;
  static std::string* clean_summary_;
};

testing_util::ScratchDir* BatchFaultsTest::scratch_ = nullptr;
std::string* BatchFaultsTest::clean_summary_ = nullptr;

// A small tmpfs of our own, mounted when we may (root with CAP_SYS_ADMIN).
class ScopedTmpfs {
 public:
  ScopedTmpfs(const std::string& path, const std::string& size) : path_(path) {
    std::filesystem::create_directories(path);
    mounted_ =
        geteuid() == 0 && mount("tmpfs", path.c_str(), "tmpfs", 0, ("size=" + size).c_str()) == 0;
  }
  ~ScopedTmpfs() {
    if (mounted_) umount2(path_.c_str(), MNT_DETACH);
  }
  bool mounted() const { return mounted_; }
  bool RemountReadOnly() const {
    return mount("tmpfs", path_.c_str(), "tmpfs", MS_REMOUNT | MS_RDONLY, nullptr) == 0;
  }
  bool RemountWritable() const {
    return mount("tmpfs", path_.c_str(), "tmpfs", MS_REMOUNT, nullptr) == 0;
  }

 private:
  std::string path_;
  bool mounted_ = false;
};

TEST_F(BatchFaultsTest, OutputDiskFullStopsTheBatchAndResumesWhenThereIsSpace) {
  const std::string disk = *scratch_ / "small_disk";
  ScopedTmpfs tmpfs(disk, "512k");
  if (!tmpfs.mounted()) GTEST_SKIP() << "mounting a tmpfs needs root (CAP_SYS_ADMIN)";
  const std::string out = disk + "/out";
  // Leave room for about one unit's files (a calibration JSON is ~6 KB).
  struct statvfs fs;
  ASSERT_EQ(statvfs(disk.c_str(), &fs), 0);
  const size_t free_bytes = static_cast<size_t>(fs.f_bavail) * fs.f_frsize;
  const size_t room = 24 * 1024;
  ASSERT_GT(free_bytes, room);
  const std::string filler = disk + "/filler";
  std::ofstream(filler, std::ios::binary) << std::string(free_bytes - room, 'x');

  const CliResult full = RunBatch(out);
  EXPECT_EQ(full.exit_code, 1) << full.err;
  EXPECT_NE(full.err.find("No space left on device"), std::string::npos) << full.err;
  EXPECT_NE(full.err.find("again to resume"), std::string::npos) << full.err;
  ExpectIntactFolder(out);
  const auto states = testing_util::JsonFiles(out + "/batch_state");
  const auto written = testing_util::JsonFiles(out);

  std::filesystem::remove(filler);
  ExpectResumesToCleanResult(out);
  // A unit whose state was stored is kept, not recomputed (a result whose
  // state file did not fit is computed again).
  const auto states_after = testing_util::JsonFiles(out + "/batch_state");
  const auto after = testing_util::JsonFiles(out);
  for (const auto& [name, id] : states) {
    EXPECT_TRUE(states_after.at(name) == id) << name << " state was rewritten";
    if (written.count(name)) EXPECT_TRUE(after.at(name) == written.at(name)) << name;
  }
}

TEST_F(BatchFaultsTest, OutputFolderBecomingUnwritableLosesNothingWritten) {
  const std::string mount_point = *scratch_ / "ro_disk";
  ScopedTmpfs tmpfs(mount_point, "4m");
  const bool root = geteuid() == 0;
  if (root && !tmpfs.mounted()) GTEST_SKIP() << "root, but a tmpfs cannot be mounted here";
  const std::string out = mount_point + "/out";
  // Half of the fleet first.
  CliResult r = RunBatch(out, {"--shard", "1/2"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto before = testing_util::JsonFiles(out);
  const auto state_before = testing_util::JsonFiles(out + "/batch_state");
  // Root writes through permissions: make the file system read-only instead.
  if (root) {
    ASSERT_TRUE(tmpfs.RemountReadOnly());
  } else {
    chmod((out + "/batch_state").c_str(), 0555);
    chmod(out.c_str(), 0555);
  }
  r = RunBatch(out);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(root ? "Read-only file system" : "Permission denied"), std::string::npos)
      << r.err;
  // The destination contract checks the output folder before any unit is
  // calibrated, so the refusal names the folder, not a result.
  EXPECT_NE(r.err.find(out + ": cannot write in the folder"), std::string::npos) << r.err;
  if (root) {
    ASSERT_TRUE(tmpfs.RemountWritable());
  } else {
    chmod(out.c_str(), 0755);
    chmod((out + "/batch_state").c_str(), 0755);
  }
  EXPECT_TRUE(testing_util::JsonFiles(out) == before);
  EXPECT_TRUE(testing_util::JsonFiles(out + "/batch_state") == state_before);
  ExpectIntactFolder(out);
  ExpectResumesToCleanResult(out);
}

// One unit's file is truncated and rewritten in place, and replaced by
// another file renamed over it, over and over while batches read it: every
// run ends with that unit calibrated or failed with a message naming it,
// never a crash or a result marked current for bytes it did not use; once
// the file is left alone, a run resumes to the clean result.
TEST_F(BatchFaultsTest, UnitFileRewrittenWhileBeingReadGivesAResultOrAMessage) {
  const std::string victim = UnitPath(2);
  const std::string replacement = *scratch_ / "replacement.csv";
  const std::string good = Slurp(victim);
  std::atomic<bool> done{false};
  std::thread churn([&] {
    for (int i = 0; !done; ++i) {
      const bool replace = i % 4 >= 2;  // Two rewrites in place, two replacements.
      std::ofstream f(replace ? replacement : victim, std::ios::binary | std::ios::trunc);
      f << good.substr(0, (i % 2 == 0) ? good.size() / 3 : good.size());
      f.close();
      if (replace) std::filesystem::rename(replacement, victim);
    }
  });
  const std::string out = *scratch_ / "churn";
  for (int run = 0; run < 3; ++run) {
    const CliResult r = RunBatch(out);
    EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1) << r.err;
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    std::vector<SummaryRow> rows;
    std::string error;
    ASSERT_TRUE(ParseSummaryCsv(Slurp(out + "/summary.csv"), "summary.csv", &rows, &error))
        << error;
    ASSERT_EQ(rows.size(), static_cast<size_t>(kUnits));
    for (const SummaryRow& row : rows) {
      if (row.unit == "unit2" && row.status != BatchStatus::kOk) {
        EXPECT_NE(row.message.find("unit2.csv"), std::string::npos) << row.message;
      } else {
        EXPECT_EQ(row.status, BatchStatus::kOk) << row.unit << ": " << row.message;
      }
    }
  }
  done = true;
  churn.join();
  std::ofstream(victim, std::ios::binary | std::ios::trunc) << good;
  ExpectResumesToCleanResult(out);
}

// A unit whose file never delivers (a FIFO nobody writes: a hung network
// file system looks the same): with --unit-timeout it fails with a message
// and the rest of the batch is calibrated.
TEST_F(BatchFaultsTest, RunawayUnitTimesOutAndTheBatchGoesOn) {
  const std::string fifo = *scratch_ / "hang.csv";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
  std::string manifest = "unit,path\nhang," + fifo + "\n";
  for (int k = 0; k < 3; ++k) {
    manifest += "unit" + std::to_string(k) + "," + UnitPath(k) + "\n";
  }
  const std::string units = scratch_->Write("runaway_units.csv", manifest);
  const std::string out = *scratch_ / "runaway";
  const CliResult r =
      testing_util::RunCli({"batch", "--manifest", units, "--config", ConfigPath(), "--output-dir",
                            out, "--threads", "2", "--unit-timeout", "1"},
                           *scratch_);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("hang: timed out after 1 s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 timed out"), std::string::npos) << r.err;
  std::vector<SummaryRow> rows;
  std::string error;
  ASSERT_TRUE(ParseSummaryCsv(Slurp(out + "/summary.csv"), "summary.csv", &rows, &error)) << error;
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0].status, BatchStatus::kFailed);
  EXPECT_NE(rows[0].message.find("timed out"), std::string::npos) << rows[0].message;
  for (size_t i = 1; i < rows.size(); ++i) EXPECT_EQ(rows[i].status, BatchStatus::kOk) << i;
  EXPECT_FALSE(testing_util::FileExists(out + "/batch_state/hang.json"));
  ExpectIntactFolder(out);
}

// The library: the abandoned worker comes back after CalibrateBatch has
// returned (the FIFO is opened for writing at the end) and touches nothing
// of the caller's; a fresh worker took its place meanwhile.
TEST_F(BatchFaultsTest, LibraryAbandonsTheRunawayWorkerSafely) {
  const std::string fifo = *scratch_ / "hang_library.csv";
  Config base;
  std::vector<BatchUnit> units = HangThenUnits(fifo, 3, &base);
  ASSERT_FALSE(HasFailure());
  std::string error;
  BatchOptions options;
  options.threads = 1;
  options.unit_timeout_seconds = 0.5;
  std::atomic<int> calls{0};
  options.on_result = [&calls](size_t, const BatchResult&) { ++calls; };
  std::vector<BatchResult> results;
  ASSERT_TRUE(CalibrateBatch(units, base, options, &results, &error)) << error;
  ASSERT_EQ(results.size(), 3u);
  EXPECT_TRUE(results[0].timed_out);
  EXPECT_EQ(results[0].status, BatchStatus::kFailed);
  EXPECT_NE(results[0].message.find("timed out after 0.5 s"), std::string::npos);
  EXPECT_EQ(results[1].status, BatchStatus::kOk) << results[1].message;
  EXPECT_EQ(results[2].status, BatchStatus::kOk) << results[2].message;
  EXPECT_EQ(calls, 2);  // Not for the abandoned unit.
  // Release the abandoned reader: it reads an empty file and goes away.
  const int fd = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
  if (fd >= 0) close(fd);
  units.clear();
  results.clear();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(calls, 2);
}

// A stop (what SIGTERM sets) while a unit hangs: the hanging unit is
// abandoned once stop_grace_seconds are over, not waited for; the unit no
// worker started is not run; each says so, and no callback is called for
// either. The abandoned worker comes back after the run and touches nothing.
TEST_F(BatchFaultsTest, StopAbandonsTheUnitStillInFlightAfterTheGrace) {
  const std::string fifo = *scratch_ / "hang_on_stop.csv";
  Config base;
  std::vector<BatchUnit> units = HangThenUnits(fifo, 2, &base);
  ASSERT_FALSE(HasFailure());
  std::string error;
  std::atomic<bool> stop{false};
  BatchOptions options;
  options.threads = 1;
  options.stop = &stop;
  options.stop_grace_seconds = 0.3;
  std::atomic<int> calls{0};
  options.on_result = [&calls](size_t, const BatchResult&) { ++calls; };
  // The stop comes once the worker has opened the FIFO (opening its write
  // end without blocking succeeds only then); the write end stays open and
  // silent, so the worker hangs in its read.
  std::atomic<int> writer{-1};
  std::thread stopper([&] {
    for (int i = 0; i < 60000 && writer < 0; ++i) {
      writer = open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
      if (writer < 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    stop = true;
  });
  std::vector<BatchResult> results;
  const bool ran = CalibrateBatch(units, base, options, &results, &error);
  stopper.join();
  ASSERT_TRUE(ran) << error;
  ASSERT_GE(writer, 0) << "the worker never opened the FIFO";
  ASSERT_EQ(results.size(), 2u);
  EXPECT_EQ(results[0].status, BatchStatus::kFailed);
  EXPECT_TRUE(results[0].not_run);
  EXPECT_FALSE(results[0].timed_out);
  EXPECT_NE(results[0].message.find("hang: abandoned in flight: the batch was stopped"),
            std::string::npos)
      << results[0].message;
  EXPECT_EQ(results[1].status, BatchStatus::kFailed);
  EXPECT_TRUE(results[1].not_run);
  EXPECT_NE(results[1].message.find("unit1: not run"), std::string::npos) << results[1].message;
  EXPECT_EQ(calls, 0);
  // Release the abandoned reader: it reads an empty file and goes away.
  close(writer);
  units.clear();
  results.clear();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(calls, 0);
}

// SIGTERM in the middle: the unit in flight finishes, no new one starts, the
// summary says which were not run, and the next run completes the fleet
// without redoing what was done.
TEST_F(BatchFaultsTest, SigtermFinishesTheUnitInFlightAndLeavesAResumableState) {
  const std::string out = *scratch_ / "sigterm";
  const pid_t pid = testing_util::SpawnCli(BatchArgs(out), *scratch_ / "term_out.txt",
                                           *scratch_ / "term_err.txt");
  ASSERT_GT(pid, 0);
  // Wait for the first unit's state file, then stop the batch.
  for (int i = 0; i < 6000 && testing_util::CountNames(out + "/batch_state", ".json") == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  kill(pid, SIGTERM);
  const int exit_code = testing_util::WaitForExit(pid);
  const std::string err = Slurp(*scratch_ / "term_err.txt");
  EXPECT_EQ(exit_code, 1) << err;
  EXPECT_NE(err.find("stopped by SIGTERM"), std::string::npos) << err;
  EXPECT_NE(err.find("run the same command again to resume"), std::string::npos) << err;
  std::vector<SummaryRow> rows;
  std::string error;
  ASSERT_TRUE(ParseSummaryCsv(Slurp(out + "/summary.csv"), "summary.csv", &rows, &error)) << error;
  ASSERT_EQ(rows.size(), static_cast<size_t>(kUnits));
  size_t ok = 0, not_run = 0;
  for (const SummaryRow& row : rows) {
    ok += row.status == BatchStatus::kOk;
    not_run += row.message.find("not run") != std::string::npos;
  }
  EXPECT_GE(ok, 1u);
  EXPECT_GE(not_run, 1u);
  EXPECT_EQ(ok + not_run, static_cast<size_t>(kUnits));
  ExpectIntactFolder(out);
  const auto written = testing_util::JsonFiles(out);
  ExpectResumesToCleanResult(out);
  const auto after = testing_util::JsonFiles(out);
  for (const auto& [name, id] : written) {
    if (name == "summary.json") continue;
    EXPECT_TRUE(after.at(name) == id) << name << " was rewritten";
  }
}

// A unit over its time limit is asked to stop: the solver aborts at its
// next iteration (an iteration callback on every solve of the library)
// instead of running on for nothing.
TEST_F(BatchFaultsTest, TheSolverStopsWhenTheUnitIsCancelled) {
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(ConfigPath(), &config, &error)) << error;
  PipelineInput input;
  input.source = UnitPath(0);
  ASSERT_TRUE(ReadImuLog(UnitPath(0), config.input, &input.log, &error)) << error;
  Calibration calibration;
  ASSERT_TRUE(RunCalibration(config, input, &calibration)) << calibration.message;
  std::atomic<bool> cancel{true};
  internal::ScopedCancelFlag scope(&cancel);
  Calibration cancelled;
  EXPECT_FALSE(RunCalibration(config, input, &cancelled));
  EXPECT_NE(cancelled.refinement.termination.find("USER_FAILURE"), std::string::npos)
      << cancelled.refinement.termination << ": " << cancelled.message;
}

}  // namespace
}  // namespace gravcal
