// The command-line tool end to end: bad input gets one line naming the file,
// line or key, a non-zero exit and no output file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli_runner.h"
#include "gravcal/core/types.h"
#include "gravcal/io/calibration_export.h"
#include "sigma_check.h"
#include "test_util.h"

namespace gravcal {
namespace {

using RunResult = testing_util::CliResult;
using testing_util::Slurp;

class CliTest : public ::testing::Test {
 protected:
  RunResult Run(const std::string& args) const { return testing_util::RunCli(args, scratch_); }
  std::string Write(const std::string& name, const std::string& text) const {
    return scratch_.Write(name, text);
  }
  static bool Exists(const std::string& path) { return testing_util::FileExists(path); }
  std::string Config() const { return testing_util::SourceDir() + "/configs/twelve_position.yaml"; }
  // A simulated twelve-position session in raw counts.
  std::string Simulated(int seed = 7) {
    const std::string sim = dir_ + "/sim" + std::to_string(seed);
    const RunResult r = Run("simulate --config " + Config() + " --seed " + std::to_string(seed) +
                            " --output-dir " + sim);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return sim + "/raw.csv";
  }
  // The error line, checked to be exactly one line.
  static std::string OneLine(const RunResult& r) {
    std::string last;
    int errors = 0;
    std::istringstream in(r.err);
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("gravcal: error:", 0) == 0) {
        ++errors;
        last = line;
      }
    }
    EXPECT_EQ(errors, 1) << r.err;
    return last;
  }

  testing_util::ScratchDir scratch_;
  const std::string dir_ = scratch_.path();
};

// The demo's table: a row per parameter (bias_x..z, u_xx..u_zz) with truth,
// estimate +- std and err/std. The printed err/std must be (estimate -
// truth) / std of the printed numbers, and every one of the nine within the
// bound nine honest N(0, 1) values all stay inside with probability 0.999
// (about 4.0 sigma); the residual after the calibration below the one before.
TEST_F(CliTest, DemoPrintsEstimateNextToTruth) {
  const RunResult r = Run("demo --config " + Config());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream in(r.out);
  int rows = 0;
  double before = NAN, after = NAN;
  const int kRows = 9;
  const double bound =
      testing_util::NormalQuantile(1.0 - 0.5 * (1.0 - testing_util::kSigmaBandProbability) / kRows);
  for (std::string line; std::getline(in, line);) {
    std::istringstream row(line);
    std::string name, plus_minus;
    double truth, estimate, sigma, z;
    if ((line.rfind("bias_", 0) == 0 || line.rfind("u_", 0) == 0) &&
        row >> name >> truth >> estimate >> plus_minus >> sigma >> z) {
      ++rows;
      EXPECT_EQ(plus_minus, "+-") << line;
      EXPECT_GT(sigma, 0.0) << line;
      EXPECT_NEAR(z, (estimate - truth) / sigma, 0.01) << line;
      EXPECT_LT(std::fabs(z), bound) << line;
    }
    const size_t at = line.find("before (nominal scale) rms ");
    if (at != std::string::npos) {
      before = std::stod(line.substr(at + 27));
      after = std::stod(line.substr(line.find("after rms ") + 10));
    }
  }
  EXPECT_EQ(rows, kRows) << r.out;
  EXPECT_LT(after, before) << r.out;
}

TEST_F(CliTest, SimulateCalibrateApplyRoundTrip) {
  const std::string raw = Simulated();
  const std::string calib = dir_ + "/calib.json";
  RunResult r = Run("calibrate --input " + raw + " --config " + Config() +
                    " --latitude 45.4 --height 20 --output " + calib);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(calib);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["accel"]["model"], "scale_misalignment");
  EXPECT_EQ(j["positions"].size(), 12u);
  EXPECT_TRUE(j["accel"]["std"]["matrix"][1][0].is_null());
  EXPECT_TRUE(j["accel"]["std"]["matrix"][0][1].is_number());
  EXPECT_NE(j["gravity"]["source"].get<std::string>().find("latitude"), std::string::npos);
  EXPECT_EQ(j["accel"]["covariance"]["parameters"].size(), 9u);
  const std::string corrected = dir_ + "/corrected.csv";
  r = Run("apply --calibration " + calib + " --input " + raw + " --output " + corrected);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(Exists(corrected));
}

