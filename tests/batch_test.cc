// Batch calibration: the library API (CalibrateBatch), the manifest, the
// fleet statistics, and `gravcal batch` / `gravcal merge-summaries` end to end
// on a dozen short simulated units, some of them bad.
#include "gravcal/workflows/batch.h"

#include <dirent.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "batch_test_util.h"
#include "cli_runner.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/batch_manifest.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/fleet_summary.h"
#include "gravcal/workflows/pipeline.h"
#include "test_util.h"

namespace gravcal {
namespace {

using nlohmann::json;

using testing_util::CountNames;
using testing_util::FileId;
using testing_util::JsonFiles;
using testing_util::Slurp;
using testing_util::WithoutTime;
using testing_util::WithoutTimes;

struct Process {
  int exit_code = -1;
  std::string err;
};

// Twelve units: nine good ones (one with its own gravity, one with a planted
// accelerometer bias), a corrupt file, a missing file and a session with
// too few poses.
class BatchTest : public ::testing::Test {
 protected:
  static constexpr int kGood = 9;
  static constexpr int kOutlier = 4;
  static constexpr int kOwnGravity = 2;
  // The fleet's biases spread by 0.05 m/s^2 (80 counts), as units of one
  // production batch might; the planted 1500 counts (0.9 m/s^2) are about 18
  // times that.
  static constexpr double kFleetBiasStd = 0.05;
  static constexpr double kPlantedBias = 1500.0;

  static void SetUpTestSuite() {
    scratch_ = new testing_util::ScratchDir();
    dir_ = new std::string(scratch_->path());
    config_path_ = new std::string(testing_util::SourceDir() + "/configs/twelve_position.yaml");
    std::string error;
    ASSERT_TRUE(LoadConfigFile(*config_path_, &base_, &error)) << error;
    SimulatorOptions sim = base_.simulation;
    sim.hold_seconds = 4.0;
    sim.initial_still_seconds = 4.0;
    sim.rotation_seconds = 2.0;
    sim.accel_bias_std = kFleetBiasStd;
    std::string manifest = "# twelve units\nunit,path,gravity\n";
    for (int k = 0; k < kGood; ++k) {
      SimulatedSession s;
      ASSERT_TRUE(Simulate(sim, 100 + k, &s, &error)) << error;
      if (k == kOutlier) {
        for (Eigen::Vector3d& a : s.log.accel) a.x() += kPlantedBias;
      }
      const std::string name = "u0" + std::to_string(k);
      ASSERT_TRUE(WriteImuLogCsv(s.log, *dir_ + "/" + name + ".csv", &error)) << error;
      manifest += name + "," + name + ".csv," + (k == kOwnGravity ? "9.81" : "") + "\n";
    }
    // Corrupt: a cell that is not a number in the middle of the file.
    std::string good = Slurp(*dir_ + "/u00.csv");
    const size_t line = good.find('\n', good.size() / 2);
    good.insert(line + 1, "12.5,abc,1,2\n");
    std::ofstream(*dir_ + "/u09.csv") << good;
    // Six poses cannot determine the nine scale_misalignment parameters.
    SimulatorOptions six = sim;
    six.scheme = {PoseScheme::kRandom, 6};
    SimulatedSession s;
    ASSERT_TRUE(Simulate(six, 11, &s, &error)) << error;
    ASSERT_TRUE(WriteImuLogCsv(s.log, *dir_ + "/u11.csv", &error)) << error;
    manifest += "u09,u09.csv,\nu10,missing.csv,\nu11,u11.csv,\n";
    std::ofstream(*dir_ + "/units.csv") << manifest;
  }

  static void TearDownTestSuite() {
    delete scratch_;
    delete dir_;
    delete config_path_;
  }

  static Process Run(const std::vector<std::string>& args) {
    const testing_util::CliResult r = testing_util::RunCli(args, *scratch_);
    return {r.exit_code, r.err};
  }

