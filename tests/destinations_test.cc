// Issue 32, the destination contract (io/files.h): no command overwrites one
// of its own inputs, replaces a non-regular file, writes before checking its
// destinations, or deletes a file it did not make. Each test plants the
// situation; every refusal is a non-zero exit, one error line naming the
// destination, and nothing written.
#include <dirent.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "gravcal/io/files.h"
#include "gravcal/io/noise_io.h"
#include "simulated_noise.h"
#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::CliResult;
using testing_util::Slurp;

// Names in a folder (without . and ..).
std::set<std::string> Names(const std::string& folder) {
  std::set<std::string> names;
  if (DIR* dir = opendir(folder.c_str())) {
    while (const dirent* e = readdir(dir)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") names.insert(n);
    }
    closedir(dir);
  }
  return names;
}

bool IsSymlink(const std::string& path) {
  struct stat st;
  return lstat(path.c_str(), &st) == 0 && S_ISLNK(st.st_mode);
}

// A pid that was alive a moment ago and is gone now.
pid_t DeadPid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  int status = 0;
  waitpid(pid, &status, 0);
  return pid;
}

// One simulated session and its calibration, made once for the suite.
class DestinationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    shared_ = std::make_unique<testing_util::ScratchDir>();
    const std::string sim = shared_->path() + "/sim";
    CliResult r = testing_util::RunCli(
        "simulate --config " + ConfigPath() + " --seed 3 --output-dir " + sim, *shared_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    raw_ = sim + "/raw.csv";
    calibration_ = shared_->path() + "/calib.json";
    r = testing_util::RunCli(
        "calibrate --config " + ConfigPath() + " --input " + raw_ + " --output " + calibration_,
        *shared_);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() { shared_.reset(); }

  void SetUp() override {
    work_ = scratch_.path() + "/work";
    ASSERT_EQ(mkdir(work_.c_str(), 0755), 0);
  }

  static std::string ConfigPath() {
    return testing_util::SourceDir() + "/configs/twelve_position.yaml";
  }
  CliResult Run(const std::string& args) const { return testing_util::RunCli(args, scratch_); }
  CliResult Run(const std::vector<std::string>& args) const {
    return testing_util::RunCli(args, scratch_);
  }
  std::string Work(const std::string& name) const { return work_ + "/" + name; }
  std::string Plant(const std::string& name, const std::string& text) const {
    std::ofstream(Work(name), std::ios::binary) << text;
    return Work(name);
  }
  // A refusal: exit 1, exactly one error line, naming `destination` and
  // never a temporary; the work folder holds `names` and nothing else.
  static void ExpectRefused(const CliResult& r, const std::string& destination,
                            const std::string& why) {
    EXPECT_EQ(r.exit_code, 1) << r.err;
    std::istringstream in(r.err);
    int errors = 0;
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("gravcal: error:", 0) != 0) continue;
      ++errors;
      EXPECT_NE(line.find(destination), std::string::npos) << line;
      EXPECT_NE(line.find(why), std::string::npos) << line;
      EXPECT_EQ(line.find("gravcal-tmp"), std::string::npos) << line;
      EXPECT_EQ(line.find(".tmp."), std::string::npos) << line;
    }
    EXPECT_EQ(errors, 1) << r.err;
  }

  static std::unique_ptr<testing_util::ScratchDir> shared_;
  static std::string raw_;
  static std::string calibration_;
  testing_util::ScratchDir scratch_;
  std::string work_;
};

std::unique_ptr<testing_util::ScratchDir> DestinationTest::shared_;
std::string DestinationTest::raw_;
std::string DestinationTest::calibration_;

