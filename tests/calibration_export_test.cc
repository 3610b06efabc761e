// Issue 16: apply with every term (streaming, "-"), the exporters against
// their targets' equations implemented here independently, the C corrector
// compiled and run, and the calibration reader's errors.
#include "gravcal/io/calibration_export.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "c_corrector_check.h"
#include "cli_runner.h"
#include "gravcal/core/calibration.h"
#include "gravcal/core/thermal_rate.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/imu_stream.h"
#include "gravcal/io/log_reader.h"
#include "util/random_vector.h"

namespace gravcal {
namespace {

using testing_util::RunCli;
using testing_util::ScratchDir;
using testing_util::Slurp;

Eigen::Matrix3d SmallRotation(double x, double y, double z) {
  Eigen::Matrix3d s;
  s << 0, -z, y, z, 0, -x, -y, x, 0;
  // exp of the skew matrix by its series (exact enough for a fixed test matrix).
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity(), term = Eigen::Matrix3d::Identity();
  for (int k = 1; k < 20; ++k) {
    term = term * s / k;
    r += term;
  }
  return r;
}

void AddEffect(Effect effect, const std::vector<double>& values, Calibration* c) {
  EffectEstimate e;
  e.effect = effect;
  e.names = Info(effect).parameter_names;
  e.values = values;
  e.std.assign(values.size(), 0.0);
  e.unit = Info(effect).unit;
  c->effects.estimates.push_back(e);
}

// A calibration in raw counts with every effect the catalogue can apply,
// and twelve static positions generated from its forward model.
Calibration FullCalibration(bool temperature_and_drift) {
  Calibration c;
  c.method = "twelve_position";
  c.accel.model.parameterization = AccelParameterization::kAffine;
  c.accel.model.bias << 30.0, -42.0, 17.0;
  c.accel.model.upper << 1.0 / 1640.0, 3e-6, -2e-6, 0.0, 1.0 / 1660.0, 4e-6, 0.0, 0.0, 1.0 / 1650.0;
  c.accel.model.rotation = SmallRotation(0.004, -0.003, 0.002);
  c.gyro.estimated = true;
  c.gyro.model.bias << 12.0, -7.0, 3.0;
  c.gyro.model.matrix << 1.0 / 131.0, 2e-5, -1e-5, -3e-5, 1.0 / 132.0, 1e-5, 2e-5, -2e-5,
      1.0 / 130.0;
  c.gyro.model.matrix *= 3.14159265358979 / 180.0;
  AddEffect(Effect::kGyroGSensitivity, {0.02, -0.01, 0.005, 0.01, 0.03, -0.02, 0.0, 0.01, -0.015},
            &c);
  if (temperature_and_drift) {
    AddEffect(Effect::kAccelTemperatureBias, {0.002, -0.003, 0.004}, &c);
    AddEffect(Effect::kAccelTemperatureScale, {1e-4, -2e-4, 5e-5}, &c);
    AddEffect(Effect::kAccelBiasDrift, {1e-5, -2e-5, 3e-5}, &c);
    AddEffect(Effect::kAccelQuadratic, {1e-4, -2e-4, 1.5e-4}, &c);
    AddEffect(Effect::kGyroTemperatureBias, {0.05, -0.04, 0.03}, &c);
    AddEffect(Effect::kGyroBiasDrift, {1e-3, -2e-3, 5e-4}, &c);
  }
  c.effects.reference_temperature = temperature_and_drift ? 31.5 : NAN;
  c.effects.reference_time = 120.0;
  c.gravity = 9.80665;
  // Static positions: twelve directions, raw means from the inverse of the
  // linear model (the effects make |a| differ from g: that is the point).
  for (int k = 0; k < 12; ++k) {
    PositionReport p;
    const double angle = 0.5 * k;
    const Eigen::Vector3d up(std::cos(angle) * std::sin(1.0 + 0.1 * k),
                             std::sin(angle) * std::sin(1.0 + 0.1 * k), std::cos(1.0 + 0.1 * k));
    p.position.raw_mean = c.accel.model.Invert(9.80665 * up);
    p.position.t_begin = 10.0 * k;
    p.position.t_end = 10.0 * k + 8.0;
    p.position.sample_count = 800;
    p.position.temperature = temperature_and_drift ? 25.0 + k : NAN;
    c.positions.push_back(p);
  }
  c.provenance = {"session.csv", "0123456789abcdef0123456789abcdef", "0.2.0"};
  c.success = true;
  c.message = "test";
  return c;
}

std::string WriteCalibration(const ScratchDir& scratch, const Calibration& c,
                             const std::string& name = "calib.json") {
  return scratch.Write(name, CalibrationToJson(c, false));
}

// A raw log in counts: t, accel, gyro, temp (or not).
std::string RawLog(size_t n, bool temperature, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> accel(0.0, 1200.0), gyro(0.0, 300.0);
  std::ostringstream s;
  s.precision(17);
  s << "t,ax,ay,az,gx,gy,gz" << (temperature ? ",temp" : "") << "\n";
  for (size_t i = 0; i < n; ++i) {
    s << 0.01 * i + 100.0 << "," << accel(rng) << "," << accel(rng) << "," << accel(rng) + 1600.0
      << "," << gyro(rng) << "," << gyro(rng) << "," << gyro(rng);
    if (temperature) s << "," << 20.0 + 0.001 * i;
    s << "\n";
  }
  return s.str();
}

ImuLog ReadLog(const std::string& path) {
  ImuLog log;
  std::string error;
  EXPECT_TRUE(ReadImuLog(path, LogReaderOptions(), &log, &error)) << error;
  return log;
}

double Relative(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

// --- apply ---------------------------------------------------------------

TEST(Apply, AppliesEveryTermOfTheCorrector) {
  const ScratchDir scratch;
  const Calibration c = FullCalibration(true);
  const std::string calib = WriteCalibration(scratch, c);
  const std::string raw = scratch.Write("raw.csv", RawLog(500, true, 1));
  const testing_util::CliResult r = RunCli(
      "apply --calibration " + calib + " --input " + raw + " --output " + (scratch / "out.csv"),
      scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const ImuLog in = ReadLog(raw), out = ReadLog(scratch / "out.csv");
  ASSERT_EQ(out.size(), in.size());
  // The same numbers, term by term, from the Calibration struct (not the
  // reader): R h^-1(U (v - b)), then M_g (u - b_g - G R^T a - gamma dT - eta dt).
  const EffectCalibration& e = c.effects;
  auto values = [&](Effect effect) {
    for (const EffectEstimate& x : e.estimates) {
      if (x.effect == effect) return x.values;
    }
    return std::vector<double>();
  };
  double worst_accel = 0.0, worst_gyro = 0.0;
  for (size_t i = 0; i < in.size(); ++i) {
    const double dT = in.temperature[i] - e.reference_temperature;
    const double dt = in.t[i] - e.reference_time;
    Eigen::Vector3d m = c.accel.model.upper * (in.accel[i] - c.accel.model.bias);
    for (int k = 0; k < 3; ++k) {
      m(k) -=
          values(Effect::kAccelTemperatureBias)[k] * dT + values(Effect::kAccelBiasDrift)[k] * dt;
      m(k) /= 1.0 + values(Effect::kAccelTemperatureScale)[k] * dT;
      const double k2 = values(Effect::kAccelQuadratic)[k];
      m(k) = (-1.0 + std::sqrt(1.0 + 4.0 * k2 * m(k))) / (2.0 * k2);
    }
    const Eigen::Vector3d a = c.accel.model.rotation * m;
    Eigen::Matrix3d g;
    const std::vector<double> gv = values(Effect::kGyroGSensitivity);
    for (int k = 0; k < 9; ++k) g(k / 3, k % 3) = gv[k];
    Eigen::Vector3d u = in.gyro[i] - c.gyro.model.bias - g * (m);
    for (int k = 0; k < 3; ++k) {
      u(k) -= values(Effect::kGyroTemperatureBias)[k] * dT + values(Effect::kGyroBiasDrift)[k] * dt;
    }
    const Eigen::Vector3d w = c.gyro.model.matrix * u;
    worst_accel = std::max(worst_accel, Relative(out.accel[i], a));
    worst_gyro = std::max(worst_gyro, Relative(out.gyro[i], w));
    ASSERT_EQ(out.t[i], in.t[i]);
    ASSERT_EQ(out.temperature[i], in.temperature[i]);
  }
  EXPECT_LT(worst_accel, 1e-9);
  EXPECT_LT(worst_gyro, 1e-9);
  // The header names the units.
  EXPECT_NE(Slurp(scratch / "out.csv").find("m/s^2"), std::string::npos);
}

TEST(Apply, StandardInputAndOutput) {
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch, FullCalibration(true));
  const std::string raw = scratch.Write("raw.csv", RawLog(200, true, 2));
  const std::string file_out = scratch / "file.csv";
  ASSERT_EQ(
      RunCli("apply --calibration " + calib + " --input " + raw + " --output " + file_out, scratch)
          .exit_code,
      0);
  const std::string cmd = "cat " + raw + " | " + GRAVCAL_CLI_PATH + " apply --calibration " +
                          calib + " --input - --output - > " + (scratch / "piped.csv");
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_EQ(Slurp(scratch / "piped.csv"), Slurp(file_out));
}

TEST(Apply, TemperatureCalibrationOnALogWithoutTemperatureFailsByName) {
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch, FullCalibration(true));
  const std::string raw = scratch.Write("raw.csv", RawLog(50, false, 3));
  const std::string out = scratch / "out.csv";
  testing_util::CliResult r =
      RunCli("apply --calibration " + calib + " --input " + raw + " --output " + out, scratch);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("'temp'"), std::string::npos) << r.err;
  EXPECT_FALSE(testing_util::FileExists(out));
  // Standard output: nothing written.
  r = RunCli("apply --calibration " + calib + " --input " + raw + " --output -", scratch);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_TRUE(r.out.empty()) << r.out.substr(0, 200);
}

TEST(Apply, BadRowLeavesNoOutputFile) {
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch, FullCalibration(true));
  std::string log = RawLog(100, true, 4);
  log += "7.0,1,2,abc,4,5,6,20\n";
  const std::string raw = scratch.Write("raw.csv", log);
  const std::string out = scratch / "out.csv";
  const testing_util::CliResult r =
      RunCli("apply --calibration " + calib + " --input " + raw + " --output " + out, scratch);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("raw.csv:102: column 'az': 'abc' is not a number"), std::string::npos)
      << r.err;
  EXPECT_FALSE(testing_util::FileExists(out));
}