  static Process RunBatch(const std::string& out, std::vector<std::string> extra = {}) {
    std::vector<std::string> args = {"batch",    "--manifest",  *dir_ + "/units.csv",
                                     "--config", *config_path_, "--output-dir",
                                     out,        "--threads",   "2"};
    args.insert(args.end(), extra.begin(), extra.end());
    return Run(args);
  }

  static std::vector<BatchUnit> Units() {
    std::vector<BatchUnit> units;
    std::string error;
    EXPECT_TRUE(ReadBatchManifest(*dir_ + "/units.csv", base_, &units, &error)) << error;
    return units;
  }

  static testing_util::ScratchDir* scratch_;
  static std::string* dir_;
  static std::string* config_path_;
  static Config base_;
};

testing_util::ScratchDir* BatchTest::scratch_ = nullptr;
std::string* BatchTest::dir_ = nullptr;
std::string* BatchTest::config_path_ = nullptr;
Config BatchTest::base_;

TEST_F(BatchTest, LibraryResultsEqualRunCalibrationAloneInInputOrder) {
  std::vector<BatchUnit> units = Units();
  ASSERT_EQ(units.size(), 12u);
  // One unit in memory instead of a path.
  std::string error;
  ASSERT_TRUE(ReadImuLog(units[1].path, base_.input, &units[1].log, &error)) << error;
  units[1].path.clear();
  BatchOptions options;
  options.threads = 2;
  std::vector<BatchResult> results;
  ASSERT_TRUE(CalibrateBatch(units, base_, options, &results, &error)) << error;
  ASSERT_EQ(results.size(), units.size());
  for (size_t i = 0; i < units.size(); ++i) {
    SCOPED_TRACE(units[i].id);
    EXPECT_EQ(results[i].unit, units[i].id);
    if (i >= static_cast<size_t>(kGood)) continue;
    ASSERT_EQ(results[i].status, BatchStatus::kOk) << results[i].message;
    Config config;
    ASSERT_TRUE(EffectiveConfig(units[i], base_, &config, &error)) << error;
    PipelineInput input;
    input.log = units[i].log;
    if (!units[i].path.empty()) {
      ASSERT_TRUE(ReadImuLog(units[i].path, config.input, &input.log, &error)) << error;
    }
    Calibration alone;
    ASSERT_TRUE(RunCalibration(config, input, &alone)) << alone.message;
    // Issue 16: batch records the log's provenance, as calibrate does.
    if (!units[i].path.empty()) {
      std::string bytes;
      ASSERT_TRUE(ReadFileBytes(units[i].path, &bytes, &error)) << error;
      alone.provenance = LogProvenanceOfBytes(units[i].path, bytes);
    }
    EXPECT_EQ(WithoutTime(CalibrationToJson(results[i].calibration, true)),
              WithoutTime(CalibrationToJson(alone, true)));
    EXPECT_EQ(results[i].content_hash.size(), 32u);
  }
  EXPECT_NEAR(results[kOwnGravity].calibration.gravity, 9.81, 1e-15);
  EXPECT_EQ(results[9].status, BatchStatus::kFailed);
  EXPECT_NE(results[9].message.find("u09.csv:"), std::string::npos) << results[9].message;
  EXPECT_NE(results[9].message.find("abc"), std::string::npos) << results[9].message;
  EXPECT_EQ(results[10].status, BatchStatus::kFailed);
  EXPECT_NE(results[10].message.find("missing.csv: cannot open"), std::string::npos)
      << results[10].message;
  EXPECT_TRUE(results[10].content_hash.empty());
  EXPECT_EQ(results[11].status, BatchStatus::kFailed);
  EXPECT_NE(results[11].message.find("found 6 static positions"), std::string::npos)
      << results[11].message;

  // One thread gives the same numbers; a changed override changes the hash.
  options.threads = 1;
  std::vector<BatchResult> serial;
  ASSERT_TRUE(CalibrateBatch(units, base_, options, &serial, &error)) << error;
  for (size_t i = 0; i < units.size(); ++i) {
    EXPECT_EQ(serial[i].content_hash, results[i].content_hash);
    EXPECT_EQ(serial[i].calibration.accel.model.bias, results[i].calibration.accel.model.bias);
  }
  units[0].overrides.emplace_back("gravity", "9.8");
  std::vector<BatchUnit> one = {units[0]};
  ASSERT_TRUE(CalibrateBatch(one, base_, options, &serial, &error)) << error;
  EXPECT_NE(serial[0].content_hash, results[0].content_hash);
}

TEST_F(BatchTest, ExceptionsInCallbacksFailOnlyThatUnit) {
  std::vector<BatchUnit> units = Units();
  units.resize(3);
  BatchOptions options;
  options.threads = 2;
  options.keep_calibrations = false;
  options.on_result = [](size_t i, const BatchResult&) {
    if (i == 1) throw std::runtime_error("disk full");
  };
  std::vector<BatchResult> results;
  std::string error;
  ASSERT_TRUE(CalibrateBatch(units, base_, options, &results, &error)) << error;
  EXPECT_EQ(results[0].status, BatchStatus::kOk);
  EXPECT_EQ(results[1].status, BatchStatus::kFailed);
  EXPECT_EQ(results[1].message, "u01: the result could not be stored: disk full");
  EXPECT_EQ(results[2].status, BatchStatus::kOk);
  EXPECT_TRUE(results[0].calibration.positions.empty());
  options.threads = -1;
  EXPECT_FALSE(CalibrateBatch(units, base_, options, &results, &error));
  EXPECT_NE(error.find("threads"), std::string::npos);
}

TEST_F(BatchTest, CliGoodUnitsEqualCalibrateAloneAndBadUnitsHaveMessages) {
  const std::string out = *dir_ + "/cli";
  const Process p = RunBatch(out);
  EXPECT_EQ(p.exit_code, 1) << p.err;
  EXPECT_NE(p.err.find("gravcal: error: 3 of 12 units failed"), std::string::npos) << p.err;
  for (int k = 0; k < kGood; ++k) {
    const std::string unit = "u0" + std::to_string(k);
    SCOPED_TRACE(unit);
    const std::string alone = *dir_ + "/alone_" + unit + ".json";
    std::vector<std::string> args = {"calibrate", "--input",     *dir_ + "/" + unit + ".csv",
                                     "--config",  *config_path_, "--output",
                                     alone};
    if (k == kOwnGravity) args.insert(args.end(), {"--gravity", "9.81"});
    const Process c = Run(args);
    ASSERT_EQ(c.exit_code, 0) << c.err;
    EXPECT_EQ(WithoutTime(Slurp(out + "/" + unit + ".json")), WithoutTime(Slurp(alone)));
  }
  for (const char* bad : {"u09", "u10", "u11"}) {
    struct stat st;
    EXPECT_NE(stat((out + "/" + bad + ".json").c_str(), &st), 0) << bad;
  }
  std::vector<SummaryRow> rows;
  std::string error;
  ASSERT_TRUE(ParseSummaryCsv(Slurp(out + "/summary.csv"), "summary.csv", &rows, &error)) << error;
  ASSERT_EQ(rows.size(), 12u);
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].index, i);
    EXPECT_EQ(rows[i].status, i < kGood ? BatchStatus::kOk : BatchStatus::kFailed) << i;
  }
  EXPECT_NE(rows[9].message.find("'abc'"), std::string::npos) << rows[9].message;
  EXPECT_NE(rows[10].message.find("cannot open"), std::string::npos) << rows[10].message;
  EXPECT_NE(rows[11].message.find("needs at least 9"), std::string::npos) << rows[11].message;
  const json calib = json::parse(Slurp(out + "/u00.json"));
  EXPECT_EQ(rows[0].values.at("accel_bias_y"), calib["accel"]["bias"][1].get<double>());
  EXPECT_EQ(rows[0].values.at("accel_m_xy_std"),
            calib["accel"]["std"]["matrix"][0][1].get<double>());
  EXPECT_TRUE(std::isnan(rows[0].values.at("accel_m_yx_std")));  // not estimated: empty cell

  const json summary = json::parse(Slurp(out + "/summary.json"));
  EXPECT_EQ(summary["units"], 12);
  EXPECT_EQ(summary["ok"], kGood);
  EXPECT_EQ(summary["failed"], 3);
  EXPECT_EQ(summary["failures"].size(), 3u);
  EXPECT_EQ(summary["outlier_check"], "done");
  // The planted bias is flagged, for that parameter, and nothing else on it.
  bool flagged = false;
  for (const json& o : summary["outliers"]) {
    for (const json& reason : o["reasons"]) {
      const std::string r = reason.get<std::string>();
      if (r.rfind("accel_bias_x ", 0) != 0) continue;
      EXPECT_EQ(o["unit"], "u0" + std::to_string(kOutlier)) << r;
      flagged |= o["unit"] == "u0" + std::to_string(kOutlier);
    }
  }
  EXPECT_TRUE(flagged) << summary["outliers"].dump(2) << summary["parameters"].dump(2);
  const json& bias = summary["parameters"]["accel_bias_x"];
  EXPECT_EQ(bias["units"], kGood);
  EXPECT_GT(bias["robust_std"].get<double>(), 0.0);
  EXPECT_LT(bias["robust_std"].get<double>(), kPlantedBias / 5);

  // Everything up to date: a second run computes nothing and writes the same.
  const std::string first_csv = Slurp(out + "/summary.csv");
  const Process again = RunBatch(out);
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.err.find("skipped 11 "), std::string::npos) << again.err;  // u10 is retried
  EXPECT_EQ(WithoutTimes(Slurp(out + "/summary.csv")), WithoutTimes(first_csv));
}

