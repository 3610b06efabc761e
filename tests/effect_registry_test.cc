// Issue 34: an effect is defined once (its file in core/effects/) and
// registered by one line (core/effect_registry.h); every consumer derives
// from the definition. The registry's layout, then one effect added that
// way (accel_temperature_bias_quadratic) followed through the simulator,
// the fit, the calibration JSON, the corrector, the generated C corrector
// and discovery, none of which names it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include "c_corrector_check.h"
#include "cli_runner.h"
#include "gravcal/core/imu_corrector.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/io/calibration_export.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/calibration_models.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/discovery.h"
#include "gravcal/workflows/pipeline.h"
#include "simulation/simulator_fields.h"
#include "test_util.h"

namespace gravcal {
namespace {

// Every effect: its name parses back, its values live in a slice of their
// own of one block, a wrong count is refused, and its simulation key (when
// it has one) is a row of the simulator's table.
TEST(EffectRegistry, EveryEffectHasItsOwnNamedSlice) {
  std::vector<int> used(kAccelEffectParameters + kGyroEffectParameters, 0);
  EXPECT_EQ(static_cast<int>(EffectCatalogue().size()), kNumEffects);
  for (const EffectInfo& info : EffectCatalogue()) {
    SCOPED_TRACE(info.name);
    Effect parsed;
    ASSERT_TRUE(FromString(info.name, &parsed));
    EXPECT_EQ(parsed, info.effect);
    EXPECT_EQ(&Info(info.effect), &info);
    ASSERT_EQ(info.parameter_names.size(), static_cast<size_t>(info.num_parameters));
    std::vector<double> values(info.num_parameters);
    std::iota(values.begin(), values.end(), 1.0);
    EffectParameters p;
    ASSERT_TRUE(p.SetValues(info.effect, values));
    if (info.form == EffectForm::kInUpper) {
      EXPECT_TRUE(p.Values(info.effect).empty());
      continue;
    }
    EXPECT_EQ(p.Values(info.effect), values);
    EXPECT_FALSE(p.SetValues(info.effect, std::vector<double>(info.num_parameters + 1)));
    // Only its own slice was written, and no other effect's slice is it.
    const bool gyro = info.form == EffectForm::kGyroOffset;
    int written = 0;
    for (int i = 0; i < kAccelEffectParameters; ++i) {
      written += p.accel[i] != 0.0;
      if (p.accel[i] != 0.0) ++used[i];
    }
    for (int i = 0; i < kGyroEffectParameters; ++i) {
      written += p.gyro[i] != 0.0;
      if (p.gyro[i] != 0.0) ++used[kAccelEffectParameters + i];
    }
    EXPECT_EQ(written, info.num_parameters);
    EXPECT_EQ(info.sensor == EffectSensor::kGyroscope, gyro);
    if (info.simulation.key != nullptr) {
      const auto& fields = internal::SimulatorFields();
      EXPECT_TRUE(std::any_of(fields.begin(), fields.end(), [&](const internal::SimulatorField& f) {
        return std::string(f.key) == info.simulation.key;
      })) << info.simulation.key;
    }
  }
  for (int n : used) EXPECT_EQ(n, 1);
}

// accel_temperature_bias_quadratic: kappa dT^2 with kappa drawn N(0, 3e-4)
// m/s^2/degC^2 per axis (a MEMS bias curvature of about 0.03 mg/K^2; over
// the warm-up's +-7.5 degC it moves the bias by up to 0.02 m/s^2).
constexpr double kCurvature = 3e-4;
constexpr Effect kNew = Effect::kAccelTemperatureBiasQuadratic;

TEST(AddedEffect, EveryConsumerTakesItFromItsDefinition) {
  SimulatorOptions sim = testing_util::WarmUpSession();
  sim.effect_std[kNew] = kCurvature;
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 2, &session, &error)) << error;
  // The simulator's truth names it.
  EXPECT_NE(TruthToJson(session, sim).find("\"accel_temperature_bias_quadratic\""),
            std::string::npos);
  const Eigen::Vector3d truth = session.effects.Vector(kNew);