TEST_F(CliTest, FlagOverridesConfig) {
  const std::string raw = Simulated();
  const std::string calib = dir_ + "/calib.json";
  const RunResult r = Run("calibrate --input " + raw + " --config " + Config() +
                          " --gravity 9.81744 --parameterization=scale --output " + calib);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(calib);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["gravity"]["value"], 9.81744);
  EXPECT_EQ(j["accel"]["model"], "scale");
  EXPECT_TRUE(j["accel"]["std"]["matrix"][0][1].is_null());
}

TEST_F(CliTest, BadInputsGiveOneLineAndNoOutput) {
  const std::string out = dir_ + "/out.json";
  struct Case {
    std::string file_text;
    std::string expect;  // in the error line
  };
  const std::vector<Case> cases = {
      {"", "no samples"},
      {"t,ax,ay\n0,1,2\n", "'az'"},
      {"t,ax,ay,az\n0,1,2,3\n0.1,1,abc,3\n", ":3:"},
      {"t,ax,ay,az\n0,1,2,3\n0.1,1,nan,3\n", ":3:"},
      {"t,ax,ay,az\n0,1,2,3\n0.1,1,inf,3\n", ":3:"},
      {"t,ax,ay,az\n0,1,2,3\n0,1,2,3\n", "time"},
  };
  for (size_t i = 0; i < cases.size(); ++i) {
    const std::string input = Write("bad" + std::to_string(i) + ".csv", cases[i].file_text);
    const RunResult r =
        Run("calibrate --input " + input + " --config " + Config() + " --output " + out);
    EXPECT_EQ(r.exit_code, 1) << i;
    const std::string line = OneLine(r);
    EXPECT_NE(line.find("bad" + std::to_string(i) + ".csv"), std::string::npos) << line;
    EXPECT_NE(line.find(cases[i].expect), std::string::npos) << line;
    EXPECT_FALSE(Exists(out)) << i;
  }
}

TEST_F(CliTest, TooFewPositionsSaysHowMany) {
  // Six positions are too few for the nine-parameter model.
  const std::string sim = dir_ + "/six";
  RunResult r = Run("simulate --config " + Config() + " --sim_scheme six --output-dir " + sim);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string out = dir_ + "/out.json";
  r = Run("calibrate --input " + sim + "/raw.csv --config " + Config() + " --output " + out);
  EXPECT_EQ(r.exit_code, 1);
  const std::string line = OneLine(r);
  EXPECT_NE(line.find("found 6 static positions"), std::string::npos) << line;
  EXPECT_NE(line.find("at least 9"), std::string::npos) << line;
  EXPECT_FALSE(Exists(out));
}

TEST_F(CliTest, UnknownConfigKeyIsNamed) {
  const std::string config = Write("bad.yaml", "method: twelve_position\nlosss: huber\n");
  const std::string raw = Simulated();
  const std::string out = dir_ + "/out.json";
  const RunResult r = Run("calibrate --input " + raw + " --config " + config + " --output " + out);
  EXPECT_EQ(r.exit_code, 1);
  const std::string line = OneLine(r);
  EXPECT_NE(line.find("bad.yaml:2"), std::string::npos) << line;
  EXPECT_NE(line.find("'losss'"), std::string::npos) << line;
  EXPECT_FALSE(Exists(out));
}