TEST_F(BatchTest, NotConvergedUnitsExitTwoAndInputDirWorks) {
  // One Ceres iteration cannot converge: that unit only, exit code 2.
  std::ofstream(*dir_ + "/conv.csv") << "unit,path,max_iterations\nu00,u00.csv,\nu01,u01.csv,1\n";
  const std::string out = *dir_ + "/conv";
  Process p = Run(
      {"batch", "--manifest", *dir_ + "/conv.csv", "--config", *config_path_, "--output-dir", out});
  EXPECT_EQ(p.exit_code, 2) << p.err;
  EXPECT_NE(p.err.find("gravcal: error: 1 of 2 units did not converge"), std::string::npos)
      << p.err;
  std::vector<SummaryRow> rows;
  std::string error;
  ASSERT_TRUE(ParseSummaryCsv(Slurp(out + "/summary.csv"), "s", &rows, &error)) << p.err;
  ASSERT_EQ(rows.size(), 2u) << p.err;
  EXPECT_EQ(rows[0].status, BatchStatus::kOk);
  EXPECT_EQ(rows[1].status, BatchStatus::kNotConverged);
  EXPECT_NE(rows[1].message.find("did not converge"), std::string::npos) << rows[1].message;
  const json summary = json::parse(Slurp(out + "/summary.json"));
  EXPECT_EQ(summary["not_converged"], 1);
  EXPECT_EQ(summary["outlier_check"], "skipped: 1 calibrated units, needs 5");

  // Every good file of the folder, all calibrated: exit 0.
  p = Run({"batch", "--input-dir", *dir_, "--pattern", "u0[0-8].csv", "--config", *config_path_,
           "--output-dir", *dir_ + "/folder", "--threads", "0"});
  EXPECT_EQ(p.exit_code, 0) << p.err;
  EXPECT_NE(p.err.find("9 ok, 0 failed"), std::string::npos) << p.err;
  ASSERT_EQ(json::parse(Slurp(*dir_ + "/folder/u08.json"))["positions"].size(), 12u);
}

