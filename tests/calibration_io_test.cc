// The calibration JSON read back and `apply`, end to end for the output of
// every method: what ReadCalibrationJson returns is the model the file holds
// (not transposed, bias kept, gyroscope when there is one), and every column
// `apply` writes is that model applied to the raw log.
#include "gravcal/io/calibration_io.h"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
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

// --- Issue 32: calibrations checked on load -----------------------------

// A consistent calibration: M = R U with a small rotation, a gyroscope.
json GoodCalibration() {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(0.01, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  Eigen::Matrix3d upper;
  upper << 6.0e-4, 2e-7, -1e-7, 0.0, 5.9e-4, 3e-7, 0.0, 0.0, 6.1e-4;
  auto matrix = [](const Eigen::Matrix3d& m) {
    json rows = json::array();
    for (int r = 0; r < 3; ++r) rows.push_back({m(r, 0), m(r, 1), m(r, 2)});
    return rows;
  };
  json j;
  j["method"] = "twelve_position";
  j["accel"] = {{"model", "affine"},
                {"bias", {10.0, -20.0, 5.0}},
                {"matrix", matrix(rotation * upper)},
                {"upper", matrix(upper)},
                {"rotation", matrix(rotation)}};
  j["gyro"] = {{"bias", {1.0, 2.0, 3.0}}, {"matrix", matrix(1.3e-4 * Eigen::Matrix3d::Identity())}};
  j["gravity"] = {{"value", 9.81}};
  return j;
}

// The error CalibrationFromJson gives for `j` ("" when it loads).
std::string LoadError(const json& j, LoadedCalibration* loaded = nullptr) {
  LoadedCalibration scratch;
  std::string error;
  const bool ok = CalibrationFromJson(j.dump(), "c.json", loaded ? loaded : &scratch, &error);
  EXPECT_EQ(ok, error.empty()) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  return ok ? std::string() : error;
}

json Diagonal(double a, double b, double c) {
  return json::array(
      {json::array({a, 0.0, 0.0}), json::array({0.0, b, 0.0}), json::array({0.0, 0.0, c})});
}

TEST(CalibrationChecksOnLoad, AConsistentCalibrationLoadsAsWritten) {
  LoadedCalibration loaded;
  ASSERT_EQ(LoadError(GoodCalibration(), &loaded), "");
  const json j = GoodCalibration();
  EXPECT_LT((loaded.corrector.accel.matrix() - JsonMatrix(j["accel"]["matrix"])).norm(),
            1e-15 * JsonMatrix(j["accel"]["matrix"]).norm());
  std::string error;
  EXPECT_TRUE(CheckCalibrationModels(loaded, "c.json", &error)) << error;
}

// Today's main rebuilt the model from upper and rotation and ignored an edited
// matrix: apply and every export gave the unedited output.
TEST(CalibrationChecksOnLoad, AnEditedMatrixIsRefusedNamingBothKeys) {
  for (double factor : {1.01, 1.0 + 1e-6, -1.0}) {
    json j = GoodCalibration();
    j["accel"]["matrix"][1][1] = j["accel"]["matrix"][1][1].get<double>() * factor;
    const std::string error = LoadError(j);
    EXPECT_NE(error.find("c.json: key 'accel.matrix'"), std::string::npos) << error;
    EXPECT_NE(error.find("'accel.rotation'"), std::string::npos) << error;
    EXPECT_NE(error.find("'accel.upper'"), std::string::npos) << error;
  }
  // An edit below the tolerance (rounding in another writer) is accepted.
  json j = GoodCalibration();
  j["accel"]["matrix"][1][1] = j["accel"]["matrix"][1][1].get<double>() * (1.0 + 1e-13);
  EXPECT_EQ(LoadError(j), "");
  // An edited upper (matrix left) disagrees the same way.
  j = GoodCalibration();
  j["accel"]["upper"][0][1] = 1e-5;
  EXPECT_NE(LoadError(j).find("key 'accel.matrix': disagrees with key 'accel.rotation' * "
                              "'accel.upper'"),
            std::string::npos);
  // effects.accel_misalignment repeats upper's off-diagonal.
  j = GoodCalibration();
  j["effects"] = {{"reference_time", 0.0},
                  {"reference_temperature", nullptr},
                  {"accel_misalignment", {{"value", {2e-7, -1e-7, 3e-7}}}}};
  EXPECT_EQ(LoadError(j), "");
  j["effects"]["accel_misalignment"]["value"][2] = 4e-7;
  const std::string error = LoadError(j);
  EXPECT_NE(error.find("key 'effects.accel_misalignment.value'"), std::string::npos) << error;
  EXPECT_NE(error.find("'accel.upper'"), std::string::npos) << error;
}

TEST(CalibrationChecksOnLoad, ARotationThatIsNotOneIsRefused) {
  struct Case {
    json rotation;
    const char* what;
  };
  const std::vector<Case> cases = {
      {Diagonal(1.0, 1.0, -1.0), "reflection"},
      {Diagonal(0.0, 0.0, 0.0), "not a rotation"},
      {Diagonal(2.0, 2.0, 2.0), "not a rotation"},
  };
  for (const Case& k : cases) {
    json j = GoodCalibration();
    j["accel"]["rotation"] = k.rotation;
    // matrix kept consistent, so that the rotation check is what refuses.
    j["accel"]["matrix"] = j["accel"]["upper"];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) {
        j["accel"]["matrix"][r][c] =
            k.rotation[r][r].get<double>() * j["accel"]["upper"][r][c].get<double>();
      }
    }
    const std::string error = LoadError(j);
    EXPECT_NE(error.find("c.json: key 'accel.rotation'"), std::string::npos) << error;
    EXPECT_NE(error.find(k.what), std::string::npos) << error;
  }
  json j = GoodCalibration();
  j["accel"]["upper"][2][0] = 1e-4;
  EXPECT_NE(LoadError(j).find("key 'accel.upper': is not upper triangular"), std::string::npos);
}