// calibrate --output equal to --input (by name, through a symbolic link and
// through a hard link), --report equal to --input, --report equal to
// --output, apply --output equal to --calibration: refused before reading.
TEST_F(DestinationTest, NeverOverwritesAnInput) {
  const std::string log = Plant("s.csv", Slurp(raw_));
  const std::string calib = Plant("c.json", Slurp(calibration_));
  const std::string config = Plant("config.yaml", Slurp(ConfigPath()));
  ASSERT_EQ(symlink("s.csv", Work("link.json").c_str()), 0);
  ASSERT_EQ(link(log.c_str(), Work("hard.json").c_str()), 0);
  const std::set<std::string> before = Names(work_);
  struct Case {
    std::string args;
    std::string destination;
    std::string why;
  };
  const std::string calibrate = "calibrate --config " + ConfigPath() + " --input " + log;
  const std::vector<Case> cases = {
      {calibrate + " --output " + log, log, "same file as the input --input"},
      {calibrate + " --output " + Work("link.json"), "link.json", "same file as the input"},
      {calibrate + " --output " + Work("hard.json"), "hard.json", "same file as the input"},
      {calibrate + " --output " + Work("x.json") + " --report " + log, log, "--report is the same"},
      {calibrate + " --output " + Work("x.json") + " --report " + Work("x.json"), "x.json",
       "--report is the same file as --output"},
      {calibrate + " --output " + Work("x.json") + " --history " + Work("./x.json"), "x.json",
       "--history is the same file as --output"},
      {"apply --calibration " + calib + " --input " + log + " --output " + calib, calib,
       "same file as the input --calibration"},
      {calibrate + " --gyro_path " + Work("c.json") + " --output " + calib, calib,
       "same file as the input gyro_path"},
      {"noise --input " + log + " --output " + Work("n.json") + " --report " + log, log,
       "same file as the input"},
      {"discover --input " + log + " --output " + Work("d.json") + " --report " + log, log,
       "same file as the input"},
      {"export --calibration " + calib + " --to kalibr --output " + calib, calib,
       "same file as the input"},
      {"calibrate --config " + config + " --input " + log + " --output " + config, config,
       "same file as the input --config"},
  };
  const std::string log_text = Slurp(log);
  const std::string calib_text = Slurp(calib);
  const std::string config_text = Slurp(config);
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    ExpectRefused(Run(c.args), c.destination, c.why);
    EXPECT_EQ(Slurp(log), log_text);
    EXPECT_EQ(Slurp(calib), calib_text);
    EXPECT_EQ(Slurp(config), config_text);
    EXPECT_EQ(Names(work_), before);
  }
  EXPECT_TRUE(IsSymlink(Work("link.json")));
}