TEST_F(BatchTest, ShardedRunsMergedEqualOneRun) {
  const std::string whole = *dir_ + "/whole";
  ASSERT_EQ(RunBatch(whole).exit_code, 1);
  std::vector<std::string> merge = {"merge-summaries", "--output-dir", *dir_ + "/merged"};
  for (int k = 1; k <= 3; ++k) {
    const std::string shard = *dir_ + "/shard" + std::to_string(k);
    const Process p = RunBatch(shard, {"--shard", std::to_string(k) + "/3"});
    EXPECT_EQ(p.exit_code, 1) << p.err;  // every shard has one bad unit
    merge.push_back(shard);
    std::vector<SummaryRow> rows;
    std::string error;
    ASSERT_TRUE(ParseSummaryCsv(Slurp(shard + "/summary.csv"), "s", &rows, &error)) << error;
    ASSERT_EQ(rows.size(), 4u);
    for (const SummaryRow& r : rows) EXPECT_EQ(r.index % 3, static_cast<size_t>(k - 1));
  }
  // Missing shard: refused, nothing written.
  std::vector<std::string> partial(merge.begin(), merge.end() - 1);
  Process p = Run(partial);
  EXPECT_EQ(p.exit_code, 1);
  EXPECT_NE(p.err.find("shards 3 of 3 are missing"), std::string::npos) << p.err;
  EXPECT_EQ(Slurp(*dir_ + "/merged/summary.json"), "");
  // Merged in any order.
  std::swap(merge[3], merge[5]);
  p = Run(merge);
  ASSERT_EQ(p.exit_code, 0) << p.err;
  EXPECT_EQ(Slurp(*dir_ + "/merged/summary.json"), Slurp(whole + "/summary.json"));
  EXPECT_EQ(WithoutTimes(Slurp(*dir_ + "/merged/summary.csv")),
            WithoutTimes(Slurp(whole + "/summary.csv")));
}