// accel.model states a structure: scale_misalignment holds R = I (the matrix
// upper triangular), scale a diagonal matrix. A file whose matrix breaks it
// (an edit, another tool's full matrix under the wrong model name) is refused
// naming the entry and both keys; a stated gyro.model is held the same way.
TEST(CalibrationChecksOnLoad, TheMatrixHasTheStructureItsModelClaims) {
  json j = GoodCalibration();
  j["accel"]["model"] = "scale_misalignment";
  std::string error = LoadError(j);  // the small rotation puts entries below
  EXPECT_NE(error.find("c.json: key 'accel.matrix': has (1,0) = "), std::string::npos) << error;
  EXPECT_NE(error.find("below the diagonal, but key 'accel.model' is 'scale_misalignment'"),
            std::string::npos)
      << error;
  // The same without upper and rotation: matrix is authoritative.
  j["accel"].erase("upper");
  j["accel"].erase("rotation");
  EXPECT_NE(LoadError(j).find("key 'accel.model' is 'scale_misalignment'"), std::string::npos);
  // R = I and an upper-triangular matrix load; as "scale" they are refused
  // (off the diagonal), a diagonal one loads.
  j = GoodCalibration();
  j["accel"]["model"] = "scale_misalignment";
  j["accel"]["rotation"] = Diagonal(1.0, 1.0, 1.0);
  j["accel"]["matrix"] = j["accel"]["upper"];
  EXPECT_EQ(LoadError(j), "");
  j["accel"]["model"] = "scale";
  error = LoadError(j);
  EXPECT_NE(error.find("key 'accel.matrix': has (0,1) = 2e-07 off the diagonal, but key "
                       "'accel.model' is 'scale'"),
            std::string::npos)
      << error;
  j["accel"]["upper"] = j["accel"]["matrix"] = Diagonal(6e-4, 5.9e-4, 6.1e-4);
  EXPECT_EQ(LoadError(j), "");
  // gyro.model (gravcal writes none): bias = s I, scale diagonal, full any.
  j = GoodCalibration();
  for (const char* model : {"bias", "scale", "full"}) {
    j["gyro"]["model"] = model;
    EXPECT_EQ(LoadError(j), "") << model;
  }
  j["gyro"]["matrix"] = Diagonal(1.3e-4, 1.2e-4, 1.3e-4);
  j["gyro"]["model"] = "bias";
  EXPECT_NE(LoadError(j).find("key 'gyro.matrix': has unequal diagonal entries"),
            std::string::npos);
  j["gyro"]["matrix"][2][1] = 1e-6;
  j["gyro"]["model"] = "scale";
  EXPECT_NE(LoadError(j).find("key 'gyro.matrix': has (2,1) = 1e-06 off the diagonal"),
            std::string::npos);
  j["gyro"]["model"] = "full";
  EXPECT_EQ(LoadError(j), "");
  j["gyro"]["model"] = "none";
  EXPECT_NE(LoadError(j).find("key 'gyro.model'"), std::string::npos);
}