TEST_F(CliTest, BadValuesAndFlagsAreNamed) {
  const std::string raw = Simulated();
  const std::string out = dir_ + "/out.json";
  RunResult r =
      Run("calibrate --input " + raw + " --config " + Config() + " --loss l3 --output " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("'loss'"), std::string::npos);
  r = Run("calibrate --input " + raw + " --config " + Config() + " --gravity 3 --output " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("gravity"), std::string::npos);
  r = Run("calibrate --input " + raw + " --frobnicate 1 --output " + out);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("--frobnicate"), std::string::npos);
  r = Run("calibrate --input " + raw);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("--output"), std::string::npos);
  EXPECT_FALSE(Exists(out));
}

TEST_F(CliTest, NonConvergenceKeepsCoarseAndExitsTwo) {
  const std::string raw = Simulated();
  const std::string out = dir_ + "/out.json";
  const RunResult r = Run("calibrate --input " + raw + " --config " + Config() +
                          " --max_iterations 1 --output " + out);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(OneLine(r).find("did not converge"), std::string::npos);
  EXPECT_FALSE(Exists(out));
}

TEST_F(CliTest, HelpListsCommandsAndKeys) {
  RunResult r = Run("help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("calibrate"), std::string::npos);
  r = Run("calibrate --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--parameterization"), std::string::npos);
  EXPECT_NE(r.out.find("--latitude"), std::string::npos);
  // An enum key's or flag's help ends in the names its table accepts.
  EXPECT_NE(r.out.find("robust loss on the residuals: " + AcceptedNames(LossType())),
            std::string::npos)
      << r.out;
  r = Run("export --help");
  EXPECT_NE(r.out.find("export: the target: " + AcceptedNames(ExportTarget())), std::string::npos)
      << r.out;
  r = Run("export --to matlab");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--to: 'matlab' is not one of kalibr"), std::string::npos) << r.err;
}

// Issue 5: the gyroscope from the rotations between poses, end to end.
TEST_F(CliTest, CalibratesTheGyroscopeAndRejectsALogWithoutOne) {
  const std::string config = testing_util::SourceDir() + "/configs/twelve_position_gyro.yaml";
  ASSERT_EQ(
      Run("simulate --config " + config + " --output-dir " + dir_ + "/sim --seed 4").exit_code, 0);
  const std::string out = dir_ + "/calib.json";
  const RunResult ok = Run("calibrate --config " + config + " --input " + dir_ +
                           "/sim/raw.csv --output " + out + " --gravity 9.80665");
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const nlohmann::json j = nlohmann::json::parse(Slurp(out));
  ASSERT_TRUE(j.contains("gyro"));
  EXPECT_EQ(j["gyro"]["rotation_residual_deg"].size(), 11u);
  EXPECT_EQ(j["gyro"]["matrix"].size(), 3u);

  // The same log without its gyroscope columns: one line, exit 1, no file.
  std::ifstream raw(dir_ + "/sim/raw.csv");
  std::ostringstream accel_only;
  std::string line;
  while (std::getline(raw, line)) {
    std::istringstream fields(line);
    std::string field;
    for (int i = 0; i < 4 && std::getline(fields, field, ','); ++i) {
      accel_only << (i ? "," : "") << field;
    }
    accel_only << "\n";
  }
  const std::string input = Write("nogyro.csv", accel_only.str());
  const std::string missing = dir_ + "/missing.json";
  const RunResult bad = Run("calibrate --config " + config + " --input " + input + " --output " +
                            missing + " --gravity 9.80665");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("nogyro.csv: the log has no gyroscope columns"), std::string::npos)
      << bad.err;
  EXPECT_FALSE(Exists(missing));
}