// A FIFO, a device, a folder or a socket at the destination is refused and
// stays what it was: /dev/null stays a character device.
TEST_F(DestinationTest, NeverReplacesANonRegularFile) {
  ASSERT_EQ(mkfifo(Work("fifo.json").c_str(), 0644), 0);
  ASSERT_EQ(mkdir(Work("folder.json").c_str(), 0755), 0);
  const std::set<std::string> before = Names(work_);
  const std::string calibrate = "calibrate --config " + ConfigPath() + " --input " + raw_;
  struct Case {
    std::string args;
    std::string destination;
    std::string why;
  };
  const std::vector<Case> cases = {
      {calibrate + " --output " + Work("fifo.json"), "fifo.json", "is a FIFO"},
      {calibrate + " --output " + Work("x.json") + " --report " + Work("fifo.json"), "fifo.json",
       "is a FIFO"},
      {calibrate + " --output /dev/null", "/dev/null", "is a character device"},
      {calibrate + " --output " + Work("folder.json"), "folder.json", "is a folder"},
      {"apply --calibration " + calibration_ + " --input " + raw_ + " --output /dev/null",
       "/dev/null", "is a character device"},
      {"export --calibration " + calibration_ + " --to kalibr --output " + Work("fifo.json"),
       "fifo.json", "is a FIFO"},
      {"plan --config " + ConfigPath() + " --output /dev/null", "/dev/null", "character device"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.args);
    ExpectRefused(Run(c.args), c.destination, c.why);
    EXPECT_EQ(Names(work_), before);
  }
  struct stat st;
  ASSERT_EQ(stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  ASSERT_EQ(stat(Work("fifo.json").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));

  // The library writer itself refuses too (the Python package's path).
  std::string error;
  EXPECT_FALSE(WriteFileAtomically(Work("fifo.json"), "x", &error));
  EXPECT_NE(error.find("fifo.json: exists and is a FIFO"), std::string::npos) << error;
  EXPECT_FALSE(WriteFileAtomically("-", "x", &error));
  EXPECT_EQ(Names(work_), before);
}

// Every destination is checked before the work: an unwritable --output
// with --report writes no report, and the message names the destination's
// missing folder, not a temporary.
TEST_F(DestinationTest, ChecksEveryDestinationBeforeTheWork) {
  const std::string calibrate = "calibrate --config " + ConfigPath() + " --input " + raw_;
  CliResult r = Run(calibrate + " --report " + Work("r.html") + " --output " + Work("nope/x.json"));
  ExpectRefused(r, Work("nope/x.json") + ": folder '" + Work("nope/") + "' does not exist", "");
  // Before the work: no "detected ... positions" line, nothing written.
  EXPECT_EQ(r.err.find("position"), std::string::npos) << r.err;
  EXPECT_TRUE(Names(work_).empty());
  Plant("f.txt", "precious");
  r = Run("noise --input " + raw_ + " --output " + Work("n.json") + " --kalibr " +
          Work("f.txt/imu.yaml"));
  ExpectRefused(r, "f.txt/imu.yaml", "is not a folder");
  EXPECT_EQ(Names(work_), std::set<std::string>({"f.txt"}));
  r = Run("simulate --config " + ConfigPath() + " --output-dir " + Work("f.txt"));
  ExpectRefused(r, "f.txt", "not a folder");
  EXPECT_EQ(Slurp(Work("f.txt")), "precious");
}

// A symbolic link at the destination is followed: its target is replaced
// and the link stays; a link to a file still to be made makes it.
TEST_F(DestinationTest, FollowsASymbolicLink) {
  ASSERT_EQ(mkdir(Work("real").c_str(), 0755), 0);
  Plant("real/target.json", "old");
  ASSERT_EQ(symlink("real/target.json", Work("link.json").c_str()), 0);
  ASSERT_EQ(symlink("real/later.csv", Work("dangling.csv").c_str()), 0);
  CliResult r = Run("calibrate --config " + ConfigPath() + " --input " + raw_ + " --output " +
                    Work("link.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(IsSymlink(Work("link.json")));
  EXPECT_TRUE(nlohmann::json::accept(Slurp(Work("real/target.json"))));
  r = Run("apply --calibration " + calibration_ + " --input " + raw_ + " --output " +
          Work("dangling.csv"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(IsSymlink(Work("dangling.csv")));
  EXPECT_NE(Slurp(Work("real/later.csv")).find("t,ax,ay,az"), std::string::npos);
  EXPECT_EQ(Names(work_), std::set<std::string>({"real", "link.json", "dangling.csv"}));
  EXPECT_EQ(Names(Work("real")), std::set<std::string>({"target.json", "later.csv"}));
}

// "-" is standard output where the command streams (calibrate's JSON,
// apply's CSV, export's text) and refused elsewhere; never a file "-".
TEST_F(DestinationTest, DashIsStandardOutputOrRefused) {
  char cwd[4096];
  ASSERT_NE(getcwd(cwd, sizeof(cwd)), nullptr);
  ASSERT_EQ(chdir(work_.c_str()), 0);
  CliResult r = Run("calibrate --config " + ConfigPath() + " --input " + raw_ + " --output -");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["positions"].size(), 12u);
  gravcal::Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(ConfigPath(), &config, &error)) << error;
  // Kalibr needs every term: a noise model that shows the random walks.
  config.simulation.accel_bias_random_walk = 1e-4;
  config.simulation.gyro_bias_random_walk = 1e-5;
  const std::string noise = scratch_.path() + "/noise.json";
  ASSERT_TRUE(WriteNoiseJson(testing_util::SimulatedNoiseModel(config.simulation), noise, &error))
      << error;
  r = Run("export --calibration " + calibration_ + " --noise " + noise + " --to kalibr --output -");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("accelerometer"), std::string::npos) << r.out;
  r = Run("apply --calibration " + calibration_ + " --input " + raw_ + " --output -");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("t,ax,ay,az"), std::string::npos);
  for (const std::string& args :
       {"calibrate --config " + ConfigPath() + " --input " + raw_ + " --output x.json --report -",
        "noise --input " + raw_ + " --output -",
        "calibrate --config " + ConfigPath() + " --input " + raw_ + " --output - --history -",
        "plan --config " + ConfigPath() + " --output -"}) {
    SCOPED_TRACE(args);
    ExpectRefused(Run(args), "-:", "standard output");
  }
  EXPECT_TRUE(Names(work_).empty());
  ASSERT_EQ(chdir(cwd), 0);

  // Standard output appended to the input itself: refused before a byte.
  const std::string log = Plant("s.csv", Slurp(raw_));
  const pid_t pid = fork();
  if (pid == 0) {
    const int out = open(log.c_str(), O_WRONLY | O_APPEND);
    const int err = open((scratch_ / "append_err.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(out, 1);
    dup2(err, 2);
    const std::string calibration = calibration_;
    execl(GRAVCAL_CLI_PATH, GRAVCAL_CLI_PATH, "apply", "--calibration", calibration.c_str(),
          "--input", log.c_str(), "--output", "-", static_cast<char*>(nullptr));
    _exit(127);
  }
  CliResult appended;
  appended.exit_code = testing_util::WaitForExit(pid);
  appended.err = Slurp(scratch_ / "append_err.txt");
  ExpectRefused(appended, "-: --output is standard output, which is the input --input", log);
  EXPECT_EQ(Slurp(log), Slurp(raw_));
}

// The batch removes only temporaries of its own form whose process is gone
// and whose lock is free: look-alikes and a live run's files stay.
TEST_F(DestinationTest, CleanupRemovesOnlyProvablyStaleTemporaries) {
  const std::string dead = std::to_string(DeadPid());
  const std::string alive = std::to_string(getpid());
  const std::vector<std::string> kept = {"notes.tmp.2023",
                                         "thesis.tmp.99999",
                                         "u1.json.tmp." + dead,
                                         ".gravcal-tmp." + dead + ".nothex!!.u1.json",
                                         ".gravcal-tmp." + dead + ".0123abcd",
                                         ".gravcal-tmp.x" + dead + ".0123abcd.u1.json",
                                         ".gravcal-tmp." + alive + ".0123abcd.u1.json",
                                         "gravcal-tmp." + dead + ".0123abcd.u1.json"};
  for (const std::string& name : kept) Plant(name, "mine");
  Plant(".gravcal-tmp." + dead + ".0123abcd.u1.json", "{");
  // A stale name whose lock is held (another namespace's live writer).
  const std::string locked = Plant(".gravcal-tmp." + dead + ".89abcdef.u2.json", "{");
  const int fd = open(locked.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(flock(fd, LOCK_EX), 0);
  // flock: RemoveStaleTemporaries's own open of the file sees this lock.
  EXPECT_EQ(RemoveStaleTemporaries(work_), 1);
  close(fd);
  std::set<std::string> expected(kept.begin(), kept.end());
  expected.insert(".gravcal-tmp." + dead + ".89abcdef.u2.json");
  EXPECT_EQ(Names(work_), expected);
  for (const std::string& name : kept) EXPECT_EQ(Slurp(Work(name)), "mine") << name;

  // The batch cleans its output folder on start the same way: the lock now
  // free, that temporary goes; every other name stays.
  ASSERT_EQ(mkdir(Work("in").c_str(), 0755), 0);
  Plant("in/u1.csv", Slurp(raw_));
  // Units that fail: the stale result of u3 (a calibration JSON) goes, the
  // user's own u2.json stays.
  Plant("in/u2.csv", "t,ax,ay,az\n");
  Plant("in/u3.csv", "t,ax,ay,az\n");
  Plant("u2.json", "mine");
  Plant("u3.json", Slurp(calibration_));
  const CliResult r = Run("batch --config " + ConfigPath() + " --input-dir " + Work("in") +
                          " --output-dir " + work_);
  ASSERT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("2 of 3 units failed"), std::string::npos) << r.err;
  for (const std::string& name : kept) EXPECT_EQ(Slurp(Work(name)), "mine") << name;
  EXPECT_FALSE(testing_util::FileExists(locked));
  EXPECT_EQ(Slurp(Work("u2.json")), "mine");
  EXPECT_FALSE(testing_util::FileExists(Work("u3.json")));
  EXPECT_TRUE(testing_util::FileExists(Work("u1.json")));
}

// merge-summaries refuses an output folder that is one of its shard
// folders, by name or by another path to it.
TEST_F(DestinationTest, MergeRefusesAShardFolderAsOutput) {
  for (const char* shard : {"s1", "s2"}) {
    ASSERT_EQ(mkdir(Work(shard).c_str(), 0755), 0);
    Plant(std::string(shard) + "/summary.csv", "shard csv");
    Plant(std::string(shard) + "/summary.json", "shard json");
  }
  ASSERT_EQ(symlink("s1", Work("alias").c_str()), 0);
  for (const std::string& out : {Work("s1"), Work("s1/"), Work("s2/."), Work("alias")}) {
    SCOPED_TRACE(out);
    ExpectRefused(Run("merge-summaries --output-dir " + out + " " + Work("s1") + " " + Work("s2")),
                  out, "same folder as the input");
    EXPECT_EQ(Slurp(Work("s1/summary.csv")), "shard csv");
    EXPECT_EQ(Slurp(Work("s2/summary.json")), "shard json");
  }
}

// --input-dir equal to --output-dir, run twice: the second run tells its
// own summary apart and resumes; hidden and AppleDouble "._" files are
// skipped with a note; a file of the input folder the batch would
// overwrite is refused.
TEST_F(DestinationTest, BatchInItsOwnInputFolder) {
  const std::string log = Slurp(raw_);
  Plant("u1.csv", log);
  Plant("u2.csv", log);
  Plant("._u1.csv", std::string("\0\5\26\7\0\2\0\0Mac OS X", 16));
  Plant(".hidden.csv", "not a log");
  // Names that merely look like temporaries: not the batch's to remove.
  const std::vector<std::string> others = {"notes.tmp.2023", "thesis.tmp.99999",
                                           "u1.json.tmp." + std::to_string(DeadPid())};
  for (const std::string& name : others) Plant(name, "mine");
  const std::string batch =
      "batch --config " + ConfigPath() + " --input-dir " + work_ + " --output-dir " + work_;
  CliResult r = Run(batch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("skipped 2 hidden files (._u1.csv, .hidden.csv)"), std::string::npos)
      << r.err;
  r = Run(batch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("2 units"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("skipped 2 (stored results up to date)"), std::string::npos) << r.err;
  EXPECT_EQ(Slurp(Work("._u1.csv")).size(), 16u);
  for (const std::string& name : others) EXPECT_EQ(Slurp(Work(name)), "mine") << name;

  // A user's own summary.csv among the logs is not overwritten.
  ASSERT_EQ(mkdir(Work("mine").c_str(), 0755), 0);
  Plant("mine/summary.csv", log);
  const std::string mine = "batch --config " + ConfigPath() + " --input-dir " + Work("mine") +
                           " --output-dir " + Work("mine");
  ExpectRefused(Run(mine), "summary.csv", "did not write");
  EXPECT_EQ(Slurp(Work("mine/summary.csv")), log);
  EXPECT_EQ(Names(Work("mine")), std::set<std::string>({"summary.csv"}));

  // A unit whose log has the name of its own result.
  ASSERT_EQ(mkdir(Work("own").c_str(), 0755), 0);
  Plant("own/u1.json", log);
  ExpectRefused(Run("batch --config " + ConfigPath() + " --input-dir " + Work("own") +
                    " --output-dir " + Work("own") + " --pattern *.json"),
                "u1.json: the batch would overwrite", "unit u1");
  EXPECT_EQ(Slurp(Work("own/u1.json")), log);
  EXPECT_EQ(Names(Work("own")), std::set<std::string>({"u1.json"}));

  // A folder of AppleDouble files only: the message says why none is a unit.
  ASSERT_EQ(mkdir(Work("apple").c_str(), 0755), 0);
  Plant("apple/._u1.csv", log);
  ExpectRefused(Run("batch --config " + ConfigPath() + " --input-dir " + Work("apple") +
                    " --output-dir " + Work("apple/out")),
                "apple: no file matches '*.csv'", "only hidden files do");
  EXPECT_EQ(Names(Work("apple")), std::set<std::string>({"._u1.csv"}));
}

// Several outputs are one: a second file that cannot be written leaves the
// first as the user had it (never removed, never a link deleted), and no
// temporary stays behind. Then all are put in place, a link's target replaced.
TEST_F(DestinationTest, SeveralOutputsAllOrNone) {
  ASSERT_EQ(mkdir(Work("real").c_str(), 0755), 0);
  Plant("real/plan.json", "precious");
  ASSERT_EQ(symlink("real/plan.json", Work("plan.json").c_str()), 0);
  Plant("report.html", "kept");
  std::string error;
  EXPECT_FALSE(WriteFilesAtomically(
      {{Work("plan.json"), "new"}, {Work("report.html"), "new"}, {Work("gone/r.html"), "x"}},
      &error));
  EXPECT_NE(error.find(Work("gone/r.html")), std::string::npos) << error;
  EXPECT_EQ(error.find("gravcal-tmp"), std::string::npos) << error;
  EXPECT_TRUE(IsSymlink(Work("plan.json")));
  EXPECT_EQ(Slurp(Work("real/plan.json")), "precious");
  EXPECT_EQ(Slurp(Work("report.html")), "kept");
  EXPECT_EQ(Names(work_), std::set<std::string>({"real", "plan.json", "report.html"}));
  EXPECT_EQ(Names(Work("real")), std::set<std::string>({"plan.json"}));
  ASSERT_TRUE(WriteFilesAtomically({{Work("plan.json"), "new"}, {"", "skipped"}}, &error)) << error;
  EXPECT_TRUE(IsSymlink(Work("plan.json")));
  EXPECT_EQ(Slurp(Work("real/plan.json")), "new");
  EXPECT_EQ(Names(work_), std::set<std::string>({"real", "plan.json", "report.html"}));
}

// simulate --output-dir makes every missing level (mkdir -p), as export --to c
// does; a level that is a file is refused by name.
TEST_F(DestinationTest, OutputFolderMadeAtEveryLevel) {
  CliResult r =
      Run("simulate --config " + ConfigPath() + " --seed 4 --output-dir " + Work("a/b/c"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Names(Work("a/b/c")),
            std::set<std::string>({"raw.csv", "truth.json", "attitudes.csv"}));
  r = Run("export --calibration " + calibration_ + " --to c --output-dir " + Work("x/y"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(Names(Work("x/y")), std::set<std::string>({"gravcal_correct.h", "gravcal_correct.c"}));
  Plant("file", "precious");
  r = Run("simulate --config " + ConfigPath() + " --output-dir " + Work("file/b"));
  ExpectRefused(r, Work("file/b"), "not a folder");
  EXPECT_EQ(Slurp(Work("file")), "precious");
}

}  // namespace
}  // namespace gravcal