// A key set twice is refused naming it (nlohmann keeps one of the two
// silently: an edited copy of "accel" above the written one was applied).
TEST(CalibrationChecksOnLoad, AKeySetTwiceIsRefused) {
  const std::string text = GoodCalibration().dump();
  LoadedCalibration loaded;
  std::string error;
  const std::string twice =
      R"({"accel": {"bias": [0, 0, 0], "matrix": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]}, )" +
      text.substr(1);
  EXPECT_FALSE(CalibrationFromJson(twice, "c.json", &loaded, &error));
  EXPECT_EQ(error, "c.json: key 'accel' appears twice (a key may be set once)");
  std::string inner = text;
  inner.replace(inner.find("\"bias\":"), 7, R"("bias": [1, 2, 3], "bias":)");
  EXPECT_FALSE(CalibrationFromJson(inner, "c.json", &loaded, &error));
  EXPECT_NE(error.find("key 'accel.bias' appears twice"), std::string::npos) << error;
}

TEST(CalibrationChecksOnLoad, SensorMatricesAreCheckedByConditioningNotDeterminant) {
  struct Case {
    json matrix;
    const char* what;  // "" = accepted
  };
  const std::vector<Case> cases = {
      {Diagonal(0.0, 0.0, 0.0), "all zeros"},
      {Diagonal(1e308, 1e308, 1e308), "singular values"},
      {Diagonal(1e-3, 1e-3, -1e-3), "reflection"},
      {Diagonal(1e-3, 1e-3, 1e-10), "ill-conditioned"},
      {Diagonal(1.0, 1.0, 0.0), "singular"},
      // det = 1e-360 underflows to 0; the matrix is perfectly conditioned.
      {Diagonal(1e-120, 1e-120, 1e-120), ""},
      {Diagonal(1e-3, 1e-3, 1e-8), ""},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.matrix.dump());
    json j = GoodCalibration();
    j["gyro"]["matrix"] = k.matrix;
    std::string error = LoadError(j);
    if (*k.what == '\0') {
      EXPECT_EQ(error, "");
    } else {
      EXPECT_NE(error.find("c.json: key 'gyro.matrix': "), std::string::npos) << error;
      EXPECT_NE(error.find(k.what), std::string::npos) << error;
    }
    // The same for an accelerometer given by its matrix alone (older files).
    j = GoodCalibration();
    j["accel"].erase("upper");
    j["accel"].erase("rotation");
    j["accel"]["matrix"] = k.matrix;
    LoadedCalibration loaded;
    error = LoadError(j, &loaded);
    if (*k.what == '\0') {
      ASSERT_EQ(error, "");
      const Eigen::Matrix3d expected = JsonMatrix(k.matrix);
      EXPECT_LT((loaded.corrector.accel.matrix() - expected).norm(), 1e-15 * expected.norm());
      const Eigen::Vector3d raw(1.0, 2.0, 3.0);
      const Eigen::Vector3d bias = JsonVector(j["accel"]["bias"]);
      EXPECT_LT((loaded.corrector.accel.Apply(raw) - expected * (raw - bias)).norm(),
                1e-14 * (expected * (raw - bias)).norm());
    } else {
      EXPECT_NE(error.find("c.json: key 'accel.matrix': "), std::string::npos) << error;
    }
  }
}

// apply, export and the Python package read the file the same way; the CLI
// refuses before writing anything.
TEST(CalibrationChecksOnLoad, ApplyAndExportRefuseAnEditedCalibration) {
  const testing_util::ScratchDir scratch;
  json j = GoodCalibration();
  j["accel"]["matrix"][0][0] = 1e-3;
  const std::string calib = scratch.Write("edited.json", j.dump(2));
  const std::string log = scratch.Write("raw.csv", "t,ax,ay,az\n0,1,2,3\n0.01,1,2,3\n");
  const std::string out = scratch / "out.csv";
  testing_util::CliResult r = testing_util::RunCli(
      "apply --calibration " + calib + " --input " + log + " --output " + out, scratch);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(calib + ": key 'accel.matrix': disagrees with key 'accel.rotation'"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(testing_util::FileExists(out));
  r = testing_util::RunCli("export --calibration " + calib + " --to px4 --output " + out, scratch);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(calib + ": key 'accel.matrix'"), std::string::npos) << r.err;
  EXPECT_FALSE(testing_util::FileExists(out));
}