// apply corrects and formats blocks of 8192 rows on worker threads: a log
// of several blocks comes out as the library's one-thread loop writes it,
// byte for byte, and a row that fails in a later block is named by its line
// with no file left.
TEST(Apply, RowsCorrectedOnWorkerThreadsAreTheOneThreadBytes) {
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch, FullCalibration(true));
  std::string text = RawLog(30000, true, 5);
  const std::string raw = scratch.Write("raw.csv", text);
  const std::string out = scratch / "out.csv";
  const testing_util::CliResult r =
      RunCli("apply --calibration " + calib + " --input " + raw + " --output " + out, scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;

  LoadedCalibration loaded;
  std::string error;
  ASSERT_TRUE(ReadCalibrationJson(calib, &loaded, &error)) << error;
  ImuCsvStreamReader reader;
  ImuCsvStreamWriter writer;
  ASSERT_TRUE(reader.Open(raw, &error)) << error;
  ASSERT_TRUE(writer.Open(scratch / "one_thread.csv", true, true, {}, &error)) << error;
  ThermalElementRate rate(loaded.corrector.thermal.lag_time_constant);
  ImuSample s;
  while (reader.Next(&s, &error)) {
    bool clamped = false;
    ASSERT_TRUE(loaded.corrector.CorrectRow(s.temperature, rate.Add(s.t, s.temperature), s.t,
                                            &s.accel, &s.gyro, &clamped));
    ASSERT_TRUE(writer.Write(s, &error)) << error;
  }
  ASSERT_EQ(error, "");
  ASSERT_TRUE(writer.Commit(&error)) << error;
  const std::string got = Slurp(out), want = Slurp(scratch / "one_thread.csv");
  const size_t header = got.find("\nt,ax,ay,az,gx,gy,gz,temp\n");
  ASSERT_NE(header, std::string::npos);
  EXPECT_TRUE(got.substr(header + 1) == want) << "the rows differ from the one-thread loop's";
  EXPECT_EQ(std::count(got.begin() + header + 1, got.end(), '\n'), 30001);

  // A reading of 1e300 counts at row 25000 (line 25002, the fourth block)
  // through a scale of 1e100 overflows.
  size_t at = 0;
  for (int line = 1; line < 25002; ++line) at = text.find('\n', at) + 1;
  text.replace(at, text.find(',', text.find(',', at) + 1) - at,
               text.substr(at, text.find(',', at) - at) + ",1e300");
  Calibration huge = FullCalibration(false);
  huge.accel.model.upper *= 1e100;
  const std::string huge_calib = WriteCalibration(scratch, huge, "huge.json");
  const std::string bad = scratch.Write("bad.csv", text);
  const std::string bad_out = scratch / "bad_out.csv";
  const testing_util::CliResult f = RunCli(
      "apply --calibration " + huge_calib + " --input " + bad + " --output " + bad_out, scratch);
  EXPECT_EQ(f.exit_code, 1);
  EXPECT_NE(f.err.find("gravcal: error: " + bad +
                       ":25002: the corrected sample is not finite (the reading times the "
                       "calibration overflows)"),
            std::string::npos)
      << f.err;
  EXPECT_FALSE(testing_util::FileExists(bad_out));
}