  // The fit: within four reported sigmas of the truth, and determined
  // (the largest axis many sigmas from zero). The linear term is fitted
  // beside it: about the fit's own reference temperature a parabola has
  // one (the simulator's reference is 25 degC).
  Config config;
  config.effects = {Effect::kAccelTemperatureBias, kNew};
  config.calibration.gravity.gravity = session.gravity;
  PipelineInput input;
  input.log = session.log;
  Calibration calibration;
  ASSERT_TRUE(RunCalibration(config, input, &calibration)) << calibration.message;
  const EffectEstimate* estimate = nullptr;
  for (const EffectEstimate& e : calibration.effects.estimates) {
    if (e.effect == kNew) estimate = &e;
  }
  ASSERT_NE(estimate, nullptr);
  EXPECT_EQ(estimate->names, std::vector<std::string>({"kappa_x", "kappa_y", "kappa_z"}));
  EXPECT_EQ(estimate->unit, "m/s^2/degC^2");
  int largest = 0;
  truth.cwiseAbs().maxCoeff(&largest);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::fabs(estimate->values[i] - truth(i)), 4.0 * estimate->std[i])
        << "axis " << i << ": " << estimate->values[i] << " vs " << truth(i);
  }
  EXPECT_GT(std::fabs(truth(largest)) / estimate->std[largest], 5.0);

  // The JSON holds it and gives back the model the result carries.
  LoadedCalibration read;
  ASSERT_TRUE(CalibrationFromJson(CalibrationToJson(calibration, true), "c.json", &read, &error))
      << error;
  ImuCorrector model;
  ASSERT_TRUE(calibration.Model(&model, nullptr, &error)) << error;
  EXPECT_TRUE(Contains(read.corrector.active_effects, kNew));
  EXPECT_EQ(read.corrector.effects.Vector(kNew), model.effects.Vector(kNew));

  // The corrector applies it: at every pose |a| - g is smaller with it than
  // with the model less its term, by a factor over the poses.
  const ImuCorrector without = model.WithEffects({Effect::kAccelTemperatureBias});
  double with_sum = 0.0, without_sum = 0.0;
  for (const SimulatedPose& p : session.poses) {
    Eigen::Vector3d raw = Eigen::Vector3d::Zero();
    double temperature = 0.0, time = 0.0;
    for (size_t i = p.begin; i < p.end; ++i) {
      raw += session.log.accel[i];
      temperature += session.log.temperature[i];
      time += session.log.t[i];
    }
    const double n = static_cast<double>(p.end - p.begin);
    Eigen::Vector3d a, b;
    ASSERT_TRUE(model.CorrectAccel(raw / n, temperature / n, time / n, &a));
    ASSERT_TRUE(without.CorrectAccel(raw / n, temperature / n, time / n, &b));
    with_sum += std::pow(a.norm() - session.gravity, 2);
    without_sum += std::pow(b.norm() - session.gravity, 2);
  }
  EXPECT_LT(4.0 * with_sum, without_sum) << with_sum << " vs " << without_sum;

  // The C corrector writes its term from its definition and drops nothing
  // (CCorrectorWithEveryEffectAndTheLagEqualsApply runs it).
  ExportOptions to_c;
  to_c.target = ExportTarget::kC;
  ExportResult exported;
  ASSERT_TRUE(ExportCalibration(read, to_c, &exported, &error)) << error;
  EXPECT_TRUE(exported.dropped.empty()) << exported.dropped.front();
  ASSERT_EQ(exported.files.size(), 2u);
  EXPECT_NE(exported.files[1].text.find("D_ACCEL_TEMPERATURE_BIAS_QUADRATIC[i] * (dT * dT)"),
            std::string::npos);

  // Discovery tries it as a candidate of the accelerometer.
  CalibrationOptions options;
  options.gravity.gravity = session.gravity;
  options.refinement.parameterization = AccelParameterization::kScaleMisalignment;
  DiscoveryResult found;
  ASSERT_TRUE(DiscoverEffects(session.log, options, {}, DiscoveryOptions(), &found))
      << found.message;
  ASSERT_FALSE(found.steps.empty());
  bool tried = false;
  for (const CandidateScore& c : found.steps.front().candidates) {
    if (c.effect == kNew) tried = c.tried;
  }
  EXPECT_TRUE(tried);
  EXPECT_TRUE(Contains(found.named(), kNew));
}