// Issue 34: a Calibration carries its model. Calibration::Model gives the
// corrector that reading the calibration's JSON gives (the effects switched
// on, their values, an undetermined parameter as 0 and named), and refuses
// parts that disagree with the key named, as reading the file does.
TEST(CalibrationModel, IsTheModelItsJsonHolds) {
  Calibration c;
  c.success = true;
  c.message = "ok";
  c.accel.model.bias = Eigen::Vector3d(10.0, -20.0, 5.0);
  c.accel.model.upper << 0.0006, 1e-6, -2e-6, 0.0, 0.00061, 3e-6, 0.0, 0.0, 0.00059;
  c.gyro.estimated = true;
  c.gyro.model.bias = Eigen::Vector3d(1.0, 2.0, 3.0);
  c.gyro.model.matrix = 1.3e-4 * Eigen::Matrix3d::Identity();
  EffectEstimate temperature;
  temperature.effect = Effect::kAccelTemperatureBias;
  temperature.names = Info(Effect::kAccelTemperatureBias).parameter_names;
  temperature.values = {1e-3, NAN, -2e-3};
  temperature.std = {1e-4, NAN, 1e-4};
  temperature.unit = Info(Effect::kAccelTemperatureBias).unit;
  EffectEstimate drift;
  drift.effect = Effect::kGyroBiasDrift;
  drift.names = Info(Effect::kGyroBiasDrift).parameter_names;
  drift.values = {1e-5, 2e-5, 3e-5};
  drift.std = {1e-6, 1e-6, 1e-6};
  drift.unit = Info(Effect::kGyroBiasDrift).unit;
  c.effects.estimates = {temperature, drift};
  c.effects.reference_temperature = 25.0;
  c.effects.reference_time = 100.0;

  ImuCorrector model;
  std::vector<std::string> undetermined;
  std::string error;
  ASSERT_TRUE(c.Model(&model, &undetermined, &error)) << error;
  LoadedCalibration read;
  ASSERT_TRUE(CalibrationFromJson(CalibrationToJson(c, true), "c.json", &read, &error)) << error;
  EXPECT_EQ(model.active_effects, read.corrector.active_effects);
  EXPECT_EQ(undetermined, read.undetermined);
  ASSERT_EQ(undetermined.size(), 1u);
  EXPECT_EQ(undetermined[0], "effects.accel_temperature_bias." + temperature.names[1]);
  EXPECT_EQ(model.accel.bias, read.corrector.accel.bias);
  EXPECT_EQ(model.gyro.matrix, read.corrector.gyro.matrix);
  EXPECT_EQ(model.effects.Vector(Effect::kAccelTemperatureBias), Eigen::Vector3d(1e-3, 0.0, -2e-3));
  EXPECT_EQ(model.effects.Vector(Effect::kAccelTemperatureBias),
            read.corrector.effects.Vector(Effect::kAccelTemperatureBias));
  EXPECT_EQ(model.effects.Vector(Effect::kGyroBiasDrift),
            read.corrector.effects.Vector(Effect::kGyroBiasDrift));
  EXPECT_EQ(model.effects.reference_temperature, 25.0);
  // Applied, the two give the same bits.
  Eigen::Vector3d a = Eigen::Vector3d(1200.0, -300.0, 16000.0), b = a;
  Eigen::Vector3d w = Eigen::Vector3d(5.0, 6.0, 7.0), u = w;
  ASSERT_TRUE(model.CorrectRow(31.0, 140.0, &a, &w));
  ASSERT_TRUE(read.corrector.CorrectRow(31.0, 140.0, &b, &u));
  EXPECT_EQ(a, b);
  EXPECT_EQ(w, u);

  // A gyroscope effect without a gyroscope model is refused by its key.
  c.gyro.estimated = false;
  EXPECT_FALSE(c.Model(&model, nullptr, &error));
  EXPECT_NE(error.find("key 'effects.gyro_bias_drift'"), std::string::npos) << error;
  // A temperature effect needs its reference temperature.
  c.gyro.estimated = true;
  c.effects.reference_temperature = NAN;
  EXPECT_FALSE(c.Model(&model, nullptr, &error));
  EXPECT_NE(error.find("effects.reference_temperature"), std::string::npos) << error;
}

}  // namespace
}  // namespace gravcal
