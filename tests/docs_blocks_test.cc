// Issue 33, part 5: docs that run. Every command block of README.md and
// docs/ (a fenced block, no language or sh/bash/shell/console, with a line
// that runs gravcal) is run as a user would paste it: with bash, in a fresh
// folder per document (the blocks of one document in order, so a chain
// sees what the block before it wrote), gravcal on the PATH and as
// ./build/gravcal, configs/ from the source tree, and the files the blocks
// name but do not make (session.csv, still.csv, cfg.yaml, calib.json, ...)
// made by the test from gravcal's own simulations (MakeFixtures). Every
// block must exit 0. A transcript block ("$ " lines followed by output)
// runs its "$ " lines. Blocks that install packages or build gravcal, or
// need a cluster scheduler or a ROS bag, are recognised and skipped with
// the reason printed. A code fence left open fails the test by name.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "gravcal/io/log_reader.h"
#include "still_log.h"
#include "test_util.h"

namespace gravcal {
namespace {

namespace fs = std::filesystem;
using testing_util::ScratchDir;
using testing_util::Slurp;

struct Block {
  std::string doc;  // path relative to the source tree
  int line = 0;     // of the opening fence
  std::string commands;
};

bool StartsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

std::string TrimLeft(const std::string& s) {
  const size_t i = s.find_first_not_of(" \t");
  return i == std::string::npos ? "" : s.substr(i);
}

// A line that runs gravcal, as a user would type it.
bool RunsGravcal(const std::string& line) {
  const std::string t = TrimLeft(line);
  return StartsWith(t, "gravcal ") || StartsWith(t, "./build/gravcal ") ||
         t.find("| gravcal ") != std::string::npos || t.find("'gravcal ") != std::string::npos ||
         t.find("\"gravcal ") != std::string::npos || t.find(" gravcal batch") != std::string::npos;
}

// The command blocks of `doc`; false with `error` naming the line of a
// fence that is never closed.
bool ReadBlocks(const std::string& doc, std::vector<Block>* blocks, std::string* error) {
  std::ifstream in(testing_util::SourceDir() + "/" + doc);
  std::string line, lang, body;
  int number = 0, open_line = 0;
  bool inside = false;
  while (std::getline(in, line)) {
    ++number;
    const std::string t = TrimLeft(line);
    if (!StartsWith(t, "```")) {
      if (inside) body += line + "\n";
      continue;
    }
    if (!inside) {
      inside = true;
      open_line = number;
      lang = t.substr(3);
      body.clear();
      continue;
    }
    if (t != "```") {
      *error = doc + ":" + std::to_string(number) +
               ": a code fence opens inside the block of line " + std::to_string(open_line) +
               " (the block is never closed)";
      return false;
    }
    inside = false;
    if (!lang.empty() && lang != "sh" && lang != "bash" && lang != "shell" && lang != "console") {
      continue;
    }
    std::istringstream lines(body);
    std::string commands, l;
    bool transcript = body.find("$ ") != std::string::npos;
    bool runs = false;
    while (std::getline(lines, l)) {
      std::string t2 = TrimLeft(l);
      if (transcript) {
        if (!StartsWith(t2, "$ ")) continue;
        t2 = t2.substr(2);
      }
      runs = runs || RunsGravcal(t2);
      commands += t2 + "\n";
    }
    if (runs) blocks->push_back({doc, open_line, commands});
  }
  if (inside) {
    *error = doc + ":" + std::to_string(open_line) + ": code fence never closed";
    return false;
  }
  return true;
}

// Why a block is not run here, or "" to run it.
std::string SkipReason(const std::string& commands) {
  for (const char* w : {"apt-get", "cmake ", "pip install", "venv"}) {
    if (commands.find(w) != std::string::npos) return "installs packages or builds gravcal";
  }
  for (const char* w : {"sbatch", "SBATCH", "SLURM_", "aws ", "parallel "}) {
    if (commands.find(w) != std::string::npos) {
      return "needs a cluster scheduler (Slurm, AWS Batch or GNU parallel)";
    }
  }
  if (commands.find(".bag") != std::string::npos) return "needs a ROS bag";
  if (commands.find(" /results") != std::string::npos) {
    return "reads a cloud container's /results volume";
  }
  return "";
}

// Runs `script` with bash in `dir` (gravcal on the PATH); its exit code,
// the output in *output.
int RunBash(const std::string& dir, const std::string& script, std::string* output) {
  {
    std::ofstream f(dir + "/block.sh");
    f << "set -e -o pipefail\n" << script;
  }
  const std::string command =
      "cd '" + dir + "' && PATH='" + dir + "/bin':\"$PATH\" bash block.sh > block.out 2>&1";
  const int status = std::system(command.c_str());
  *output = Slurp(dir + "/block.out");
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// gravcal as the blocks call it, and configs/ of the source tree.
void LinkTools(const std::string& dir) {
  fs::create_directories(dir + "/bin");
  fs::create_directories(dir + "/build");
  fs::create_symlink(GRAVCAL_CLI_PATH, dir + "/bin/gravcal");
  fs::create_symlink(GRAVCAL_CLI_PATH, dir + "/build/gravcal");
  fs::create_symlink(testing_util::SourceDir() + "/configs", dir + "/configs");
}

// The files the blocks name without making them, from gravcal's own
// simulations (small: holds of 4 s): a twelve-pose session (session.csv,
// raw.csv, log.csv, sessions/, units.csv), its config (cfg.yaml,
// line3.yaml), its calibration, a still log and its noise.json, a
// hand-held session and two batch shards.
bool MakeFixtures(const std::string& dir, std::string* output) {
  LinkTools(dir);
  NoiseProcessOptions accel, gyro;
  // White noise and a rate random walk that a 3000-s log shows (Kalibr's
  // export needs K): the Allan curves cross at tau = sqrt(3) N / K, about
  // 170 s; small enough for the targets of docs/workflows/plan.md.
  accel.rate_hz = gyro.rate_hz = 10.0;
  accel.white_noise = 0.002;
  accel.random_walk = 2e-5;
  gyro.white_noise = 1e-4;
  gyro.random_walk = 1e-6;
  const ImuLog still = testing_util::StillLog(accel, gyro, 1.0, 3, 3000.0);
  std::string error;
  if (!WriteImuLogCsv(still, dir + "/still.csv", &error)) {
    *output = error;
    return false;
  }
  const std::string script =
      "gravcal simulate --config configs/twelve_position.yaml --seed 1 --sim_hold 4 --output-dir "
      "s1\n"
      "gravcal simulate --config configs/twelve_position.yaml --seed 2 --sim_hold 4 --output-dir "
      "s2\n"
      "cp s1/raw.csv session.csv; cp s1/raw.csv raw.csv; cp s1/raw.csv log.csv\n"
      "mkdir sessions; cp s1/raw.csv sessions/unit-a.csv; cp s2/raw.csv sessions/unit-b.csv\n"
      "printf 'unit,path\\nunit-a,sessions/unit-a.csv\\nunit-b,sessions/unit-b.csv\\n' > "
      "units.csv\n"
      "cp configs/twelve_position.yaml cfg.yaml; cp cfg.yaml line3.yaml\n"
      "gravcal simulate --config configs/twelve_position.yaml --seed 3 --sim_hold 4 "
      "--sim_raw_counts false --output-dir s3\n"
      "gravcal calibrate --input s3/raw.csv --config cfg.yaml --output calib.json\n"
      "gravcal noise --input still.csv --config cfg.yaml --output noise.json\n"
      "gravcal simulate --config configs/handheld_kalman.yaml --sim_motion handheld "
      "--sim_raw_counts false --output-dir hh\n"
      "cp hh/raw.csv handheld.csv\n"
      "gravcal batch --manifest units.csv --config cfg.yaml --output-dir shard-1/ --shard 1/2\n"
      "gravcal batch --manifest units.csv --config cfg.yaml --output-dir shard-2/ --shard 2/2\n"
      "rm -rf s1 s2 s3 hh block.sh block.out\n";
  return RunBash(dir, script, output) == 0;
}

std::vector<std::string> Documents() {
  std::vector<std::string> docs = {"README.md"};
  const fs::path root = fs::path(testing_util::SourceDir()) / "docs";
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.path().extension() == ".md") {
      docs.push_back(fs::relative(e.path(), testing_util::SourceDir()).string());
    }
  }
  std::sort(docs.begin(), docs.end());
  return docs;
}

TEST(DocsBlocks, EveryFenceIsClosed) {
  for (const std::string& doc : Documents()) {
    std::vector<Block> blocks;
    std::string error;
    EXPECT_TRUE(ReadBlocks(doc, &blocks, &error)) << error;
  }
}

TEST(DocsBlocks, EveryCommandBlockRuns) {
  // One scratch folder per test: the fixtures and a sandbox per document
  // inside it.
  ScratchDir scratch;
  const std::string fixtures = scratch / "fixtures";
  fs::create_directories(fixtures);
  std::string output;
  ASSERT_TRUE(MakeFixtures(fixtures, &output)) << output;
  int ran = 0;
  for (const std::string& doc : Documents()) {
    std::vector<Block> blocks;
    std::string error;
    if (!ReadBlocks(doc, &blocks, &error) || blocks.empty()) continue;
    std::string name = doc;
    std::replace(name.begin(), name.end(), '/', '_');
    const std::string sandbox = scratch / name;
    fs::copy(fixtures, sandbox, fs::copy_options::recursive | fs::copy_options::copy_symlinks);
    for (const Block& b : blocks) {
      const std::string skip = SkipReason(b.commands);
      if (!skip.empty()) {
        std::printf("skipped %s:%d: %s\n", b.doc.c_str(), b.line, skip.c_str());
        continue;
      }
      const int code = RunBash(sandbox, b.commands, &output);
      EXPECT_EQ(code, 0) << b.doc << ":" << b.line << ": the block fails\n"
                         << b.commands << "--- output:\n"
                         << output;
      ++ran;
    }
  }
  std::printf("%d command blocks ran\n", ran);
  EXPECT_GT(ran, 20);
}

// `plan` with a target no design within its limits can meet says the best
// it can reach, per parameter, instead of only that it cannot.
TEST(DocumentedChains, PlanThatCannotMeetATargetSaysTheBestItCanReach) {
  ScratchDir dir;
  const testing_util::CliResult r = testing_util::RunCli(
      {"plan", "--config", testing_util::SourceDir() + "/configs/twelve_position.yaml",
       "--accel-noise-density", "0.002", "--target", "accel_bias=0.0001mg accel_scale=0.01ppm",
       "--output", dir / "plan.json"},
      dir);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("the best it can reach"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bias_x"), std::string::npos) << r.err;
  EXPECT_FALSE(testing_util::FileExists(dir / "plan.json"));
}

// The hand-held report: a filter on a moving log counts no static poses,
// and the terms its model holds (cross-axis without hk_cross_axis) are "not
// estimated", not "not determined".
TEST(DocumentedChains, HandheldReportSaysWhatItNeverEstimated) {
  ScratchDir dir;
  const std::string config = testing_util::SourceDir() + "/configs/handheld_kalman.yaml";
  testing_util::CliResult r =
      testing_util::RunCli({"simulate", "--config", config, "--sim_motion", "handheld",
                            "--sim_raw_counts", "false", "--output-dir", dir / "sim"},
                           dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = testing_util::RunCli({"calibrate", "--input", dir / "sim/raw.csv", "--config", config,
                            "--output", dir / "c.json", "--report", dir / "c.html"},
                           dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string html = Slurp(dir / "c.html");
  EXPECT_EQ(html.find("static poses"), std::string::npos);
  EXPECT_EQ(html.find(">not determined<"), std::string::npos);
  EXPECT_NE(html.find("not estimated (held at its nominal value"), std::string::npos);
}

}  // namespace
}  // namespace gravcal
