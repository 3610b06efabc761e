// Issue 20: flags a command does not use are errors; the calibrate summary
// line; a file named once in a message.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::CliResult;

class CliFlagsTest : public ::testing::Test {
 protected:
  CliResult Run(const std::string& args) const { return testing_util::RunCli(args, scratch_); }
  std::string Config() const { return testing_util::SourceDir() + "/configs/twelve_position.yaml"; }
  std::string Simulated() const {
    const std::string sim = scratch_ / "sim";
    const CliResult r = Run("simulate --config " + Config() + " --seed 3 --output-dir " + sim);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return sim + "/raw.csv";
  }
  static size_t Count(const std::string& text, const std::string& part) {
    size_t n = 0;
    for (size_t p = text.find(part); p != std::string::npos; p = text.find(part, p + 1)) ++n;
    return n;
  }

  testing_util::ScratchDir scratch_;
};

// calibrate --kalibr used to exit 0 and write nothing: --kalibr belongs to
// noise. (The example, calibrate --report, is a calibrate flag now.)
TEST_F(CliFlagsTest, AFlagTheCommandDoesNotUseIsAnErrorNamingBoth) {
  const std::string raw = Simulated();
  const std::string out = scratch_ / "out.json";
  const std::string report = scratch_ / "imu.yaml";
  CliResult r = Run("calibrate --input " + raw + " --config " + Config() + " --output " + out +
                    " --kalibr " + report);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--kalibr"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'calibrate'"), std::string::npos) << r.err;
  EXPECT_FALSE(testing_util::FileExists(out));
  EXPECT_FALSE(testing_util::FileExists(report));
  // Spelled with dashes or underscores, with '=' or apart: the same flag.
  r = Run("apply --calibration c.json --input " + raw + " --output " + out + " --output-dir=x");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--output-dir is not used by 'apply'"), std::string::npos) << r.err;
  r = Run("simulate --config " + Config() + " --output_dir " + (scratch_ / "s") + " --threads 2");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--threads is not used by 'simulate'"), std::string::npos) << r.err;
  // merge-summaries reads no config: a config key there is refused too.
  r = Run("merge-summaries --output-dir " + (scratch_ / "m") + " --gravity 9.8 a/ b/");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("--gravity is not used by 'merge-summaries'"), std::string::npos) << r.err;
  // Unknown flags still say unknown.
  r = Run("calibrate --input " + raw + " --no-such-flag 1");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("unknown flag --no-such-flag"), std::string::npos) << r.err;
}

TEST_F(CliFlagsTest, TheFlagsACommandListsAreAccepted) {
  const std::string raw = Simulated();
  const std::string out = scratch_ / "out.json";
  const CliResult r =
      Run("calibrate --input " + raw + " --config " + Config() + " --output=" + out);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(testing_util::FileExists(out));
}

// Raw counts without nominal_scale: the "before" residual is counts minus
// m/s^2 and means nothing ("|a| - g rms 58191 -> 0.00006" before).
TEST_F(CliFlagsTest, SummaryLineSaysUnscaledInsteadOfAMeaninglessBeforeResidual) {
  const std::string raw = Simulated();
  const std::string out = scratch_ / "out.json";
  CliResult r = Run("calibrate --input " + raw + " --config " + Config() + " --output " + out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("->"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("unscaled"), std::string::npos) << r.err;
  // With the nominal scale of the simulated counts (16384 counts per g),
  // the before figure is meaningful and printed.
  r = Run("calibrate --input " + raw + " --config " + Config() +
          " --nominal_scale 0.000598550415 --output " + out);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("->"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("unscaled"), std::string::npos) << r.err;
}

// "bom.csv: bom.csv: 2 samples are too few" before: the detector and the
// method both named the file.
TEST_F(CliFlagsTest, AFileIsNamedOnceInAMessage) {
  const std::string bom = scratch_.Write("bom.csv", "\xEF\xBB\xBFt,ax,ay,az\n0,1,2,3\n0.1,1,2,3\n");
  const CliResult r = Run("calibrate --input " + bom + " --config " + Config() + " --output " +
                          (scratch_ / "out.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("2 samples are too few"), std::string::npos) << r.err;
  EXPECT_EQ(Count(r.err, "bom.csv"), 1u) << r.err;
}

// A binary file's header goes into the message escaped, never raw.
TEST_F(CliFlagsTest, BinaryHeaderBytesAreEscaped) {
  const std::string garbled =
      scratch_.Write("garbled.csv", std::string("\x1b[31m\x01\xff\xfe,ax,ay\n0,1,2\n", 20));
  const CliResult r = Run("calibrate --input " + garbled + " --config " + Config() + " --output " +
                          (scratch_ / "out.json"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\xff'), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\\x1b[31m\\x01\\xff\\xfe"), std::string::npos) << r.err;
}

// Issue 32, strict configuration at the command line: help on an unknown
// command fails, --version names gravcal, Ceres and Eigen, a --config that
// is a folder, a flag given twice and contradictory settings are one-line
// errors naming what is wrong, and nothing is written.
TEST_F(CliFlagsTest, StrictConfigurationSaysNo) {
  CliResult r = Run("help bogus");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("unknown command 'bogus'"), std::string::npos) << r.err;
  EXPECT_EQ(Run("help calibrate").exit_code, 0);
  for (const char* version : {"--version", "version"}) {
    r = Run(version);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.out.rfind("gravcal 0.", 0), 0u) << r.out;
    EXPECT_NE(r.out.find("Ceres Solver 2."), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("Eigen 3."), std::string::npos) << r.out;
  }
  const std::string out = scratch_ / "out.json";
  const std::string missing = scratch_ / "never_read.csv";
  struct Case {
    std::string args;
    std::vector<std::string> named;
  };
  const Case cases[] = {
      {"--config " + testing_util::SourceDir() + "/configs", {"not a regular file", "configs"}},
      {"--config " + Config() + " --gravity 9.81 --latitude 45", {"'gravity'", "'latitude'"}},
      {"--config " + Config() + " --solver newton --loss cauchy", {"'solver'", "'loss'"}},
      {"--config " + Config() + " --gyro-g-sensitivity true", {"'gyro_model'", "'gyro_g_sens"}},
      {"--config " + Config() + " --gyro-model none --gyro-joint true",
       {"'gyro_model'", "'gyro_joint'"}},
      {"--config " + Config() + " --gravity 9.81 --gravity 9.79", {"--gravity is given twice"}},
      {"--config " + Config() + " --output " + out, {"--output is given twice"}},
  };
  for (const Case& c : cases) {
    r = Run("calibrate --input " + missing + " --output " + out + " " + c.args);
    EXPECT_EQ(r.exit_code, 1) << c.args;
    EXPECT_EQ(Count(r.err, "\n"), 1u) << r.err;
    for (const std::string& name : c.named) {
      EXPECT_NE(r.err.find(name), std::string::npos) << c.args << ": " << r.err;
    }
    EXPECT_FALSE(testing_util::FileExists(out)) << c.args;
  }
  const std::string twice =
      scratch_.Write("twice.yaml", "gravity: 9.81\nloss: cauchy\ngravity: 9.7\n");
  r = Run("calibrate --input " + missing + " --output " + out + " --config " + twice);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("twice.yaml:3: duplicate key 'gravity'"), std::string::npos) << r.err;
  const std::string two = scratch_.Write("two.yaml", "gravity: 9.81\n---\nloss: cauchy\n");
  r = Run("calibrate --input " + missing + " --output " + out + " --config " + two);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("second YAML document"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace gravcal
