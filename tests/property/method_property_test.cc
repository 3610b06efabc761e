// Every calibration method under one property: simulated with known truth
// over many seeds, with the shipped configs/*.yaml as the settings under
// test, each estimated parameter's error / reported sigma must have mean
// near 0 and rms inside the chi band for the number of seeds (two-sided,
// 99.9 %, tests/sigma_check.h). Where a case changes a shipped setting, the
// change is next to it with the reason.
//
// ctest runs this twice: MethodProperty.* with kDefaultSeeds seeds per case,
// and large_seed.MethodProperty.* (label large_seed) with
// GRAVCAL_PROPERTY_SEEDS=1001:400 (400 other seeds); both print the per-parameter
// table (n, mean z, rms z, band).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <fstream>

#include "gravcal/io/attitude_fixture.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/simulated_attitudes.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "property/method_case.h"
#include "property/parameter_errors.h"
#include "property/pipeline_case.h"
#include "test_util.h"

namespace gravcal {
namespace testing_util {
namespace {

std::vector<MethodCase> AllCases() {
  std::vector<MethodCase> cases;

  // Twelve positions as shipped: the simulated session scatters from pose
  // to pose as real hand-placed ones do (sim_pose_disturbance), and the
  // shipped pipeline (batch-means pose noise and the REML pose variance)
  // must be honest on it. The models `parameterization` offers run with
  // the same pipeline; the white-noise pipeline of a fixture config
  // (pose_variance false, pose_noise white) is judged on a session without
  // scatter (a table), the session it assumes.
  cases.push_back(
      PipelineCase("twelve_position/scale_misalignment", ShippedConfig("twelve_position.yaml")));
  // The scale model has no non-orthogonality: the simulated sensor must not
  // have any either (sim_accel_misalignment 0), or the truth is outside the
  // model and its error is a model error, not noise.
  cases.push_back(
      PipelineCase("twelve_position/scale/white_on_a_table",
                   ShippedConfig("twelve_position.yaml", {{"parameterization", "scale"},
                                                          {"sim_accel_misalignment", "0"},
                                                          {"sim_pose_disturbance", "0"},
                                                          {"pose_variance", "false"},
                                                          {"pose_noise", "white"}})));
  {
    MethodCase m =
        PipelineCase("twelve_position/affine",
                     ShippedConfig("twelve_position.yaml", {{"parameterization", "affine"}}));
    // The housing rotation's sigma carries the Student-t factor nu/(nu-2)
    // (housing_rotation.h); before it, rms error/sigma was 1.075, 1.161,
    // 1.118 over seeds 1001-1400 (sigma estimated from 9 dof).
    cases.push_back(m);
  }

  // Ten positions. Checked: the step-4 covariance parameters (bias and U in
  // the sensor's own frame, the model that covariance describes) and the
  // diagonal of K the calibration reports with matrix_std. Not checked, by
  // design (ten_position.h): the off-diagonal of K, reported with a NaN
  // standard deviation and a warning, since the self-aligned reference
  // inherits the sensor's own axes.
  {
    MethodCase m = PipelineCase("ten_position", ShippedConfig("ten_position.yaml"));
    m.extract = TenPositionErrors;
    cases.push_back(m);
  }

  cases.push_back(PipelineCase("known_attitude", ShippedConfig("known_attitude.yaml")));

  // The handheld Kalman filter as shipped: the paper's diagonal model
  // (hk_cross_axis false), so the simulated sensor has no cross-axis terms
  // (sim_accel_misalignment and sim_gyro_misalignment 0; with them the truth
  // is outside the model, see configs/handheld_kalman.yaml), moved by hand
  // (sim_motion handheld, as scripts/golden_outputs.sh simulates it). The
  // simulated log is in counts, so the nominal scales are the part's, given
  // as a user gives them (--nominal_scale, --gyro_nominal_scale).
  {
    MethodCase m = PipelineCase(
        "handheld_kalman", ShippedConfig("handheld_kalman.yaml", {{"sim_motion", "handheld"},
                                                                  {"sim_accel_misalignment", "0"},
                                                                  {"sim_gyro_misalignment", "0"}}));
    m.calibrate = [](const Config& shipped, const SimulatedInput& input, uint64_t seed,
                     Calibration* c) {
      Config config = shipped;
      config.calibration.nominal_scale = 1.0 / input.session.accel_units_per_si;
      config.handheld.gyro_nominal_scale = 1.0 / input.session.gyro_units_per_si;
      return CalibrateAsCli(config, input, seed, c);
    };
    m.extract = [](const Calibration& c, const SimulatedInput& input,
                   std::vector<ParameterError>* out) {
      AccelErrors(c, input, out);
      GyroTruth truth;
      truth.bias = input.session.gyro_truth.bias;
      truth.matrix = input.session.gyro_truth.matrix;
      AddGyroErrors("gyro.", c.gyro, truth, out);
    };
    // Known failure, measured 2026-11-23 (seeds 1001-1400): the filter's
    // accelerometer z bias and scale are biased, mean error/sigma +0.238
    // and +0.174 (bound 0.165; the same in the filter's own units,
    // accel_bias_z and accel_scale_z of the convergence report), about 4.8
    // and 3.5 standard errors of the mean. Every rms is low (0.886-0.959:
    // the shipped 3 cm pseudo-measurement noise is conservative for the
    // simulated hand, as tests/handheld_kalman_test.cc notes) but inside
    // the band.
    m.known_failures = {"accel.bias_z", "accel.m_zz"};
    cases.push_back(m);
  }

  // The gyroscope from the rotations between poses, as shipped (full M_g,
  // no G, accelerometer held), then with G and jointly.
  {
    MethodCase m =
        PipelineCase("gyro_between_poses/full", ShippedConfig("twelve_position_gyro.yaml"));
    m.extract = AccelAndGyroErrors;
    cases.push_back(m);
  }
  {
    // G estimated (gyro_g_sensitivity true) on a sensor that has one
    // (sim_gyro_g_sensitivity 2e-4 rad/s per m/s^2, about 0.1 deg/s per g,
    // a typical MEMS value): with the default G = 0 the estimate would be
    // checked against zero only.
    MethodCase m = PipelineCase(
        "gyro_between_poses/full+G",
        ShippedConfig("twelve_position_gyro.yaml",
                      {{"gyro_g_sensitivity", "true"}, {"sim_gyro_g_sensitivity", "2e-4"}}));
    m.extract = AccelAndGyroErrors;
    cases.push_back(m);
  }
  {
    MethodCase m =
        PipelineCase("gyro_between_poses/joint",
                     ShippedConfig("twelve_position_gyro.yaml", {{"gyro_joint", "true"}}));
    m.extract = AccelAndGyroErrors;
    cases.push_back(m);
  }

  // The rate table: no shipped config and no pipeline method, so the
  // defaults of `gravcal simulate --sim_motion rate_table` and
  // CalibrateRateTable on its segments. The truth is in the body frame the
  // table's rates are given in.
  {
    Config config;
    std::string error;
    EXPECT_TRUE(SetConfigValue("sim_motion", "rate_table", &config, &error)) << error;
    MethodCase m = PipelineCase("rate_table", config);
    m.calibrate = [](const Config&, const SimulatedInput& input, uint64_t, Calibration* c) {
      RateTableResult r;
      const bool ok = CalibrateRateTable(input.session.log, input.segments, &r);
      c->success = ok;
      c->message = r.message;
      c->gyro = r.gyro;
      return ok;
    };
    m.extract = [](const Calibration& c, const SimulatedInput& input,
                   std::vector<ParameterError>* out) {
      GyroTruth truth;
      truth.bias = input.session.gyro_truth.bias;
      truth.matrix = input.session.gyro_truth.matrix;
      AddGyroErrors("gyro.", c.gyro, truth, out);
    };
    cases.push_back(m);
  }

  // Effects: the discovery session (configs/discovery.yaml simulates a
  // warm-up with a 0.5 mg/K accelerometer bias tempco) calibrated with that
  // effect, as the config's comment shows (--effects
  // [accel_temperature_bias]). The bias is estimated at the fit's reference
  // temperature T_ref (the mean over the positions), the simulator's is at
  // 25 degC: the truth at T_ref is b + U^-1 beta (T_ref - 25).
  {
    MethodCase m =
        PipelineCase("effects/accel_temperature_bias",
                     ShippedConfig("discovery.yaml", {{"effects", "[accel_temperature_bias]"}}));
    m.extract = [](const Calibration& c, const SimulatedInput& input,
                   std::vector<ParameterError>* out) {
      const SimulatedSession& s = input.session;
      AccelModel truth = s.accel_truth;
      truth.bias += truth.upper.inverse() * s.effects.Vector(Effect::kAccelTemperatureBias) *
                    (c.effects.reference_temperature - s.effects.reference_temperature);
      // The accelerometer covariance also holds the effect terms (beta_x,
      // ...): they are checked below, with the std the effects report.
      std::vector<std::string> effect_names;
      for (const EffectEstimate& e : c.effects.estimates) {
        effect_names.insert(effect_names.end(), e.names.begin(), e.names.end());
      }
      AddAccelErrors("accel.", c.accel, truth, out, effect_names);
      EXPECT_EQ(c.effects.estimates.size(), 1u);
      for (const EffectEstimate& e : c.effects.estimates) {
        const std::vector<double> values = s.effects.Values(e.effect);
        for (size_t i = 0; i < e.values.size(); ++i) {
          const double t = i < values.size() ? values[i] : NAN;
          out->push_back({std::string("effect.") + e.names[i], e.values[i] - t, e.std[i]});
        }
      }
    };
    cases.push_back(m);
  }
  return cases;
}

class MethodProperty : public ::testing::TestWithParam<int> {};

TEST_P(MethodProperty, ErrorOverSigmaIsStandardNormal) {
  const std::vector<MethodCase> cases = AllCases();
  ASSERT_LT(GetParam(), static_cast<int>(cases.size()));
  const MethodCase& method = cases[GetParam()];
  int first = 1, seeds = 0;
  PropertySeeds(&first, &seeds);
  const int threads = PropertyThreads();
  ASSERT_GE(seeds, 2);
  const auto start = std::chrono::steady_clock::now();
  SigmaCheck check, known;
  const std::vector<SeedOutcome> failed =
      RunMethodCase(method, first, seeds, threads, &check, &known);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const SeedOutcome& f : failed) {
    ADD_FAILURE() << method.name << " seed " << f.seed << ": " << f.message;
  }
  // Every parameter has a z for every seed (no silent gaps).
  ASSERT_FALSE(check.Names().empty()) << method.name;
  for (const std::string& name : check.Names()) {
    EXPECT_EQ(check.Count(name), seeds - static_cast<int>(failed.size()))
        << method.name << " " << name;
  }
  check.ExpectHonest(method.name);
  for (const std::string& name : method.known_failures) {
    EXPECT_EQ(known.Count(name), seeds - static_cast<int>(failed.size()))
        << method.name << " " << name << " (known failure) not reported";
  }
  std::printf("%s: seeds %d..%d, %d threads, %.1f s\n%s", method.name.c_str(), first,
              first + seeds - 1, threads, seconds, check.Table().c_str());
  if (!method.known_failures.empty()) {
    std::printf("%s, known failures (not asserted):\n%s", method.name.c_str(),
                known.Table().c_str());
  }
}

std::string MethodCaseName(const ::testing::TestParamInfo<int>& info) {
  return TestParameterName(AllCases()[info.param].name);
}

INSTANTIATE_TEST_SUITE_P(Methods, MethodProperty,
                         ::testing::Range(0, static_cast<int>(AllCases().size())), MethodCaseName);

}  // namespace
}  // namespace testing_util
}  // namespace gravcal
