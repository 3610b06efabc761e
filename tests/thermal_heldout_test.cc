// Issue 35's held-out check, cheap part: a thermal session from an
// independent generator (tests/thermal_heldout.py, numpy, no gravcal code)
// with a cubic bias, calibrated by the gravcal tool with the shipped
// configs/thermal.yaml, exported to PX4 and ArduPilot, and corrected by the
// autopilots' own equations written again in Python: what remains over the
// range is within 3 sigma of a pose mean's noise. The full run (seeds,
// layouts, single pose, small span, hysteresis) is the same script without
// --smoke (docs/workflows/thermal.md). Skips without /usr/bin/python3 and
// numpy.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace {

TEST(ThermalHeldOut, IndependentSessionThroughBothAutopilotsEquations) {
  if (std::system("/usr/bin/python3 -c 'import numpy' > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "/usr/bin/python3 with numpy is not available";
  }
  const std::string dir = ::testing::TempDir() + "gravcal_thermal_heldout";
  const std::string out = dir + ".json";
  const std::string command = std::string("/usr/bin/python3 ") + GRAVCAL_SOURCE_DIR +
                              "/tests/thermal_heldout.py " + GRAVCAL_CLI_PATH + " " +
                              GRAVCAL_SOURCE_DIR + " " + dir + " --smoke > " + out;
  const int status = std::system(command.c_str());
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  ASSERT_TRUE(WIFEXITED(status)) << command;
  if (WEXITSTATUS(status) == 77) GTEST_SKIP() << "numpy is missing";
  EXPECT_EQ(WEXITSTATUS(status), 0) << text.str();
  EXPECT_NE(text.str().find("\"pass\": true"), std::string::npos) << text.str();
}

}  // namespace