// A log larger than the address space the process may use goes through:
// generated on the fly into standard input, counted at the other end.
TEST(Apply, StreamsALogLargerThanItsMemoryLimit) {
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch, FullCalibration(true));
  // 4 million rows of about 72 bytes: ~290 MB through a process limited to
  // 250 MB of address space (ulimit -v), libraries included.
  const std::string script = scratch.Write(
      "stream.sh",
      "set -o pipefail\n"
      "awk 'BEGIN { print \"t,ax,ay,az,gx,gy,gz,temp\"; for (i = 0; i < 4000000; i++) "
      "printf \"%.6f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.5f\\n\", 100 + i * 0.01, 100 + i % 977, "
      "-200 + i % 613, 1600 + i % 331, 12 + i % 17, -7 + i % 13, 3 + i % 11, 20 + i * 1e-6 }' "
      "| tee >(wc -c > " +
          (scratch / "bytes.txt") +
          ") "
          "| (ulimit -v 250000; exec " +
          GRAVCAL_CLI_PATH + " apply --calibration " + calib + " --input - --output -) | wc -l > " +
          (scratch / "rows.txt") + "\n");
  ASSERT_EQ(std::system(("bash " + script).c_str()), 0);
  EXPECT_GT(std::stod(Slurp(scratch / "bytes.txt")), 250000.0 * 1024.0);
  // Two comment lines, the header, every row.
  EXPECT_EQ(std::stol(Slurp(scratch / "rows.txt")), 4000000 + 3);
}