TEST_F(BatchTest, KilledRunResumesWithoutRecomputing) {
  // kUnits units (the good sessions over and over), one thread, so units are
  // calibrated in manifest order. Unit kKillAt's input is a named pipe: the
  // batch blocks opening it until this test opens the other end, and by then
  // exactly the kKillAt units before it are finished and stored. The test
  // kills the batch there: no clock decides where the kill lands.
  constexpr int kUnits = 40;
  constexpr int kKillAt = 20;
  std::string manifest = "unit,path\n";
  for (int i = 0; i < kUnits; ++i) {
    const std::string path = i == kKillAt ? "pipe.csv" : "u0" + std::to_string(i % kGood) + ".csv";
    manifest += "r" + std::to_string(1000 + i) + "," + path + "\n";
  }
  const std::string list = *dir_ + "/many.csv";
  std::ofstream(list) << manifest;
  const std::string pipe = *dir_ + "/pipe.csv";
  ASSERT_EQ(mkfifo(pipe.c_str(), 0644), 0) << std::strerror(errno);
  auto args = [&](const std::string& out) {
    return std::vector<std::string>{"batch",    "--manifest",  list,
                                    "--config", *config_path_, "--output-dir",
                                    out,        "--threads",   "1"};
  };
  const std::string out = *dir_ + "/killed";
  const pid_t pid = testing_util::SpawnCli(args(out), "/dev/null", *dir_ + "/killed.txt");
  // Wait until the batch opens the pipe for reading (a non-blocking open for
  // writing fails with ENXIO until then), or has ended without doing so.
  int writer = -1;
  int status = 0;
  bool ended = false;
  while (writer < 0 && !ended) {
    writer = open(pipe.c_str(), O_WRONLY | O_NONBLOCK);
    if (writer < 0) {
      ASSERT_EQ(errno, ENXIO) << std::strerror(errno);
      ended = waitpid(pid, &status, WNOHANG) == pid;
      sched_yield();
    }
  }
  ASSERT_FALSE(ended) << "the batch ended before reaching unit " << kKillAt << ": "
                      << Slurp(*dir_ + "/killed.txt");
  kill(pid, SIGKILL);
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  close(writer);
  ASSERT_TRUE(WIFSIGNALED(status));
  const std::map<std::string, FileId> state = JsonFiles(out + "/batch_state");
  const std::map<std::string, FileId> results = JsonFiles(out);
  // Exactly the units before the pipe, each with its result.
  ASSERT_EQ(state.size(), static_cast<size_t>(kKillAt));
  for (int i = 0; i < kKillAt; ++i) {
    const std::string name = "r" + std::to_string(1000 + i) + ".json";
    EXPECT_EQ(state.count(name), 1u) << name;
    EXPECT_EQ(results.count(name), 1u) << name;
  }
  EXPECT_EQ(results.size(), static_cast<size_t>(kKillAt));
  EXPECT_EQ(JsonFiles(out).count("summary.json"), 0u);
  // The pipe becomes the unit's file for the resumed run.
  ASSERT_EQ(unlink(pipe.c_str()), 0);
  std::ofstream(pipe) << Slurp(*dir_ + "/u00.csv");

  // As if the kill had caught a write half way.
  std::ofstream(out + "/.gravcal-tmp." + std::to_string(pid) + ".0badcafe.r1000.json") << "{";
  const Process resumed = Run(args(out));
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.err.find("skipped " + std::to_string(state.size()) + " "), std::string::npos)
      << resumed.err;
  // No temporary file of the killed run is left.
  EXPECT_EQ(CountNames(out, ".gravcal-tmp.") + CountNames(out + "/batch_state", ".gravcal-tmp."),
            0u);
  const std::map<std::string, FileId> state_after = JsonFiles(out + "/batch_state");
  const std::map<std::string, FileId> results_after = JsonFiles(out);
  EXPECT_EQ(state_after.size(), static_cast<size_t>(kUnits));
  // The finished units are untouched (same inode and time), the others new.
  for (const auto& [name, id] : state) EXPECT_TRUE(state_after.at(name) == id) << name;
  for (const auto& [name, id] : results) EXPECT_TRUE(results_after.at(name) == id) << name;

  const std::string clean = *dir_ + "/uninterrupted";
  ASSERT_EQ(Run(args(clean)).exit_code, 0);
  EXPECT_EQ(Slurp(out + "/summary.json"), Slurp(clean + "/summary.json"));
  EXPECT_EQ(WithoutTimes(Slurp(out + "/summary.csv")), WithoutTimes(Slurp(clean + "/summary.csv")));
}

