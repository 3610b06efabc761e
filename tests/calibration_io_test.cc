// The calibration JSON read back and `apply`, end to end for the output of
// every method: what ReadCalibrationJson returns is the model the file holds
// (not transposed, bias kept, gyroscope when there is one), and every column
// `apply` writes is that model applied to the raw log.
#include "gravcal/io/calibration_io.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "gravcal/io/log_reader.h"
#include "test_util.h"

namespace gravcal {
namespace {

using nlohmann::json;

Eigen::Vector3d JsonVector(const json& j) {
  return Eigen::Vector3d(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
}

Eigen::Matrix3d JsonMatrix(const json& j) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = j[r][c].get<double>();
  }
  return m;
}

struct MethodCase {
  std::string name;
  std::string config;
  std::string simulate_flags;
  std::string calibrate_flags;
  bool gyro = false;
};

void PrintTo(const MethodCase& m, std::ostream* os) { *os << m.name; }

std::vector<MethodCase> Methods() {
  const std::string handheld_scales =
      " --nominal_scale 0.00059855 --gyro_nominal_scale 0.000133231 --gravity 9.80665";
  return {
      {"twelve_position", "twelve_position.yaml", "", "", false},
      {"twelve_position_gyro", "twelve_position_gyro.yaml", "", " --gravity 9.80665", true},
      {"ten_position", "ten_position.yaml", "", "", false},
      {"known_attitude", "known_attitude.yaml", "", " --gravity 9.80665 --attitudes ATTITUDES",
       false},
      {"handheld_kalman", "handheld_kalman.yaml", " --sim_motion handheld", handheld_scales, true},
      {"effects", "discovery.yaml", "", " --effects [accel_temperature_bias]", false},
  };
}

class CalibrationRoundTrip : public ::testing::TestWithParam<MethodCase> {};

TEST_P(CalibrationRoundTrip, ReaderAndApplyReproduceTheWrittenModel) {
  const MethodCase& m = GetParam();
  const testing_util::ScratchDir scratch;
  const std::string config = testing_util::SourceDir() + "/configs/" + m.config;
  const std::string sim = scratch / "sim";
  testing_util::CliResult r = testing_util::RunCli(
      "simulate --config " + config + m.simulate_flags + " --seed 3 --output-dir " + sim, scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::string flags = m.calibrate_flags;
  const size_t at = flags.find("ATTITUDES");
  if (at != std::string::npos) flags.replace(at, 9, sim + "/attitudes.csv");
  const std::string calib = scratch / "calib.json";
  r = testing_util::RunCli(
      "calibrate --input " + sim + "/raw.csv --config " + config + flags + " --output " + calib,
      scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;

  // The file's numbers, read independently of the library's reader.
  const json j = json::parse(testing_util::Slurp(calib));
  const Eigen::Vector3d accel_bias = JsonVector(j["accel"]["bias"]);
  const Eigen::Matrix3d accel_matrix = JsonMatrix(j["accel"]["matrix"]);
  ASSERT_EQ(j.contains("gyro"), m.gyro);

  LoadedCalibration loaded;
  std::string error;
  ASSERT_TRUE(ReadCalibrationJson(calib, &loaded, &error)) << error;
  EXPECT_EQ(loaded.corrector.accel.bias, accel_bias);
  EXPECT_LT((loaded.corrector.accel.matrix() - accel_matrix).norm(), 1e-14 * accel_matrix.norm())
      << loaded.corrector.accel.matrix() << "\nvs the file's\n"
      << accel_matrix;
  EXPECT_EQ(loaded.gravity, j["gravity"]["value"].get<double>());
  EXPECT_EQ(loaded.corrector.has_gyro, m.gyro);
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Matrix3d gyro_matrix = Eigen::Matrix3d::Identity();
  if (m.gyro) {
    gyro_bias = JsonVector(j["gyro"]["bias"]);
    gyro_matrix = JsonMatrix(j["gyro"]["matrix"]);
    EXPECT_EQ(loaded.corrector.gyro.bias, gyro_bias);
    EXPECT_EQ(loaded.corrector.gyro.matrix, gyro_matrix);
  }

  // apply: every sample, every column, against M (raw - b) with the file's
  // M and b (the gyroscope passes through unchanged without a model).
  const std::string corrected = scratch / "corrected.csv";
  r = testing_util::RunCli(
      "apply --calibration " + calib + " --input " + sim + "/raw.csv --output " + corrected,
      scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ImuLog raw, out;
  ASSERT_TRUE(ReadImuLog(sim + "/raw.csv", LogReaderOptions(), &raw, &error)) << error;
  ASSERT_TRUE(ReadImuLog(corrected, LogReaderOptions(), &out, &error)) << error;
  ASSERT_EQ(out.size(), raw.size());
  ASSERT_EQ(out.gyro.size(), raw.gyro.size());
  ASSERT_FALSE(raw.gyro.empty());
  // The largest difference over the whole log, relative to the value.
  double worst_t = 0.0, worst_accel = 0.0, worst_gyro = 0.0;
  size_t worst_accel_at = 0, worst_gyro_at = 0;
  auto relative = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return (a - b).cwiseAbs().cwiseQuotient(a.cwiseAbs().cwiseMax(1.0)).maxCoeff();
  };
  // Issue 16: apply applies the effect terms too; the effects case has one,
  // accel_temperature_bias: a = R (U (v - b) - beta (T - T_ref)).
  Eigen::Vector3d beta = Eigen::Vector3d::Zero();
  double reference_temperature = 0.0;
  if (j.contains("effects")) {
    ASSERT_EQ(j["effects"].size(), 3u) << "the test knows accel_temperature_bias only";
    beta = JsonVector(j["effects"]["accel_temperature_bias"]["value"]);
    reference_temperature = j["effects"]["reference_temperature"].get<double>();
  }
  const Eigen::Matrix3d upper = JsonMatrix(j["accel"]["upper"]);
  const Eigen::Matrix3d rotation = JsonMatrix(j["accel"]["rotation"]);
  for (size_t i = 0; i < raw.size(); ++i) {
    worst_t = std::max(worst_t, std::abs(out.t[i] - raw.t[i]));
    const double temperature_offset =
        raw.temperature.empty() ? 0.0 : raw.temperature[i] - reference_temperature;
    const Eigen::Vector3d expected =
        j.contains("effects") ? Eigen::Vector3d(rotation * (upper * (raw.accel[i] - accel_bias) -
                                                            beta * temperature_offset))
                              : Eigen::Vector3d(accel_matrix * (raw.accel[i] - accel_bias));
    const double ea = relative(expected, out.accel[i]);
    const double eg = relative(gyro_matrix * (raw.gyro[i] - gyro_bias), out.gyro[i]);
    if (ea > worst_accel) worst_accel = ea, worst_accel_at = i;
    if (eg > worst_gyro) worst_gyro = eg, worst_gyro_at = i;
  }
  EXPECT_LT(worst_t, 1e-9);
  EXPECT_LT(worst_accel, 1e-8) << "accelerometer, sample " << worst_accel_at << ": "
                               << out.accel[worst_accel_at].transpose();
  EXPECT_LT(worst_gyro, 1e-8) << "gyroscope, sample " << worst_gyro_at << ": "
                              << out.gyro[worst_gyro_at].transpose();
}

INSTANTIATE_TEST_SUITE_P(EveryMethod, CalibrationRoundTrip, ::testing::ValuesIn(Methods()),
                         [](const ::testing::TestParamInfo<MethodCase>& info) {
                           return info.param.name;
                         });

// Found by fuzz/fuzz_calibration_json (kept in fuzz/regressions/): a number
// beyond double made nlohmann throw out_of_range, which nothing caught, so
// `gravcal apply` aborted. Now it is an error naming the file.
TEST(CalibrationJsonReader, ANumberBeyondDoubleIsAnErrorNotACrash) {
  testing_util::ScratchDir dir;
  const std::string path =
      dir.Write("huge.json", "{\"accel\": {\"bias\": [4.01e5685773387834, 0, 0]}}");
  LoadedCalibration loaded;
  std::string error;
  EXPECT_FALSE(ReadCalibrationJson(path, &loaded, &error));
  EXPECT_NE(error.find(path + ": not valid JSON"), std::string::npos) << error;
  EXPECT_NE(error.find("number overflow"), std::string::npos) << error;
  const std::string regression =
      testing_util::SourceDir() + "/fuzz/regressions/calibration_json/number_overflow.json";
  error.clear();
  EXPECT_FALSE(ReadCalibrationJson(regression, &loaded, &error));
  EXPECT_FALSE(error.empty());
}

}  // namespace
}  // namespace gravcal