// --- the calibration file ------------------------------------------------

TEST(CalibrationFile, RoundTripsTheCorrectorPositionsAndProvenance) {
  const Calibration c = FullCalibration(true);
  LoadedCalibration loaded;
  std::string error;
  ASSERT_TRUE(CalibrationFromJson(CalibrationToJson(c, false), "calib.json", &loaded, &error))
      << error;
  EXPECT_EQ(loaded.provenance.log_file, "session.csv");
  EXPECT_EQ(loaded.provenance.log_hash, "0123456789abcdef0123456789abcdef");
  ASSERT_EQ(loaded.positions.size(), 12u);
  EXPECT_EQ(loaded.positions[3].temperature, 28.0);
  EXPECT_EQ(loaded.positions[3].time, 34.0);
  EXPECT_EQ(loaded.corrector.active_effects.size(), 7u);
  EXPECT_TRUE(loaded.corrector.RequiresTemperature());
  EXPECT_TRUE(loaded.corrector.RequiresTime());
}

TEST(CalibrationFile, OlderFilesWithoutProvenanceAreRead) {
  nlohmann::json j = nlohmann::json::parse(CalibrationToJson(FullCalibration(false), false));
  j.erase("provenance");
  for (auto& p : j["positions"]) p.erase("temperature");
  LoadedCalibration loaded;
  std::string error;
  ASSERT_TRUE(CalibrationFromJson(j.dump(), "old.json", &loaded, &error)) << error;
  EXPECT_TRUE(loaded.provenance.log_file.empty());
}