TEST_F(BatchTest, ManifestErrorsNameFileLineAndColumnAndWriteNothing) {
  struct Case {
    std::string text;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"unit,path,gravity\na,a.csv,9.81\nb,b.csv,abc\n",
       "m.csv:3:9: key 'gravity': must be a number"},
      {"unit,path,colour\n", "m.csv:1:11: column 'colour' is not unit, path"},
      {"unit,gravity\n", "m.csv:1:1: the header needs the columns unit and path"},
      {"unit,path\na,a.csv\na,b.csv\n", "m.csv:3:1: unit 'a' is already on line 2"},
      {"unit,path\nx/y,a.csv\n", "m.csv:2:1: unit id 'x/y' may only hold"},
      {"unit,path\nsummary,a.csv\n", "m.csv:2:1: unit id 'summary' is reserved"},
      {"unit,path\na,a.csv,extra\n", "m.csv:2:9: has 3 fields, the header 2"},
      {"unit,path\na,\"a.csv\n", "m.csv:2:3: the quoted field is not closed"},
      {"unit,path,parameterization\na,a.csv,cubic\n", "m.csv:2:9: key 'parameterization'"},
      {"unit,path\n", "m.csv: the manifest lists no units"},
      {"unit,path,window\na,a.csv,-1\n", "m.csv:2:1: unit 'a': "},
  };
  for (const Case& c : cases) {
    std::vector<BatchUnit> units;
    std::string error;
    EXPECT_FALSE(ParseBatchManifest(c.text, "m.csv", "/data", base_, &units, &error)) << c.text;
    EXPECT_EQ(error.rfind(c.expected, 0), 0u) << error;
  }
  std::vector<BatchUnit> units;
  std::string error;
  ASSERT_TRUE(ParseBatchManifest(
      "unit,path,gyro_path,nominal_up\n a , x/a.csv , g.txt , \"[+z, -z]\"\nb,/abs/b.csv,,\n",
      "m.csv", "/data", base_, &units, &error))
      << error;
  ASSERT_EQ(units.size(), 2u);
  EXPECT_EQ(units[0].id, "a");
  EXPECT_EQ(units[0].path, "/data/x/a.csv");
  ASSERT_EQ(units[0].overrides.size(), 2u);
  EXPECT_EQ(units[0].overrides[0].second, "/data/g.txt");
  EXPECT_EQ(units[0].overrides[1].second, "[+z, -z]");
  EXPECT_EQ(units[1].path, "/abs/b.csv");
  EXPECT_TRUE(units[1].overrides.empty());

  // The CLI: one line, exit 1, no output folder.
  std::ofstream(*dir_ + "/bad.csv") << cases[0].text;
  const Process p =
      Run({"batch", "--manifest", *dir_ + "/bad.csv", "--output-dir", *dir_ + "/never"});
  EXPECT_EQ(p.exit_code, 1);
  EXPECT_NE(p.err.find("bad.csv:3:9: key 'gravity'"), std::string::npos) << p.err;
  struct stat st;
  EXPECT_NE(stat((*dir_ + "/never").c_str(), &st), 0);
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"batch", "--output-dir", *dir_ + "/never"},
        std::vector<std::string>{"batch", "--manifest", *dir_ + "/units.csv", "--output-dir",
                                 *dir_ + "/never", "--shard", "4/3"},
        std::vector<std::string>{"batch", "--input-dir", *dir_ + "/nothing", "--output-dir",
                                 *dir_ + "/never"}}) {
    const Process q = Run(args);
    EXPECT_EQ(q.exit_code, 1) << q.err;
    EXPECT_NE(stat((*dir_ + "/never").c_str(), &st), 0) << q.err;
  }
}