// Issue 4: the handheld Kalman method end to end, from a simulated handheld
// session in counts, with the time history.
TEST_F(CliTest, HandheldKalmanWritesCalibrationAndHistory) {
  const std::string sim = dir_ + "/handheld";
  RunResult r =
      Run("simulate --sim_motion handheld --sim_accel_misalignment 0 "
          "--sim_gyro_misalignment 0 --seed 3 --output-dir " +
          sim);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string config = testing_util::SourceDir() + "/configs/handheld_kalman.yaml";
  const std::string calib = dir_ + "/calib.json";
  const std::string history = dir_ + "/history.csv";
  const std::string scales =
      " --nominal_scale 0.00059855 --gyro_nominal_scale 0.000133231 "
      "--gravity 9.80665 ";
  r = Run("calibrate --input " + sim + "/raw.csv --config " + config + scales + "--output " +
          calib + " --history " + history);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(Slurp(calib));
  const nlohmann::json truth = nlohmann::json::parse(Slurp(sim + "/truth.json"));
  EXPECT_EQ(j["method"], "handheld_kalman");
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(j["gyro"]["bias"][i].get<double>(), truth["gyro"]["bias"][i].get<double>(),
                4.0 * j["gyro"]["std"]["bias"][i].get<double>());
    EXPECT_NEAR(j["accel"]["matrix"][i][i].get<double>(),
                truth["accel"]["matrix"][i][i].get<double>(),
                4.0 * j["accel"]["std"]["matrix"][i][i].get<double>());
  }
  EXPECT_TRUE(j["convergence"]["parameters"]["accel_bias_x"]["converged"].get<bool>());
  const std::string csv = Slurp(history);
  EXPECT_EQ(csv.rfind("t,accel_bias_x,accel_bias_x_std,", 0), 0u) << csv.substr(0, 80);
  EXPECT_GT(std::count(csv.begin(), csv.end(), '\n'), 100);

  // --history with a method that has none: one line, no output at all.
  const std::string calib2 = dir_ + "/calib2.json";
  const std::string history2 = dir_ + "/history2.csv";
  r = Run("calibrate --input " + Simulated() + " --config " + Config() + " --output " + calib2 +
          " --history " + history2);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("keeps no estimate history"), std::string::npos) << r.err;
  EXPECT_FALSE(Exists(calib2));
  EXPECT_FALSE(Exists(history2));
  // ... said before any work: before the log is even read.
  r = Run("calibrate --input " + dir_ + "/no_such_log.csv --config " + Config() + " --output " +
          calib2 + " --history " + history2);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("--history: method"), std::string::npos) << r.err;
  // A history that cannot be written: no calibration file either.
  r = Run("calibrate --input " + sim + "/raw.csv --config " + config + scales + "--output " +
          calib2 + " --history " + dir_ + "/missing/history.csv");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("missing/history.csv"), std::string::npos) << r.err;
  EXPECT_FALSE(Exists(calib2));
  // A log without a gyroscope.
  std::string still = "t,ax,ay,az\n";
  for (int i = 0; i < 1000; ++i) still += std::to_string(0.01 * i) + ",0.1,0.2,9.8\n";
  r = Run("calibrate --input " + Write("still.csv", still) + " --config " + config + " --output " +
          calib2);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("needs a gyroscope"), std::string::npos) << r.err;
  EXPECT_FALSE(Exists(calib2));
}