TEST(CalibrationFile, MissingOrMalformedFieldIsNamedOnOneLine) {
  const std::string text = CalibrationToJson(FullCalibration(true), false);
  struct Case {
    const char* pointer;
    nlohmann::json value;  // null = remove
    const char* key;
  };
  const std::vector<Case> cases = {
      {"/accel/bias", nullptr, "accel.bias"},
      {"/accel/matrix", "x", "accel.matrix"},
      {"/gyro/matrix", nlohmann::json::array({1, 2, 3}), "gyro.matrix"},
      {"/effects/accel_temperature_bias/value", nlohmann::json::array({1, 2}),
       "effects.accel_temperature_bias.value"},
      {"/effects/reference_time", nullptr, "effects.reference_time"},
      {"/positions/2/raw_mean", "y", "positions[2].raw_mean"},
      {"/gravity/value", "9.8", "gravity.value"},
      {"/provenance/log_hash", 12, "provenance.log_hash"},
  };
  for (const Case& k : cases) {
    nlohmann::json j = nlohmann::json::parse(text);
    const nlohmann::json::json_pointer pointer(k.pointer);
    if (k.value.is_null()) {
      j[pointer.parent_pointer()].erase(pointer.back());
    } else {
      j[pointer] = k.value;
    }
    LoadedCalibration loaded;
    std::string error;
    EXPECT_FALSE(CalibrationFromJson(j.dump(), "c.json", &loaded, &error)) << k.pointer;
    EXPECT_NE(error.find(std::string("c.json: key '") + k.key + "'"), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

// --- exporters -----------------------------------------------------------

ImuNoiseModel Noise() {
  ImuNoiseModel n;
  n.rate_hz = 200.0;
  for (int i = 0; i < 3; ++i) {
    n.accel[i].white_noise.value = 1e-3 * (1 + i);
    n.accel[i].random_walk.value = 2e-4 * (3 - i);
    n.gyro[i].white_noise.value = 1e-4 * (2 + i);
    n.gyro[i].random_walk.value = 3e-6 * (1 + i);
  }
  return n;
}

Eigen::Matrix3d YamlMatrix3(const YAML::Node& node) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = node[r][c].as<double>();
  }
  return m;
}

Eigen::Vector3d YamlVector3(const YAML::Node& node) {
  return Eigen::Vector3d(node[0].as<double>(), node[1].as<double>(), node[2].as<double>());
}

LoadedCalibration Loaded(const Calibration& c) {
  LoadedCalibration loaded;
  std::string error;
  EXPECT_TRUE(CalibrationFromJson(CalibrationToJson(c, false), "calib.json", &loaded, &error))
      << error;
  return loaded;
}

std::vector<ImuSample> Samples(size_t n) {
  std::vector<ImuSample> samples;
  std::mt19937_64 rng(9);
  std::normal_distribution<double> accel(0.0, 1200.0), gyro(0.0, 300.0);
  for (size_t i = 0; i < n; ++i) {
    ImuSample s;
    s.t = i;
    s.accel = internal::DrawVector3([&] { return accel(rng); });
    s.gyro = internal::DrawVector3([&] { return gyro(rng); });
    samples.push_back(s);
  }
  return samples;
}

// The text of a single-file export, with the test's noise model.
std::string ExportedText(const LoadedCalibration& c, ExportTarget target, ExportResult* result) {
  const ImuNoiseModel noise = Noise();
  ExportOptions options;
  options.target = target;
  options.noise = &noise;
  std::string error;
  EXPECT_TRUE(ExportCalibration(c, options, result, &error)) << error;
  return result->files.empty() ? std::string() : result->files[0].text;
}

TEST(Export, KalibrEquationReproducesApply) {
  const LoadedCalibration c = Loaded(FullCalibration(false));
  ExportResult result;
  const std::string text = ExportedText(c, ExportTarget::kKalibr, &result);
  EXPECT_TRUE(result.dropped.empty());
  const YAML::Node y = YAML::Load(text);
  // Kalibr: raw = M_a C_i_b a_b + b_a; raw_g = M_g C_gyro_i w_i + A C_gyro_i a_i + b_g.
  const Eigen::Matrix3d m_a = YamlMatrix3(y["accelerometers"]["M"]);
  const Eigen::Matrix3d m_g = YamlMatrix3(y["gyroscopes"]["M"]);
  const Eigen::Matrix3d a_g = YamlMatrix3(y["gyroscopes"]["A"]);
  const Eigen::Matrix3d c_gyro_i = YamlMatrix3(y["gyroscopes"]["C_gyro_i"]);
  Eigen::Matrix3d c_i_b;
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) c_i_b(r, k) = y["T_i_b"][r][k].as<double>();
  }
  EXPECT_EQ(m_a(0, 1), 0.0);
  EXPECT_EQ(m_a(0, 2), 0.0);
  EXPECT_EQ(m_a(1, 2), 0.0);
  EXPECT_EQ(m_g(0, 1), 0.0);
  const Eigen::Vector3d b_a = YamlVector3(y["accelerometers"]["gravcal_bias"]);
  const Eigen::Vector3d b_g = YamlVector3(y["gyroscopes"]["gravcal_bias"]);
  double worst = 0.0;
  for (const ImuSample& s : Samples(200)) {
    Eigen::Vector3d a;
    ASSERT_TRUE(c.corrector.CorrectAccel(s.accel, NAN, s.t, &a));
    const Eigen::Vector3d w = c.corrector.CorrectGyro(s.gyro, a, NAN, s.t);
    const Eigen::Vector3d a_b = c_i_b.transpose() * m_a.inverse() * (s.accel - b_a);
    const Eigen::Vector3d a_i = c_i_b * a_b;
    const Eigen::Vector3d w_i =
        c_gyro_i.transpose() * m_g.inverse() * (s.gyro - b_g - a_g * c_gyro_i * a_i);
    worst = std::max({worst, Relative(a_b, a), Relative(c_i_b.transpose() * w_i, w)});
  }
  EXPECT_LT(worst, 1e-12);
  // Noise: the axis maxima, in Kalibr's units, exactly.
  EXPECT_NEAR(y["accelerometer_noise_density"].as<double>(), 3e-3, 1e-15);
  EXPECT_NEAR(y["accelerometer_random_walk"].as<double>(), 6e-4, 1e-15);
  EXPECT_NEAR(y["gyroscope_noise_density"].as<double>(), 4e-4, 1e-15);
  EXPECT_NEAR(y["gyroscope_random_walk"].as<double>(), 9e-6, 1e-15);
  EXPECT_EQ(y["update_rate"].as<double>(), 200.0);
}

