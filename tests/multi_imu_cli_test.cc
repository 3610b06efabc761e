// gravcal calibrate with configs/multi_imu.yaml (issue 38): one table of
// several IMUs in, one calibration per IMU, the assembly and its exports
// out; bad configs and tables refused with one line and no output.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "cli_runner.h"
#include "gravcal/simulation/plate_simulator.h"
#include "gravcal/workflows/multi_imu_log.h"

namespace gravcal {
namespace {

using namespace testing_util;

const std::string kMultiImuConfig = std::string(GRAVCAL_SOURCE_DIR) + "/configs/multi_imu.yaml";

std::string PlateCsv(int imus, int permuted) {
  PlateSimulatorOptions o;
  o.imus = imus;
  o.permuted_imu = permuted;
  o.mounting = "aligned";
  o.imu.hold_seconds = 4.0;
  o.imu.initial_still_seconds = 4.0;
  o.imu.rotation_seconds = 2.0;
  o.oversample = 2;
  SimulatedPlate plate;
  std::string error;
  EXPECT_TRUE(SimulatePlate(o, 21, &plate, &error)) << error;
  return PlateToCsv(plate);
}

TEST(MultiImuCli, CalibratesATableOfThreeImus) {
  ScratchDir scratch;
  const std::string input = scratch.Write("plate.csv", PlateCsv(3, 2));
  const std::string out = scratch / "out";
  const CliResult r = RunCli({"calibrate", "--config", kMultiImuConfig, "--input", input,
                              "--output-dir", out, "--report", scratch / "report.html"},
                             scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* name : {"imu0.json", "imu1.json", "imu2.json", "assembly.json",
                           "kalibr_imu_chain.yaml", "px4_rotations.params"}) {
    EXPECT_TRUE(FileExists(out + "/" + name)) << name;
  }
  EXPECT_NE(r.err.find("imu2 looks rotated 90 degrees about z from imu0"), std::string::npos)
      << r.err;
  const nlohmann::json a = nlohmann::json::parse(Slurp(out + "/assembly.json"));
  ASSERT_EQ(a["imus"].size(), 3u);
  EXPECT_EQ(a["reference"], "imu0");
  EXPECT_TRUE(a["imus"][1]["time_offset"].is_number());
  EXPECT_TRUE(a["imus"][1]["rotation_sigma"][0].is_number());
  EXPECT_EQ(a["time_offset_covariance"].size(), 3u);
  const nlohmann::json c = nlohmann::json::parse(Slurp(out + "/imu1.json"));
  EXPECT_EQ(c["method"], "multi_imu");
  // The aligned IMUs are PX4 rotation 0; the permuted one is yaw 90 (2).
  const std::string px4 = Slurp(out + "/px4_rotations.params");
  EXPECT_NE(px4.find("CAL_ACC1_ROT 0"), std::string::npos) << px4;
  EXPECT_NE(px4.find("CAL_ACC2_ROT 2"), std::string::npos) << px4;
  EXPECT_NE(Slurp(scratch / "report.html").find("imu2"), std::string::npos);
}

TEST(MultiImuCli, BadConfigsAndTablesAreRefused) {
  ScratchDir scratch;
  const std::string out = scratch / "out";
  const std::string input = scratch.Write("plate.csv", "t,a.ax,a.ay\n0,1,2\n");
  CliResult r = RunCli(
      {"calibrate", "--config", kMultiImuConfig, "--input", input, "--output-dir", out}, scratch);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("found no IMU columns"), std::string::npos) << r.err;
  EXPECT_FALSE(FileExists(out + "/assembly.json"));
  const std::string bad =
      scratch.Write("bad.yaml", "method: multi_imu\nimus:\n  - name: a\n    colums: [x]\n");
  r = RunCli({"calibrate", "--config", bad, "--input", input, "--output-dir", out}, scratch);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("bad.yaml:4: imus[0]: unknown key 'colums'"), std::string::npos) << r.err;
  r = RunCli({"calibrate", "--config", kMultiImuConfig, "--input", input}, scratch);
  EXPECT_NE(r.err.find("needs --output-dir"), std::string::npos) << r.err;
  const std::string missing =
      scratch.Write("missing.yaml", "imus:\n  - name: a\n  - name: b\n    accel_units: furlongs\n");
  r = RunCli({"calibrate", "--config", missing, "--input", input, "--output-dir", out}, scratch);
  EXPECT_NE(r.err.find("missing.yaml:3: imus[1]: accel_units must be"), std::string::npos) << r.err;
}

TEST(MultiImuLog, HeaderNamesTheImus) {
  const std::vector<MultiImuLogSpec> imus = ImusOfHeader(
      "# comment\nt,left.ax,left.ay,left.az,right.ax,right.ay,right.az,right.gx,"
      "right.gy,right.gz,temp\n",
      1.0, 2.0);
  ASSERT_EQ(imus.size(), 2u);
  EXPECT_EQ(imus[0].name, "left");
  EXPECT_EQ(imus[0].columns.size(), 3u);
  EXPECT_EQ(imus[1].columns.size(), 6u);
  EXPECT_EQ(imus[1].columns[3], "right.gx");
  EXPECT_EQ(imus[1].gyro_scale, 2.0);
}

}  // namespace
}  // namespace gravcal