TEST_F(BatchTest, InputDirUnitsAreSortedFileStems) {
  std::vector<BatchUnit> units;
  std::string error;
  ASSERT_TRUE(UnitsFromDirectory(*dir_, "u[0-9]*.csv", &units, &error)) << error;
  ASSERT_EQ(units.size(), 11u);  // u00..u09, u11
  EXPECT_EQ(units[0].id, "u00");
  EXPECT_EQ(units[10].id, "u11");
  EXPECT_EQ(units[3].path, *dir_ + "/u03.csv");
  EXPECT_FALSE(UnitsFromDirectory(*dir_, "*.nothing", &units, &error));
  EXPECT_NE(error.find("no file matches '*.nothing'"), std::string::npos);
}

TEST(ContentHash, SeesEveryByteFramingAndConfig) {
  const Config config;
  std::string bytes(1000, 'x');
  const std::string h = UnitContentHash(bytes, "", "", config);
  EXPECT_EQ(h.size(), 32u);
  EXPECT_EQ(UnitContentHash(bytes, "", "", config), h);
  std::set<std::string> seen = {h};
  for (size_t i : {0, 7, 8, 31, 32, 500, 998, 999}) {
    std::string changed = bytes;
    changed[i] = 'y';
    EXPECT_TRUE(seen.insert(UnitContentHash(changed, "", "", config)).second) << i;
  }
  EXPECT_TRUE(seen.insert(UnitContentHash(bytes + "x", "", "", config)).second);
  EXPECT_TRUE(seen.insert(UnitContentHash("ab", "c", "", config)).second);
  EXPECT_TRUE(seen.insert(UnitContentHash("a", "bc", "", config)).second);
  Config other = config;
  other.calibration.gravity.gravity = 9.81;
  EXPECT_TRUE(seen.insert(UnitContentHash(bytes, "", "", other)).second);
}