// Issue 6: discover on a session with a hidden accelerometer bias tempco
// names it in discovery.json and the HTML report, and calibrate then fits
// it; bad input gives one line and writes nothing.
// 26 random poses, as in discovery_test.cc's DiscoverySession: discover's
// magnitudes then test every candidate and it leaves the turns out of its
// fits (on 24 poses every fit integrated every turn: 80 s of this test's
// time under the sanitizers); calibrate --effects below still fits the turns.
TEST_F(CliTest, DiscoverNamesHiddenEffectAndCalibrateFitsIt) {
  const std::string sim = dir_ + "/warm";
  const std::string sim_flags =
      " --sim_scheme random:26 --sim_temperature_start 20 --sim_temperature_end 35"
      " --sim_temperature_tau 120 --sim_accel_temperature_bias 0.005";
  RunResult r = Run("simulate --config " + Config() + sim_flags + " --seed 3 --output-dir " + sim);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string json_path = dir_ + "/discovery.json";
  const std::string html_path = dir_ + "/discovery.html";
  r = Run("discover --input " + sim + "/raw.csv --config " + Config() + " --output " + json_path +
          " --report " + html_path);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(json_path);
  const nlohmann::json j = nlohmann::json::parse(in);
  for (const char* key : {"baseline", "steps", "ambiguous", "final_model", "verdict"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_TRUE(j["baseline"]["gap"]["accel"].is_number());
  EXPECT_TRUE(j["baseline"]["cv_gap"]["accel"].is_number());
  ASSERT_GE(j["steps"].size(), 1u);
  const nlohmann::json& step = j["steps"][0];
  EXPECT_EQ(step["effect"], "accel_temperature_bias");
  EXPECT_EQ(step["parameters"].size(), 3u);
  EXPECT_TRUE(step["parameters"][0]["std"].is_number());
  for (const char* key : {"p_value", "delta_bic", "gap_before", "gap_after", "cv_gap_before",
                          "cv_gap_after", "description"}) {
    EXPECT_TRUE(step.contains(key)) << key;
  }
  EXPECT_LT(step["cv_gap_after"].get<double>(), 0.5 * step["cv_gap_before"].get<double>());
  EXPECT_FALSE(step["where"]["summary"].get<std::string>().empty());
  // Issue 21: which information each decision used, and a verdict per sensor.
  EXPECT_FALSE(step["information"].get<std::string>().empty());
  ASSERT_EQ(j["sensors"].size(), 2u);
  EXPECT_EQ(j["sensors"][0]["sensor"], "accelerometer");
  EXPECT_EQ(j["sensors"][0]["information"], step["information"]);
  EXPECT_NE(r.err.find("(from the " + step["information"].get<std::string>() + ")"),
            std::string::npos)
      << r.err;
  EXPECT_NE(j["verdict"].get<std::string>().find("accel_temperature_bias"), std::string::npos);
  const std::string html = Slurp(html_path);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("information used"), std::string::npos);
  EXPECT_EQ(html.find("src="), std::string::npos);
  EXPECT_EQ(html.find("href="), std::string::npos);

  const std::string calib = dir_ + "/calib.json";
  r = Run("calibrate --input " + sim + "/raw.csv --config " + Config() +
          " --effects [accel_temperature_bias] --output " + calib);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream cin(calib);
  const nlohmann::json c = nlohmann::json::parse(cin);
  ASSERT_TRUE(c["effects"].contains("accel_temperature_bias"));
  EXPECT_EQ(c["effects"]["accel_temperature_bias"]["value"].size(), 3u);
  EXPECT_TRUE(c["effects"]["accel_temperature_bias"]["std"][2].is_number());
}

TEST_F(CliTest, DiscoverBadInputGivesOneLineAndNoOutput) {
  const std::string json_path = dir_ + "/discovery.json";
  const std::string html_path = dir_ + "/discovery.html";
  RunResult r = Run("discover --input " + dir_ + "/missing.csv --config " + Config() +
                    " --output " + json_path + " --report " + html_path);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("missing.csv"), std::string::npos);
  const std::string config = Write("bad.yaml", "method: twelve_position\neffects: [temp_bias]\n");
  r = Run("discover --input " + Simulated() + " --config " + config + " --output " + json_path);
  EXPECT_EQ(r.exit_code, 1);
  const std::string line = OneLine(r);
  EXPECT_NE(line.find("bad.yaml:2"), std::string::npos) << line;
  EXPECT_NE(line.find("temp_bias"), std::string::npos) << line;
  r = Run("discover --input " + Simulated() + " --config " + Config());
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(OneLine(r).find("--output"), std::string::npos);
  EXPECT_FALSE(Exists(json_path));
  EXPECT_FALSE(Exists(html_path));
}

}  // namespace
}  // namespace gravcal