TEST(Export, OpenVinsRpngEquationReproducesApply) {
  const LoadedCalibration c = Loaded(FullCalibration(false));
  ExportResult result;
  const std::string text = ExportedText(c, ExportTarget::kOpenVins, &result);
  // OpenCV's "%YAML:1.0" first line is not a YAML directive yaml-cpp takes.
  ASSERT_EQ(text.rfind("%YAML:1.0\n", 0), 0u);
  const YAML::Node y = YAML::Load(text.substr(10))["imu0"];
  EXPECT_EQ(y["model"].as<std::string>(), "rpng");
  // ov_msckf: Da = Ta^-1, Dw = Tw^-1, R_ACCtoIMU = R_IMUtoACC^T,
  // a = R_ACCtoIMU Da (a_m - b_a), w = R_GYROtoIMU Dw (w_m - b_g - Tg a).
  const Eigen::Matrix3d da = YamlMatrix3(y["Ta"]).inverse();
  const Eigen::Matrix3d dw = YamlMatrix3(y["Tw"]).inverse();
  const Eigen::Matrix3d r_acc = YamlMatrix3(y["R_IMUtoACC"]).transpose();
  const Eigen::Matrix3d r_gyro = YamlMatrix3(y["R_IMUtoGYRO"]).transpose();
  const Eigen::Matrix3d tg = YamlMatrix3(y["Tg"]);
  // rpng reads the upper triangle only.
  EXPECT_NEAR(da(1, 0), 0.0, 1e-18);
  EXPECT_NEAR(dw(2, 1), 0.0, 1e-18);
  const Eigen::Vector3d b_a = YamlVector3(y["gravcal_accel_bias"]);
  const Eigen::Vector3d b_g = YamlVector3(y["gravcal_gyro_bias"]);
  double worst = 0.0;
  for (const ImuSample& s : Samples(200)) {
    Eigen::Vector3d a;
    ASSERT_TRUE(c.corrector.CorrectAccel(s.accel, NAN, s.t, &a));
    const Eigen::Vector3d w = c.corrector.CorrectGyro(s.gyro, a, NAN, s.t);
    const Eigen::Vector3d a_ov = r_acc * da * (s.accel - b_a);
    const Eigen::Vector3d w_ov = r_gyro * dw * (s.gyro - b_g - tg * a_ov);
    worst = std::max({worst, Relative(a_ov, a), Relative(w_ov, w)});
  }
  EXPECT_LT(worst, 1e-12);
  EXPECT_NEAR(y["gyroscope_noise_density"].as<double>(), 4e-4, 1e-15);
  EXPECT_EQ(y["update_rate"].as<double>(), 200.0);
}

TEST(Export, RosCovariancesAreDiscreteTimeVariances) {
  const LoadedCalibration c = Loaded(FullCalibration(false));
  ExportResult result;
  const std::string text = ExportedText(c, ExportTarget::kRos, &result);
  const YAML::Node y = YAML::Load(text)["imu_covariance"];
  // sigma^2 = N^2 f, (m/s^2)^2 and (rad/s)^2.
  EXPECT_NEAR(y["linear_acceleration_covariance"][4].as<double>(), 2e-3 * 2e-3 * 200.0, 1e-18);
  EXPECT_NEAR(y["angular_velocity_covariance"][8].as<double>(), 4e-4 * 4e-4 * 200.0, 1e-18);
  EXPECT_EQ(y["linear_acceleration_covariance"][1].as<double>(), 0.0);
  EXPECT_EQ(y["orientation_covariance"][0].as<double>(), -1.0);
}

// An SI-unit calibration (raw in m/s^2 and rad/s), as the autopilots' drivers
// deliver, with temperature and cross-axis terms they cannot hold.
Calibration SiCalibration() {
  Calibration c = FullCalibration(true);
  c.accel.model.upper << 1.01, 0.004, -0.002, 0.0, 0.99, 0.003, 0.0, 0.0, 1.005;
  c.accel.model.bias << 0.12, -0.08, 0.21;
  c.gyro.model.matrix << 1.002, 0.001, 0.0, -0.002, 0.998, 0.001, 0.0, 0.001, 1.001;
  c.gyro.model.bias << 0.01, -0.02, 0.005;
  for (PositionReport& p : c.positions) {
    const Eigen::Vector3d up = p.position.raw_mean.normalized();
    p.position.raw_mean = c.accel.model.Invert(9.80665 * up);
  }
  return c;
}

// The number after `marker` in `text`.
double NumberAfter(const std::string& text, const std::string& marker) {
  const size_t at = text.find(marker);
  EXPECT_NE(at, std::string::npos) << marker;
  return at == std::string::npos ? NAN : std::stod(text.substr(at + marker.size()));
}

// rms over the positions of |diag(s) (v - o)| - g, with the numbers read
// from the exported file.
double DiagonalRms(const LoadedCalibration& c, const Eigen::Vector3d& offset,
                   const Eigen::Vector3d& scale) {
  double sum = 0.0;
  for (const RecordedPosition& p : c.positions) {
    const double r = scale.cwiseProduct(p.raw_mean - offset).norm() - c.gravity;
    sum += r * r;
  }
  return std::sqrt(sum / c.positions.size());
}