TEST(Shard, ParsesAndSplitsByPositionModN) {
  Shard shard;
  std::string error;
  ASSERT_TRUE(ParseShard("2/3", &shard, &error));
  EXPECT_EQ(ShardPositions(8, shard), (std::vector<size_t>{1, 4, 7}));
  for (const char* bad : {"0/3", "4/3", "3", "a/b", "-1/3", "1/0", ""}) {
    EXPECT_FALSE(ParseShard(bad, &shard, &error)) << bad;
    EXPECT_NE(error.find("K/N"), std::string::npos);
  }
}

TEST(FleetSummary, CsvRoundTripAndRobustStatistics) {
  std::vector<SummaryRow> rows;
  const double biases[] = {1.0, 1.2, 0.8, 1.1, 0.9, 1.05, 9.0};
  for (size_t i = 0; i < 7; ++i) {
    SummaryRow r;
    r.index = i;
    r.unit = "n" + std::to_string(i);
    r.status = BatchStatus::kOk;
    r.message = "calibrated, \"fine\"";
    r.values = {{"accel_bias_x", biases[i]},
                {"accel_m_yx", 0.0},
                {"residual_rms", 0.01 + 1e-4 * i},
                {"total_s", 0.1},
                {"accel_bias_x_std", NAN}};
    rows.push_back(r);
  }
  rows[6].values["residual_rms"] = 0.02;
  SummaryRow failed;
  failed.index = 7;
  failed.unit = "n7";
  failed.message = "x.csv:3: bad";
  rows.push_back(failed);
  std::vector<SummaryRow> parsed;
  std::string error;
  const std::string csv = SummaryToCsv(rows);
  ASSERT_TRUE(ParseSummaryCsv(csv, "s.csv", &parsed, &error)) << error;
  EXPECT_EQ(SummaryToCsv(parsed), csv);
  EXPECT_EQ(parsed[0].message, rows[0].message);
  EXPECT_TRUE(std::isnan(parsed[0].values.at("accel_bias_x_std")));

  FleetStatistics s;
  ASSERT_TRUE(ComputeFleetStatistics(parsed, FleetInfo(), FleetOptions(), &s, &error)) << error;
  EXPECT_EQ(s.ok, 7u);
  EXPECT_EQ(s.failed, 1u);
  ASSERT_EQ(s.parameters[0].name, "residual_rms");
  const ParameterStatistics& b = s.parameters[1];
  ASSERT_EQ(b.name, "accel_bias_x");
  EXPECT_DOUBLE_EQ(b.median, 1.05);
  // |x - 1.05| = .05 .15 .25 .05 .15 0 7.95 -> MAD 0.15.
  EXPECT_NEAR(b.robust_std, 1.4826 * 0.15, 1e-12);
  ASSERT_EQ(s.outliers.size(), 1u);
  EXPECT_EQ(s.outliers[0].unit, "n6");
  ASSERT_EQ(s.outliers[0].reasons.size(), 2u);  // bias and residual; accel_m_yx has no spread
  EXPECT_EQ(s.outliers[0].reasons[0].rfind("residual_rms = 0.02 is ", 0), 0u);
  EXPECT_EQ(s.outliers[0].reasons[1].rfind("accel_bias_x = 9 is 35.7", 0), 0u)
      << s.outliers[0].reasons[1];

  FleetOptions few;
  few.min_units = 8;
  ASSERT_TRUE(ComputeFleetStatistics(parsed, FleetInfo(), few, &s, &error));
  EXPECT_TRUE(s.outliers.empty());
  EXPECT_EQ(s.outlier_check, "skipped: 7 calibrated units, needs 8");
  few.outlier_sigmas = 0;
  EXPECT_FALSE(ComputeFleetStatistics(parsed, FleetInfo(), few, &s, &error));

  EXPECT_FALSE(
      ParseSummaryCsv("index,unit,status,message,x\n0,a,ok,,1e\n", "s.csv", &parsed, &error));
  EXPECT_EQ(error, "s.csv:2:9: column 'x': '1e' is not a number");
}

}  // namespace
}  // namespace gravcal