// The generated C corrector against gravcal apply on a simulated warm-up
// (24 poses, 20 to 35 degC) with every effect of the registry on (the
// added one too) and a thermal model with every term and a 40 s lag whose
// range [22, 33] degC clamps both ends: compiled by gcc with -std=c99
// -Wall -Wextra -Werror -pedantic, gravcal_correct_sample (the lag's state)
// in double and float over every row of the log.
TEST(AddedEffect, CCorrectorWithEveryEffectAndTheLagEqualsApply) {
  if (std::system("gcc --version > /dev/null 2>&1") != 0) GTEST_SKIP() << "gcc is not installed";
  SimulatorOptions sim = testing_util::WarmUpSession();
  sim.hold_seconds = 4.0;
  for (const EffectInfo& info : EffectCatalogue()) {
    if (info.simulation.key != nullptr) sim.effect_std[info.effect] = 1e-4;
  }
  sim.effect_std[kNew] = kCurvature;
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 5, &session, &error)) << error;
  Calibration c;
  c.method = "thermal";
  c.accel.model = session.accel_truth;
  c.accel.model.parameterization = AccelParameterization::kAffine;
  c.gyro.estimated = true;
  c.gyro.model = session.gyro_truth;
  int held = 0;
  for (const EffectInfo& info : EffectCatalogue()) {
    if (info.form == EffectForm::kInUpper) continue;
    EffectEstimate e;
    e.effect = info.effect;
    e.names = info.parameter_names;
    e.values = session.effects.Values(info.effect);
    // Gyroscope terms in raw units, and never all zero.
    for (size_t k = 0; k < e.values.size(); ++k) {
      e.values[k] =
          (e.values[k] + 1e-4 * (k + 1)) * (info.form == EffectForm::kGyroOffset ? 50.0 : 1.0);
    }
    e.std.assign(e.values.size(), 0.0);
    e.unit = info.unit;
    c.effects.estimates.push_back(e);
    ++held;
  }
  ASSERT_EQ(held, kNumEffects - 1);
  c.effects.reference_temperature = 26.0;
  c.effects.reference_time = 30.0;
  ThermalModel& m = c.thermal;
  m.reference_temperature = 27.0;
  m.min_temperature = 22.0;
  m.max_temperature = 33.0;
  m.lag_time_constant = 40.0;
  auto set = [](ThermalPolynomial* p, int components, int order, double scale) {
    p->Resize(components, order);
    for (int i = 0; i < components; ++i) {
      for (int k = 0; k < order; ++k) p->coefficients(i, k) = scale * (i + 1 - 2.0 * k) / (k + 1);
    }
  };
  set(&m.accel.bias, 3, 3, 2e-3);
  set(&m.accel.scale, 3, 2, 1e-4);
  set(&m.accel.misalignment, 3, 1, 2e-5);
  set(&m.gyro.bias, 3, 2, 1e-3);
  set(&m.gyro.scale, 3, 1, 5e-5);
  set(&m.gyro.misalignment, 6, 1, 1e-5);
  c.gravity = session.gravity;
  c.success = true;
  const testing_util::ScratchDir scratch;
  const std::string calib = scratch.Write("calib.json", CalibrationToJson(c, false));
  ASSERT_TRUE(WriteImuLogCsv(session.log, scratch / "raw.csv", &error)) << error;
  testing_util::CliResult r = testing_util::RunCli(
      "export --calibration " + calib + " --to c --output-dir " + (scratch / "c"), scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("nothing dropped"), std::string::npos) << r.err;
  r = testing_util::RunCli("apply --calibration " + calib + " --input " + (scratch / "raw.csv") +
                               " --output " + (scratch / "applied.csv"),
                           scratch);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The C program reads t, accel, gyro, temperature per row.
  std::string rows;
  const ImuLog& log = session.log;
  for (size_t i = 0; i < log.size(); ++i) {
    char line[400];
    std::snprintf(line, sizeof(line), "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", log.t[i],
                  log.accel[i](0), log.accel[i](1), log.accel[i](2), log.gyro[i](0), log.gyro[i](1),
                  log.gyro[i](2), log.temperature[i]);
    rows += line;
  }
  scratch.Write("c/rows.txt", rows);
  std::vector<testing_util::CCorrectedRow> c_rows;
  ASSERT_TRUE(testing_util::RunCCorrector(scratch / "c", "cat " + (scratch / "c/rows.txt"), " ",
                                          true, &c_rows, &error))
      << error;
  ImuLog applied;
  ASSERT_TRUE(ReadImuLog(scratch / "applied.csv", LogReaderOptions(), &applied, &error)) << error;
  ASSERT_EQ(applied.size(), log.size());
  EXPECT_EQ(c_rows.size(), applied.size());
  double worst_double = 0.0, worst_float = 0.0;
  testing_util::WorstRelative(c_rows, applied, &worst_double, &worst_float);
  // The same rows without the lag (the stateless functions' model), to
  // show the lag matters here.
  ImuCorrector no_lag;
  ASSERT_TRUE(c.Model(&no_lag, nullptr, &error)) << error;
  double lag_effect = 0.0;
  for (size_t n = 0; n < applied.size(); ++n) {
    Eigen::Vector3d a0 = log.accel[n], w0 = log.gyro[n];
    ASSERT_TRUE(no_lag.CorrectRow(log.temperature[n], log.t[n], &a0, &w0));
    lag_effect = std::max(lag_effect, (a0 - applied.accel[n]).norm());
  }
  std::printf(
      "C corrector (every effect, 40 s lag) vs apply over %zu rows: double %.3g, float "
      "%.3g (largest relative); the lag moves a by up to %.3g m/s^2\n",
      c_rows.size(), worst_double, worst_float, lag_effect);
  EXPECT_LT(worst_double, 1e-9);
  EXPECT_LT(worst_float, 1e-5);
  EXPECT_GT(lag_effect, 1e-4);
}

}  // namespace
}  // namespace gravcal