// Exports the SI calibration to `target` through the CLI, parses every
// non-comment line with `parse` (false = not the format), and checks the
// truncation error in the comment against a recomputation from the file's
// own offsets and scales. `names`: accelerometer offset X, Y, Z, scale X, Y, Z.
void CheckAutopilotExport(const std::string& target,
                          bool (*parse)(const std::string& line, std::string* name, double* value),
                          const std::vector<std::string>& names) {
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch, SiCalibration());
  const std::string out = scratch / "parameters.txt";
  const testing_util::CliResult r =
      RunCli("export --calibration " + calib + " --to " + target + " --output " + out, scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("drops: effect terms"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("cross-axis"), std::string::npos) << r.err;
  const std::string text = Slurp(out);
  std::map<std::string, double> params;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::string name;
    double value;
    ASSERT_TRUE(parse(line, &name, &value)) << line;
    params[name] = value;
  }
  ASSERT_EQ(params.size(), 9u);
  const Eigen::Vector3d offset(params[names[0]], params[names[1]], params[names[2]]);
  const Eigen::Vector3d scale(params[names[3]], params[names[4]], params[names[5]]);
  const LoadedCalibration c = Loaded(SiCalibration());
  const double recomputed = DiagonalRms(c, offset, scale);
  EXPECT_GT(recomputed, 1e-4);  // the dropped terms matter here
  // The comment prints 6 significant digits.
  EXPECT_NEAR(NumberAfter(text, "static positions: "), recomputed, 1e-5 * recomputed);
  const double full = PositionResidualRms(c.corrector, c.positions, c.gravity);
  EXPECT_NEAR(NumberAfter(text, "m/s^2 with what this file holds, "), full, 1e-5 * full);
}

// QGroundControl: vehicle, component, name, value, type 9 (float).
bool ParsePx4Line(const std::string& line, std::string* name, double* value) {
  std::istringstream fields(line);
  int vehicle, component, type;
  return (fields >> vehicle >> component >> *name >> *value >> type) && type == 9;
}

// .parm: NAME VALUE and nothing else.
bool ParseArduPilotLine(const std::string& line, std::string* name, double* value) {
  std::istringstream fields(line);
  std::string rest;
  return (fields >> *name >> *value) && !(fields >> rest);
}

TEST(Export, Px4FileParsesAndItsTruncationErrorIsRecomputed) {
  CheckAutopilotExport("px4", ParsePx4Line,
                       {"CAL_ACC0_XOFF", "CAL_ACC0_YOFF", "CAL_ACC0_ZOFF", "CAL_ACC0_XSCALE",
                        "CAL_ACC0_YSCALE", "CAL_ACC0_ZSCALE"});
}

TEST(Export, ArduPilotFileParsesAndItsTruncationErrorIsRecomputed) {
  CheckAutopilotExport("ardupilot", ParseArduPilotLine,
                       {"INS_ACCOFFS_X", "INS_ACCOFFS_Y", "INS_ACCOFFS_Z", "INS_ACCSCAL_X",
                        "INS_ACCSCAL_Y", "INS_ACCSCAL_Z"});
}

TEST(Export, Px4RefusesRawCounts) {
  ExportOptions options;
  options.target = ExportTarget::kPx4;
  ExportResult result;
  std::string error;
  EXPECT_FALSE(ExportCalibration(Loaded(FullCalibration(false)), options, &result, &error));
  EXPECT_NE(error.find("not m/s^2"), std::string::npos) << error;
}

