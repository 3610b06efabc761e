// Issue 34: an effect is defined once (its file in core/effects/) and
// registered by one line (core/effect_registry.h); every consumer derives
// from the definition. The registry's layout, then one effect added that
// way (accel_temperature_bias_quadratic) followed through the simulator,
// the fit, the calibration JSON, the corrector, the exporters' notes and
// discovery, none of which names it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

#include "gravcal/core/imu_corrector.h"
#include "gravcal/core/model_effects.h"
#include "gravcal/io/calibration_export.h"
#include "gravcal/io/calibration_io.h"
#include "gravcal/io/calibration_models.h"
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

  // The C corrector does not write it: the export says it dropped it.
  ExportOptions to_c;
  to_c.target = ExportTarget::kC;
  ExportResult exported;
  ASSERT_TRUE(ExportCalibration(read, to_c, &exported, &error)) << error;
  std::string dropped;
  for (const std::string& line : exported.dropped) dropped += line + "\n";
  EXPECT_NE(dropped.find("accel_temperature_bias_quadratic"), std::string::npos) << dropped;

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

}  // namespace
}  // namespace gravcal
