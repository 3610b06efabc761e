// Issue 36: gravcal compare and gravcal verify from the command line: the
// exit codes (0 consistent, 3 changed, 1 bad input with nothing written),
// compare.json's shape (docs/data_contract.md), the undetermined
// parameters left out, and the three AHRS repeats of ../shared/data/real
// (skipped when absent) consistent under the shipped config.
#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"
#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::CliResult;
using testing_util::FileExists;
using testing_util::RunCli;
using testing_util::ScratchDir;
using testing_util::Slurp;

const std::string kTwelve = testing_util::SourceDir() + "/configs/twelve_position.yaml";
// m/s^2 per count of the simulated accelerometer (16384 counts per g).
constexpr double kCounts = 9.80665 / 16384.0;

// Simulates the unit of `seed` (twelve_position.yaml: the truth is drawn
// per seed) and calibrates it: <name>/raw.csv, <name>/cal.json.
void SimulatedUnit(const ScratchDir& dir, const std::string& name, int seed) {
  CliResult r = RunCli(
      {"simulate", "--config", kTwelve, "--seed", std::to_string(seed), "--output-dir", dir / name},
      dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunCli({"calibrate", "--config", kTwelve, "--input", dir / (name + "/raw.csv"), "--output",
              dir / (name + "/cal.json")},
             dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
}

void WriteJson(const std::string& path, const nlohmann::json& j) {
  FILE* f = std::fopen(path.c_str(), "w");
  ASSERT_NE(f, nullptr);
  const std::string text = j.dump(2);
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
}

TEST(CompareCli, ExitCodesShapeAndTheNamedParameter) {
  ScratchDir dir;
  SimulatedUnit(dir, "a", 1);
  const std::string a = dir / "a/cal.json";
  // The same calibration twice: nothing differs.
  CliResult r = RunCli({"compare", a, a, "--output", dir / "same.json"}, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(Slurp(dir / "same.json"));
  EXPECT_TRUE(j["consistent"].get<bool>());
  EXPECT_DOUBLE_EQ(j["level"].get<double>(), 0.01);
  ASSERT_EQ(j["parameters"].size(), 9u);
  for (const char* key : {"name", "difference", "std", "z"}) {
    EXPECT_TRUE(j["parameters"][0].contains(key)) << key;
  }

  // b: the z bias moved by 12 sigma of the difference (the bias is
  // authoritative in the file, so the edit is a valid calibration).
  nlohmann::json cal = nlohmann::json::parse(Slurp(a));
  const double sigma = cal["accel"]["std"]["bias"][2].get<double>();
  cal["accel"]["bias"][2] = cal["accel"]["bias"][2].get<double>() + 12.0 * std::sqrt(2.0) * sigma;
  WriteJson(dir / "moved.json", cal);
  r = RunCli({"compare", a, dir / "moved.json", "--output", dir / "moved_cmp.json", "--input",
              dir / "a/raw.csv", "--config", kTwelve},
             dir);
  EXPECT_EQ(r.exit_code, 3) << r.err << r.out;
  j = nlohmann::json::parse(Slurp(dir / "moved_cmp.json"));
  EXPECT_FALSE(j["consistent"].get<bool>());
  EXPECT_LT(j["p_value"].get<double>(), 0.01);
  EXPECT_EQ(j["changed"]["name"], "accel.bias_z");
  EXPECT_NEAR(j["changed"]["sigmas"].get<double>(), 12.0, 0.5);
  EXPECT_NE(r.out.find("accel.bias_z moved by"), std::string::npos) << r.out;
  // The corrected output over the log differs by about the bias moved
  // (raw units times the scale).
  EXPECT_GT(j["output_difference"]["samples"].get<int>(), 1000);
  EXPECT_GT(j["output_difference"]["accel_max"].get<double>(), 0.0);

  // Another unit (another seed's truth) is not the same unit.
  SimulatedUnit(dir, "b", 2);
  r = RunCli({"compare", a, dir / "b/cal.json"}, dir);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  r = RunCli({"compare", a, dir / "b/cal.json", "--space", "intrinsic"}, dir);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.out.find("accel.sensitivity_x"), std::string::npos) << r.out;

  // verify: the unit's own session against its calibration, then the other
  // unit's session.
  r = RunCli({"verify", "--calibration", a, "--input", dir / "a/raw.csv", "--config", kTwelve,
              "--output", dir / "verify.json"},
             dir);
  EXPECT_EQ(r.exit_code, 0) << r.err << r.out;
  j = nlohmann::json::parse(Slurp(dir / "verify.json"));
  EXPECT_TRUE(j["consistent"].get<bool>());
  EXPECT_EQ(j["poses"].size(), 12u);
  EXPECT_EQ(j["parameters"].size(), 9u);
  r = RunCli({"verify", "--calibration", a, "--input", dir / "b/raw.csv", "--config", kTwelve},
             dir);
  EXPECT_EQ(r.exit_code, 3) << r.err << r.out;
  EXPECT_NE(r.out.find("changed at level"), std::string::npos) << r.out;

  // plan --verify: the shortest four-pose check session for this calibration.
  r = RunCli({"plan", "--verify", a, "--accel-noise-density", "0.002", "--output",
              dir / "check_plan.json"},
             dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(Slurp(dir / "check_plan.json"));
  EXPECT_EQ(j["parameters"].size(), 9u);
  EXPECT_GT(j["hold_seconds"].get<double>(), 0.0);
  if (j["met"].get<bool>()) {
    for (const auto& p : j["parameters"]) {
      EXPECT_LE(p["minimal_detectable_change_sigmas"].get<double>(), 10.0);
    }
  } else {
    EXPECT_FALSE(j["short_of_target"].empty());
  }
  r = RunCli({"plan", "--verify", a, "--output", dir / "no.json"}, dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--accel-noise-density"), std::string::npos) << r.err;

  // calibrate --store files the result; history lists it.
  r = RunCli({"calibrate", "--config", kTwelve, "--input", dir / "a/raw.csv", "--output",
              dir / "stored.json", "--store", dir / "store", "--unit", "SN-7"},
             dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunCli({"history", "SN-7", "--store", dir / "store", "--output", dir / "history.json"}, dir);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(Slurp(dir / "history.json"));
  EXPECT_EQ(j["calibrations"].size(), 1u);
  EXPECT_EQ(j["parameters"].size(), 9u);
  r = RunCli({"history", "SN-8", "--store", dir / "store"}, dir);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("SN-8"), std::string::npos) << r.err;
}

TEST(CompareCli, BadInputIsOneLineAndWritesNothing) {
  ScratchDir dir;
  SimulatedUnit(dir, "a", 3);
  const std::string a = dir / "a/cal.json";
  const std::string out = dir / "out.json";
  auto expect_refused = [&](const std::vector<std::string>& args, const std::string& says) {
    const CliResult r = RunCli(args, dir);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_EQ(testing_util::Count(r.err, "\n"), 1u) << r.err;
    EXPECT_FALSE(FileExists(out));
  };
  expect_refused({"compare", a, "--output", out}, "two calibration files");
  expect_refused({"compare", a, dir / "missing.json", "--output", out}, "missing.json");
  expect_refused({"compare", a, a, "--level", "1.5", "--output", out}, "--level");
  expect_refused({"compare", a, a, "--space", "housing", "--output", out}, "--space");
  nlohmann::json cal = nlohmann::json::parse(Slurp(a));
  cal["accel"].erase("covariance");
  WriteJson(dir / "bare.json", cal);
  expect_refused({"compare", a, dir / "bare.json", "--output", out}, "no accelerometer covariance");
  cal = nlohmann::json::parse(Slurp(a));
  cal["accel"]["covariance"]["matrix"][0][1] = 5.0;
  WriteJson(dir / "asym.json", cal);
  expect_refused({"compare", a, dir / "asym.json", "--output", out}, "accel.covariance.matrix");
  expect_refused({"verify", "--calibration", a, "--output", out}, "--input");
  // The same session in m/s^2 instead of counts (t,ax,ay,az first): not a
  // change of the unit but of the raw unit, refused by compare and verify.
  {
    std::string si = "t,ax,ay,az\n";
    const std::string raw = Slurp(dir / "a/raw.csv");
    size_t at = raw.find('\n') + 1;
    while (at < raw.size()) {
      const size_t end = raw.find('\n', at);
      double v[4];
      ASSERT_EQ(std::sscanf(raw.c_str() + at, "%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3]), 4);
      char line[160];
      std::snprintf(line, sizeof(line), "%.9g,%.9g,%.9g,%.9g\n", v[0], v[1] * kCounts,
                    v[2] * kCounts, v[3] * kCounts);
      si += line;
      at = end == std::string::npos ? raw.size() : end + 1;
    }
    FILE* f = std::fopen((dir / "si.csv").c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fwrite(si.data(), 1, si.size(), f);
    std::fclose(f);
  }
  expect_refused({"verify", "--calibration", a, "--input", dir / "si.csv", "--config", kTwelve,
                  "--output", out},
                 "raw unit is not the calibration's");
  {
    const std::string config = Slurp(kTwelve) + "\nnominal_scale: 1.0\n";
    FILE* f = std::fopen((dir / "si.yaml").c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fwrite(config.data(), 1, config.size(), f);
    std::fclose(f);
  }
  const CliResult si = RunCli({"calibrate", "--config", dir / "si.yaml", "--input", dir / "si.csv",
                               "--output", dir / "si.json"},
                              dir);
  ASSERT_EQ(si.exit_code, 0) << si.err;
  expect_refused({"compare", a, dir / "si.json", "--output", out}, "different raw units");
  expect_refused(
      {"verify", "--calibration", dir / "bare.json", "--input", dir / "a/raw.csv", "--output", out},
      "no accelerometer covariance");
}

// The three AHRS repeats with the shipped config: good1's nine poses leave
// u_xy and u_xz undetermined (left out of the test, and said); every pair is
// consistent, in model and in intrinsic parameters, and verify of one
// recording against another's calibration is too.
TEST(CompareCli, AhrsRepeatsAreConsistent) {
  if (testing_util::RealDataDir().empty()) GTEST_SKIP() << "../shared/data/real is not there";
  const std::string folder = testing_util::RealDataDir() + "/ahrs_static_poses/";
  if (!FileExists(folder + "imu_good3.txt")) GTEST_SKIP() << "AHRS repeats not there";
  const std::string config = testing_util::SourceDir() + "/configs/ahrs_static_poses.yaml";
  ScratchDir dir;
  for (int i = 1; i <= 3; ++i) {
    const CliResult r = RunCli({"calibrate", "--config", config, "--input",
                                folder + "imu_good" + std::to_string(i) + ".txt", "--output",
                                dir / ("g" + std::to_string(i) + ".json")},
                               dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  for (const char* space : {"model", "intrinsic"}) {
    for (int i = 1; i <= 3; ++i) {
      for (int k = i + 1; k <= 3; ++k) {
        const CliResult r = RunCli({"compare", dir / ("g" + std::to_string(i) + ".json"),
                                    dir / ("g" + std::to_string(k) + ".json"), "--space", space,
                                    "--output", dir / "c.json"},
                                   dir);
        EXPECT_EQ(r.exit_code, 0) << space << " good" << i << "-good" << k << ": " << r.out;
        const nlohmann::json j = nlohmann::json::parse(Slurp(dir / "c.json"));
        if (i == 1) EXPECT_FALSE(j["undetermined"].empty()) << space;
        std::printf("%s good%d-good%d: %s\n", space, i, k, j["message"].get<std::string>().c_str());
      }
    }
  }
  const CliResult r = RunCli({"verify", "--calibration", dir / "g2.json", "--input",
                              folder + "imu_good3.txt", "--config", config},
                             dir);
  EXPECT_EQ(r.exit_code, 0) << r.out;
}

}  // namespace
}  // namespace gravcal