// The C corrector, compiled with -std=c99 -Wall -Wextra -Werror -pedantic,
// against gravcal apply on the same log.
TEST(Export, CCorrectorEqualsApply) {
  if (std::system("gcc --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "gcc is not installed";
  const ScratchDir scratch;
  const std::string calib = WriteCalibration(scratch, FullCalibration(true));
  const std::string raw = scratch.Write("raw.csv", RawLog(2000, true, 5));
  testing_util::CliResult r =
      RunCli("export --calibration " + calib + " --to c --output-dir " + (scratch / "c"), scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = RunCli(
      "apply --calibration " + calib + " --input " + raw + " --output " + (scratch / "applied.csv"),
      scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The raw rows without the header.
  std::vector<testing_util::CCorrectedRow> c_rows;
  std::string error;
  ASSERT_TRUE(
      testing_util::RunCCorrector(scratch / "c", "tail -n +2 " + raw, ",", false, &c_rows, &error))
      << error;
  const ImuLog applied = ReadLog(scratch / "applied.csv");
  double worst_double = 0.0, worst_float = 0.0;
  testing_util::WorstRelative(c_rows, applied, &worst_double, &worst_float);
  const size_t n = c_rows.size();
  EXPECT_EQ(n, applied.size());
  EXPECT_LT(worst_double, 1e-9);
  EXPECT_LT(worst_float, 1e-5);
  std::printf("C corrector vs apply over %zu samples: double %.3g, float %.3g (largest relative)\n",
              n, worst_double, worst_float);
}

// Issue 32: the C corrector compiles warning-free (-std=c99 -Wall -Wextra
// -Werror -pedantic), in both precisions, for every subset of the model's
// optional terms: the registry's accelerometer effects (every subset, each
// once with and once without a gyroscope) and its gyroscope effects (every
// subset, beside the accelerometer subsets in turn); the accelerometer's and
// the gyroscope's functions read only their own terms. Temperature and
// drift terms bring the reference temperature and time. Compiled by gcc and
// by clang (when installed) with -fsyntax-only, one compiler run each.
TEST(Export, CCorrectorCompilesWithoutWarningsForEveryModelSubset) {
  std::vector<Effect> accel_effects, gyro_effects;
  for (const EffectInfo& info : EffectCatalogue()) {
    if (info.form == EffectForm::kInUpper) continue;
    (info.sensor == EffectSensor::kGyroscope ? gyro_effects : accel_effects).push_back(info.effect);
  }
  Calibration full = FullCalibration(true);
  // Every effect on (the catalogue's values 1e-5 .. for those FullCalibration
  // does not set).
  for (const EffectInfo& info : EffectCatalogue()) {
    if (info.form == EffectForm::kInUpper) continue;
    const bool set = std::any_of(full.effects.estimates.begin(), full.effects.estimates.end(),
                                 [&](const EffectEstimate& e) { return e.effect == info.effect; });
    if (!set) AddEffect(info.effect, std::vector<double>(info.num_parameters, 1e-5), &full);
  }
  const int accel_subsets = 1 << accel_effects.size(), gyro_subsets = 1 << gyro_effects.size();
  const ScratchDir scratch;
  int models = 0;
  for (int gyro = 0; gyro < 2; ++gyro) {
    for (int k = 0; k < std::max(accel_subsets, gyro ? gyro_subsets : 1); ++k) {
      const int accel_mask = k % accel_subsets, gyro_mask = gyro ? k % gyro_subsets : 0;
      {
        Calibration c = full;
        c.gyro.estimated = gyro == 1;
        if (!gyro) c.gyro = Calibration().gyro;
        c.effects.estimates.clear();
        const std::string name =
            (gyro ? "g_" : "a_") + std::to_string(accel_mask) + "_" + std::to_string(gyro_mask);
        for (const EffectEstimate& e : full.effects.estimates) {
          bool keep = false;
          for (size_t b = 0; b < accel_effects.size(); ++b) {
            keep |= (accel_mask >> b & 1) && e.effect == accel_effects[b];
          }
          for (size_t b = 0; b < gyro_effects.size(); ++b) {
            keep |= (gyro_mask >> b & 1) && e.effect == gyro_effects[b];
          }
          if (keep) c.effects.estimates.push_back(e);
        }
        // Without a temperature term the log may have had no temperature
        // column: the reference is NaN, as calibrate writes it.
        bool temperature = false;
        for (const EffectEstimate& e : c.effects.estimates) {
          temperature |= Info(e.effect).regressor == EffectRegressor::kTemperature;
        }
        if (!temperature) c.effects.reference_temperature = NAN;
        ExportOptions options;
        options.target = ExportTarget::kC;
        ExportResult result;
        std::string error;
        ASSERT_TRUE(ExportCalibration(Loaded(c), options, &result, &error))
            << name << ": " << error;
        ASSERT_EQ(result.files.size(), 2u) << name;
        EXPECT_TRUE(result.dropped.empty()) << name << ": " << result.dropped.front();
        std::filesystem::create_directories(scratch / ("models/" + name));
        for (const ExportedFile& f : result.files) {
          scratch.Write("models/" + name + "/" + f.name, f.text);
        }
        ++models;
      }
    }
  }
  EXPECT_EQ(models, accel_subsets + std::max(accel_subsets, gyro_subsets));
  int compilers = 0;
  for (const char* compiler : {"gcc", "clang"}) {
    if (std::system((std::string(compiler) + " --version > /dev/null 2>&1").c_str()) != 0) {
      std::printf("%s is not installed: not compiled with it\n", compiler);
      continue;
    }
    ++compilers;
    // Every model in one compiler run (each file is its own translation
    // unit; the messages name the model's folder).
    const std::string log = scratch / (std::string(compiler) + ".txt");
    const std::string run = std::string("cd ") + (scratch / "models") + " && " + compiler +
                            " -std=c99 -Wall -Wextra -Werror -pedantic -fsyntax-only */*.c > " +
                            log + " 2>&1";
    EXPECT_EQ(std::system(run.c_str()), 0) << compiler << ":\n" << Slurp(log);
  }
  if (compilers == 0) GTEST_SKIP() << "neither gcc nor clang is installed";
}

}  // namespace
}  // namespace gravcal
