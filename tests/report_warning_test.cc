// Issue 17: every warning a method gives carries a code (core/types.h
// WarningCode), and the calibration report explains every code with the
// action that fixes it; a warning without an explanation fails here. The
// sessions are those of scripts/golden_outputs.sh (one simulated run of every
// method, and the real recordings when they are there), calibrated by the
// command-line tool with --report: the report has one explained row per
// warning of the calibration JSON.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "gravcal/core/calibration.h"
#include "gravcal/workflows/report.h"
#include "test_util.h"
#include "workflows/report/warning_advice.h"

namespace gravcal {
namespace {

using testing_util::Count;
using testing_util::RunCli;
using testing_util::ScratchDir;
using testing_util::Slurp;

// The codes of the report's warning rows, in order.
std::vector<std::string> RowCodes(const std::string& html) {
  std::vector<std::string> codes;
  const std::string key = "data-code='";
  for (size_t at = html.find(key); at != std::string::npos; at = html.find(key, at + 1)) {
    const size_t begin = at + key.size();
    codes.push_back(html.substr(begin, html.find('\'', begin) - begin));
  }
  return codes;
}

TEST(ReportWarnings, EveryCodeHasAnExplanationAndAnAction) {
  size_t codes = 0;
  for (int i = 0;; ++i) {
    const WarningCode code = static_cast<WarningCode>(i);
    const std::string name = ToString(code);
    if (name == "unknown") break;
    ++codes;
    WarningCode back;
    ASSERT_TRUE(FromString(name, &back)) << name;
    EXPECT_EQ(back, code);
    const internal::WarningAdvice advice = internal::AdviceFor(code);
    if (code == WarningCode::kUnclassified) {
      EXPECT_TRUE(advice.meaning.empty());
      continue;
    }
    EXPECT_FALSE(advice.meaning.empty()) << name;
    EXPECT_FALSE(advice.action.empty()) << name;
  }
  EXPECT_GE(codes, 15u);
}

// The checker catches what it is for: a warning added without a code is
// marked unexplained in the report.
TEST(ReportWarnings, AWarningWithoutACodeIsMarkedUnexplained) {
  Calibration c;
  c.message = "planted";
  c.warnings = {"a warning with a code", "a warning without one"};
  c.warning_codes = {WarningCode::kStandardGravity};
  const std::string html = CalibrationToHtml(c, ImuLog(), "planted");
  EXPECT_EQ(Count(html, "class='warning'"), 1u);
  EXPECT_EQ(Count(html, "class='warning unexplained'"), 1u);
  EXPECT_EQ(RowCodes(html), (std::vector<std::string>{"standard_gravity", "unclassified"}));
}

struct WarningSession {
  std::string name;
  std::string config;
  // Extra flags of `simulate` and of `calibrate`.
  std::vector<std::string> simulate;
  std::vector<std::string> calibrate;
  // A real recording under RealDataDir() instead of a simulated log.
  std::string real_file;
};

std::vector<WarningSession> Sessions() {
  const std::vector<std::string> handheld_scales = {
      "--nominal_scale", "0.00059855", "--gyro_nominal_scale",
      "0.000133231",     "--gravity",  "9.80665"};
  return {
      {"twelve_position", "twelve_position.yaml", {}, {}, ""},
      {"twelve_position_newton", "twelve_position.yaml", {}, {"--solver", "newton"}, ""},
      {"twelve_position_gyro", "twelve_position_gyro.yaml", {}, {}, ""},
      {"ten_position", "ten_position.yaml", {}, {}, ""},
      {"known_attitude", "known_attitude.yaml", {}, {}, ""},
      {"handheld_kalman",
       "handheld_kalman.yaml",
       {"--sim_motion", "handheld"},
       handheld_scales,
       ""},
      {"discovery_effects", "discovery.yaml", {}, {}, ""},
      {"rate_table", "rate_table.yaml", {"--sim_motion", "rate_table"}, {}, ""},
      {"real_ferraris_nilspod", "ferraris_nilspod.yaml", {}, {}, "ferraris_nilspod/session.csv"},
      {"real_ferraris_nilspod_handheld",
       "ferraris_nilspod_handheld.yaml",
       {},
       {},
       "ferraris_nilspod/session.csv"},
      {"real_mpu6050_ten_pose", "mpu6050_ten_pose.yaml", {}, {}, "mpu6050_ten_pose/session.csv"},
      {"real_ahrs_static_poses",
       "ahrs_static_poses.yaml",
       {},
       {},
       "ahrs_static_poses/imu_good1.txt"},
  };
}

TEST(ReportWarnings, EveryWarningOfEveryMethodIsExplained) {
  ScratchDir dir;
  std::set<std::string> seen;
  size_t warnings = 0;
  for (const WarningSession& s : Sessions()) {
    SCOPED_TRACE(s.name);
    const std::string config = testing_util::SourceDir() + "/configs/" + s.config;
    std::string input;
    std::vector<std::string> calibrate = {"calibrate", "--config", config};
    if (s.real_file.empty()) {
      std::vector<std::string> sim = {"simulate", "--config",     config,      "--seed",
                                      "3",        "--output-dir", dir / s.name};
      sim.insert(sim.end(), s.simulate.begin(), s.simulate.end());
      ASSERT_EQ(RunCli(sim, dir).exit_code, 0);
      input = dir / (s.name + "/raw.csv");
      if (s.name == "known_attitude") {
        calibrate.insert(calibrate.end(), {"--attitudes", dir / (s.name + "/attitudes.csv")});
      }
      if (s.name == "rate_table") {
        calibrate.insert(calibrate.end(), {"--segments", dir / (s.name + "/segments.csv")});
      }
    } else {
      if (testing_util::RealDataDir().empty()) continue;
      input = testing_util::RealDataDir() + "/" + s.real_file;
    }
    const std::string json = dir / (s.name + ".json");
    const std::string html = dir / (s.name + ".html");
    calibrate.insert(calibrate.end(), {"--input", input, "--output", json, "--report", html});
    calibrate.insert(calibrate.end(), s.calibrate.begin(), s.calibrate.end());
    const testing_util::CliResult r = RunCli(calibrate, dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json calib = nlohmann::json::parse(Slurp(json));
    const size_t n = calib.value("warnings", nlohmann::json::array()).size();
    const std::string report = Slurp(html);
    const std::vector<std::string> codes = RowCodes(report);
    EXPECT_EQ(codes.size(), n);
    for (size_t i = 0; i < codes.size(); ++i) {
      EXPECT_NE(codes[i], "unclassified") << calib["warnings"][i];
      seen.insert(codes[i]);
    }
    EXPECT_EQ(Count(report, "unexplained"), 0u);
    warnings += n;
  }
  std::string list;
  for (const std::string& c : seen) list += c + " ";
  ::testing::Test::RecordProperty("codes_seen", list);
  std::printf("%zu warnings, codes seen: %s\n", warnings, list.c_str());
  // The sessions exercise more than one kind of warning: four kinds from
  // the simulated sessions alone, a fifth from the real recordings, which
  // are skipped when ../shared/data/real is absent (a clean clone elsewhere).
  EXPECT_GE(seen.size(), testing_util::RealDataDir().empty() ? 4u : 5u) << list;
}

}  // namespace
}  // namespace gravcal
