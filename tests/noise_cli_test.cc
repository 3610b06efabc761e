// Issue 14 in the user's workflow: `gravcal noise` on simulated still logs
// of known noise (noise.json read back against the truth, the Kalibr and
// handheld YAML consistent with it), its bad input (one line, non-zero exit,
// no file), and `gravcal calibrate --noise`: the pose-mean covariance and the
// handheld filter's Q from the noise model, and a bad noise file.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/io/noise_io.h"
#include "gravcal/simulation/noise_process.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "still_log.h"
#include "test_util.h"

namespace gravcal {
namespace {

using testing_util::CliResult;
using testing_util::FileExists;
using testing_util::RunCli;
using testing_util::ScratchDir;
using testing_util::Slurp;

constexpr double kRate = 100.0;
// Truth of the still logs: white noise N and rate random walk K per sensor
// (SI), meeting at tau = 3 s (accelerometer) and 1 s (gyroscope).
constexpr double kAccelN = 2e-3;
constexpr double kAccelK = 1.2e-3;
constexpr double kGyroN = 2e-4;
constexpr double kGyroK = 3.5e-4;
// rad/s per gyroscope count of the logs (gyro_nominal_scale).
constexpr double kGyroScale = 1e-3;

// A still log of `seconds` with the noise above; gyroscope in counts of
// kGyroScale.
ImuLog StillLog(double seconds, uint64_t seed) {
  NoiseProcessOptions accel;
  accel.rate_hz = kRate;
  accel.white_noise = kAccelN;
  accel.random_walk = kAccelK;
  NoiseProcessOptions gyro = accel;
  gyro.white_noise = kGyroN;
  gyro.random_walk = kGyroK;
  return testing_util::StillLog(accel, gyro, kGyroScale, seed, seconds);
}

std::string WriteLog(const ImuLog& log, const ScratchDir& dir, const std::string& name) {
  std::string error;
  const std::string path = dir / name;
  EXPECT_TRUE(WriteImuLogCsv(log, path, &error)) << error;
  return path;
}

// The flags every noise run of these logs takes: the gyroscope's raw unit
// and the whole log (known still).
std::string Units() { return " --gyro_nominal_scale " + std::to_string(kGyroScale) + " "; }

// One line on stderr, naming `what`; exit non-zero.
void ExpectOneLineError(const CliResult& r, const std::string& what) {
  EXPECT_NE(r.exit_code, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_EQ(r.err.rfind("gravcal: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find(what), std::string::npos) << "'" << what << "' not in: " << r.err;
}

// The YAML files carry 9 significant digits.
void ExpectSame(double yaml, double json) { EXPECT_NEAR(yaml, json, 1e-8 * std::abs(json)); }

// A 2-hour still log: N and K of every axis within 4 reported sigmas of the
// truth (and the sigmas small: N to 1 %, K to 15 %); Kalibr's four keys are
// the axis maxima of noise.json; the handheld keys load as a config with
// the same values.
TEST(NoiseCli, StillLogRecoversTheTruth) {
  ScratchDir dir;
  const std::string log = WriteLog(StillLog(7200.0, 1), dir, "still.csv");
  const std::string out = dir / "noise.json";
  const std::string kalibr = dir / "imu.yaml";
  const std::string handheld = dir / "hk.yaml";
  const CliResult r = RunCli("noise --input " + log + Units() + "--output " + out + " --kalibr " +
                                 kalibr + " --handheld " + handheld,
                             dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ImuNoise noise;
  std::string error;
  ASSERT_TRUE(ReadNoiseJson(out, &noise, &error)) << error;
  EXPECT_NEAR(noise.model.rate_hz, kRate, 1e-6);
  const struct {
    const char* name;
    const std::array<AxisNoiseModel, 3>* axes;
    double n, k;
  } sensors[] = {{"accel", &noise.model.accel, kAccelN, kAccelK},
                 {"gyro", &noise.model.gyro, kGyroN, kGyroK}};
  for (const auto& s : sensors) {
    for (int a = 0; a < 3; ++a) {
      const NoiseTerm& n = (*s.axes)[a].white_noise;
      const NoiseTerm& k = (*s.axes)[a].random_walk;
      ASSERT_TRUE(n.visible() && k.visible()) << s.name << a << ": " << n.reason << k.reason;
      EXPECT_NEAR(n.value, s.n, 4.0 * n.std) << s.name << a;
      EXPECT_NEAR(k.value, s.k, 4.0 * k.std) << s.name << a;
      EXPECT_LT(n.std, 0.01 * s.n) << s.name << a;
      EXPECT_LT(k.std, 0.15 * s.k) << s.name << a;
    }
  }
  const YAML::Node k = YAML::LoadFile(kalibr);
  ExpectSame(k["accelerometer_noise_density"].as<double>(),
             AxisMaximum(noise.model.accel, &AxisNoiseModel::white_noise));
  ExpectSame(k["accelerometer_random_walk"].as<double>(),
             AxisMaximum(noise.model.accel, &AxisNoiseModel::random_walk));
  ExpectSame(k["gyroscope_noise_density"].as<double>(),
             AxisMaximum(noise.model.gyro, &AxisNoiseModel::white_noise));
  ExpectSame(k["gyroscope_random_walk"].as<double>(),
             AxisMaximum(noise.model.gyro, &AxisNoiseModel::random_walk));
  EXPECT_DOUBLE_EQ(k["update_rate"].as<double>(), kRate);
  Config config;
  ASSERT_TRUE(LoadConfigFile(handheld, &config, &error)) << error;
  ExpectSame(config.handheld.accel_noise_density,
             AxisMaximum(noise.model.accel, &AxisNoiseModel::white_noise));
  ExpectSame(config.handheld.gyro_bias_walk,
             AxisMaximum(noise.model.gyro, &AxisNoiseModel::random_walk));
}

// A hobby board read over USB: unsigned counts around 32768 and host time
// stamps in bursts (five samples 2 ms apart every 50 ms, a 0.3 s stall).
// Accepted: the mean removed, the rate from least squares over the sample
// index, every choice in noise.json; N of the truth. With nominal_offset
// the unit is checked against gravity; a nominal rate is used as given.
TEST(NoiseCli, OffsetCountsWithHostTimeStamps) {
  ScratchDir dir;
  ImuLog log = StillLog(300.0, 6);
  const double scale = 9.80665 / 16384.0;
  for (Eigen::Vector3d& a : log.accel) a = a / scale + Eigen::Vector3d::Constant(32768.0);
  for (size_t i = 0; i < log.size(); ++i) {
    log.t[i] = 0.05 * static_cast<double>(i / 5) + 0.002 * static_cast<double>(i % 5) +
               (i >= 15000 ? 0.3 : 0.0);
  }
  const std::string path = WriteLog(log, dir, "usb.csv");
  const std::string out = dir / "noise.json";
  const std::string common = "noise --input " + path + Units() + "--nominal_scale " +
                             std::to_string(scale) + " --noise_find_still false --output " + out;
  CliResult r = RunCli(common, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(Slurp(out));
  const nlohmann::json& choices = j.at("choices");
  EXPECT_EQ(choices.at("units").at("unit_check").get<std::string>().rfind("not checked", 0), 0u)
      << choices.dump();
  EXPECT_NE(choices.at("timing").at("rate_source").get<std::string>().find("least squares"),
            std::string::npos);
  EXPECT_NEAR(j.at("rate_hz").get<double>(), kRate, 0.2);
  EXPECT_NE(r.err.find("not checked"), std::string::npos) << r.err;
  ImuNoise noise;
  std::string error;
  ASSERT_TRUE(ReadNoiseJson(out, &noise, &error)) << error;
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(noise.model.accel[a].white_noise.value / kAccelN, 1.0, 0.1) << a;
    EXPECT_NEAR(noise.model.gyro[a].white_noise.value / kGyroN, 1.0, 0.1) << a;
  }
  r = RunCli(common + " --nominal_offset 32768 --noise_rate 100", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  j = nlohmann::json::parse(Slurp(out));
  EXPECT_EQ(j.at("choices").at("units").at("unit_check").get<std::string>().rfind("checked", 0),
            0u);
  EXPECT_DOUBLE_EQ(j.at("rate_hz").get<double>(), 100.0);
  // A wrong stated offset is refused, naming it.
  ExpectOneLineError(RunCli(common + " --nominal_offset 30000", dir), "nominal_offset");
}

// Each bad input: one line naming the problem, exit 1, no file written
// (with --kalibr and --handheld asked for too).
TEST(NoiseCli, BadInputWritesNothing) {
  ScratchDir dir;
  const std::string out = dir / "noise.json";
  const std::string extra =
      " --output " + out + " --kalibr " + (dir / "imu.yaml") + " --handheld " + (dir / "hk.yaml");
  auto expect_nothing = [&] {
    EXPECT_FALSE(FileExists(out));
    EXPECT_FALSE(FileExists(dir / "imu.yaml"));
    EXPECT_FALSE(FileExists(dir / "hk.yaml"));
  };
  const std::string still = WriteLog(StillLog(200.0, 2), dir, "short.csv");
  // Too short for the tau asked: 200 s of rest, tau 100 s needs 500 s.
  ExpectOneLineError(
      RunCli("noise --input " + still + Units() + "--noise_max_tau 100" + extra, dir),
      "too short for tau up to 100 s");
  expect_nothing();
  // Long enough for the curve, too short to show the random walk Kalibr
  // needs: 5 s of rest.
  const std::string five = WriteLog(StillLog(5.0, 3), dir, "five.csv");
  ExpectOneLineError(
      RunCli("noise --input " + five + Units() + "--noise_find_still false" + extra, dir),
      "Kalibr needs");
  expect_nothing();
  // Time stamps no uniform grid fits: the second half ten times slower.
  ImuLog gap = StillLog(200.0, 4);
  for (size_t i = 10000; i < gap.size(); ++i) gap.t[i] = gap.t[10000] + 0.1 * (i - 10000.0);
  ExpectOneLineError(RunCli("noise --input " + WriteLog(gap, dir, "gap.csv") + Units() +
                                "--noise_find_still false" + extra,
                            dir),
                     "depart from a uniform grid");
  expect_nothing();
  // A moving log: a twelve-position session taken as still.
  SimulatorOptions sim;
  sim.raw_counts = false;
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 1, &session, &error)) << error;
  const std::string moving = WriteLog(session.log, dir, "moving.csv");
  ExpectOneLineError(RunCli("noise --input " + moving + " --noise_find_still false" + extra, dir),
                     "the log moves");
  expect_nothing();
  // The accelerometer not in m/s^2 (counts with nominal_scale 1).
  ImuLog counts = StillLog(200.0, 5);
  for (Eigen::Vector3d& a : counts.accel) a *= 16384.0 / 9.80665;
  ExpectOneLineError(RunCli("noise --input " + WriteLog(counts, dir, "counts.csv") + Units() +
                                "--noise_find_still false" + extra,
                            dir),
                     "set nominal_scale");
  expect_nothing();
  // Unreadable.
  ExpectOneLineError(RunCli("noise --input " + (dir / "missing.csv") + extra, dir), "missing.csv");
  expect_nothing();
}

// Issue 32: every value of a noise.json is checked for range and sign on
// reading, with the message naming the file and the value's path (a
// negative white noise used to surface as "positions do not determine all 9
// parameters").
TEST(NoiseCli, EveryNoiseJsonValueIsCheckedForRangeAndSign) {
  ImuNoise noise;
  noise.model.rate_hz = kRate;
  noise.model.still_begin = 0;
  noise.model.still_end = 1000;
  noise.model.still_t_begin = 0.0;
  noise.model.still_t_end = 10.0;
  for (auto* axes : {&noise.model.accel, &noise.model.gyro}) {
    for (AxisNoiseModel& axis : *axes) {
      axis.white_noise.value = 2e-3;
      axis.white_noise.std = 1e-5;
      axis.white_noise.tau = 1.0;
      axis.white_noise.tau_min = 0.01;
      axis.white_noise.tau_max = 3.0;
      axis.random_walk.value = 1e-3;
    }
  }
  for (auto* curves : {&noise.accel_curves, &noise.gyro_curves}) {
    for (AllanDeviation& c : *curves) {
      for (double tau : {0.01, 0.1, 1.0}) {
        AllanPoint p;
        p.tau = tau;
        p.adev = 2e-3 / std::sqrt(tau);
        p.lo = 0.9 * p.adev;
        p.hi = 1.1 * p.adev;
        p.edf = 100.0 / tau;
        c.points.push_back(p);
      }
      c.confidence = 0.683;
    }
  }
  const nlohmann::json good = nlohmann::json::parse(NoiseToJson(noise));
  ImuNoise read;
  std::string error;
  ASSERT_TRUE(NoiseFromJson(good.dump(), "noise.json", &read, &error)) << error;
  EXPECT_DOUBLE_EQ(read.model.accel[1].white_noise.value, 2e-3);
  // JSON pointer, bad value, what the message must name.
  struct Case {
    const char* pointer;
    nlohmann::json value;
    const char* named;
  };
  const Case cases[] = {
      {"/accel/x/white_noise/value", -0.01, "accel.x.white_noise.value must be a positive number"},
      {"/accel/y/random_walk/value", 0.0, "accel.y.random_walk.value"},
      {"/gyro/z/white_noise/std", -1e-5, "gyro.z.white_noise.std must be a number >= 0"},
      {"/gyro/x/white_noise/tau", 0.0, "gyro.x.white_noise.tau"},
      {"/accel/z/white_noise/tau_range/0", -1.0, "accel.z.white_noise.tau_range[0]"},
      {"/accel/z/white_noise/tau_range/0", 5.0, "accel.z.white_noise.tau_range: max is below min"},
      {"/accel/z/white_noise/value", "2e-3", "accel.z.white_noise.value must be a number"},
      {"/rate_hz", -100.0, "rate_hz must be a positive number"},
      {"/rate_hz", 0.0, "rate_hz"},
      {"/confidence", 1.5, "confidence must be a number between 0 and 1"},
      {"/still/t_end", -5.0, "still.t_end is before still.t_begin"},
      {"/accel/x/allan/tau/1", 0.001, "accel.x.allan.tau[1] must be larger"},
      {"/gyro/y/allan/adev/2", -1.0, "gyro.y.allan.adev[2] must be a number >= 0"},
      {"/accel/y/allan/lo/0", 1.0, "accel.y.allan[0]: lo <= adev <= hi"},
      {"/accel/y/allan/edf/0", 0.0, "accel.y.allan.edf[0] must be a positive number"},
      // A variance (the square) beyond double arithmetic.
      {"/accel/x/white_noise/value", 1e300,
       "accel.x.white_noise.value must be a positive number up to 1e150"},
      {"/gyro/y/random_walk/std", 1e200, "gyro.y.random_walk.std must be a number >= 0, up to"},
  };
  for (const Case& c : cases) {
    nlohmann::json bad = good;
    bad[nlohmann::json::json_pointer(c.pointer)] = c.value;
    EXPECT_FALSE(NoiseFromJson(bad.dump(), "bad_noise.json", &read, &error)) << c.pointer;
    EXPECT_EQ(error.rfind("bad_noise.json: ", 0), 0u) << error;
    EXPECT_NE(error.find(c.named), std::string::npos) << c.pointer << ": " << error;
  }
  // A missing axis or section is named by its path (not the JSON library's
  // "key 'y' not found"); a key set twice is refused, not the last one taken.
  const std::pair<std::string, std::string> edits[] = {{"/accel/y", "accel.y is missing"},
                                                       {"/still", "still is missing"}};
  for (const auto& [pointer, named] : edits) {
    nlohmann::json bad = good;
    bad[nlohmann::json::json_pointer(pointer).parent_pointer()].erase(
        pointer.substr(pointer.rfind('/') + 1));
    EXPECT_FALSE(NoiseFromJson(bad.dump(), "bad_noise.json", &read, &error)) << pointer;
    EXPECT_EQ(error, "bad_noise.json: not a noise.json: " + named);
  }
  const std::string text = good.dump();
  const std::string twice = "{\"rate_hz\": 50, " + text.substr(1);
  EXPECT_FALSE(NoiseFromJson(twice, "bad_noise.json", &read, &error));
  EXPECT_EQ(
      error,
      "bad_noise.json: not a noise.json: key 'rate_hz' appears twice (a key may be set once)");
}

// calibrate --noise: a bad noise file or a method that uses none is one
// line naming it and no calibration; a good one is used by the
// twelve-position poses (a random-walk bias makes the model's pose
// variance larger than the white-noise one: larger sigmas).
TEST(NoiseCli, CalibrateWithNoiseModel) {
  ScratchDir dir;
  const std::string noise = dir / "noise.json";
  ASSERT_EQ(RunCli("noise --input " + WriteLog(StillLog(3600.0, 6), dir, "still.csv") + Units() +
                       "--output " + noise,
                   dir)
                .exit_code,
            0);
  SimulatorOptions sim;
  sim.raw_counts = false;
  sim.accel_noise = kAccelN * std::sqrt(kRate);
  sim.accel_bias_random_walk = kAccelK;
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 2, &session, &error)) << error;
  const std::string log = WriteLog(session.log, dir, "session.csv");
  const std::string calib = dir / "calib.json";
  const std::string white = dir / "white.json";
  ASSERT_EQ(RunCli("calibrate --input " + log + " --output " + white, dir).exit_code, 0);
  const CliResult r =
      RunCli("calibrate --input " + log + " --noise " + noise + " --output " + calib, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("differs from the poses"), std::string::npos) << r.err;
  const nlohmann::json a = nlohmann::json::parse(Slurp(white));
  const nlohmann::json b = nlohmann::json::parse(Slurp(calib));
  for (int i = 0; i < 3; ++i) {
    EXPECT_GT(b["accel"]["std"]["bias"][i].get<double>(),
              1.2 * a["accel"]["std"]["bias"][i].get<double>())
        << i;
  }

  const std::string bad = dir / "bad.json";
  std::ofstream(bad) << "{\"rate_hz\": 100";
  const std::string out = dir / "calib2.json";
  ExpectOneLineError(
      RunCli("calibrate --input " + log + " --noise " + bad + " --output " + out, dir), "bad.json");
  EXPECT_FALSE(FileExists(out));
  ExpectOneLineError(
      RunCli("calibrate --input " + log + " --noise " + (dir / "none.json") + " --output " + out,
             dir),
      "none.json");
  EXPECT_FALSE(FileExists(out));
  ExpectOneLineError(RunCli("calibrate --input " + log + " --method rate_table --noise " + noise +
                                " --output " + out,
                            dir),
                     "uses no noise model");
  EXPECT_FALSE(FileExists(out));
}

// The handheld filter takes Q from the noise model unless a key sets it,
// and says so.
TEST(NoiseCli, HandheldQFromNoiseModel) {
  ScratchDir dir;
  const std::string noise = dir / "noise.json";
  ASSERT_EQ(RunCli("noise --input " + WriteLog(StillLog(3600.0, 7), dir, "still.csv") + Units() +
                       "--output " + noise,
                   dir)
                .exit_code,
            0);
  const std::string sim = dir / "handheld";
  ASSERT_EQ(
      RunCli("simulate --sim_motion handheld --seed 3 --sim_raw_counts false --output-dir " + sim,
             dir)
          .exit_code,
      0);
  const std::string config = testing_util::SourceDir() + "/configs/handheld_kalman.yaml";
  const std::string calibrate = "calibrate --input " + sim + "/raw.csv --config " + config +
                                " --gravity 9.80665 --noise " + noise + " --output " +
                                (dir / "calib.json");
  CliResult r = RunCli(calibrate, dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("handheld filter Q: hk_accel_noise_density 0.002"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("from the noise model " + noise), std::string::npos) << r.err;
  r = RunCli(calibrate + " --hk_gyro_bias_walk 0", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("hk_gyro_bias_walk as set in the config"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace gravcal
