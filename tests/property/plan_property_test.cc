// Issue 15: a planned session, simulated over many seeds and calibrated by
// the twelve_position pipeline as `gravcal calibrate` would, has the
// spread the plan predicted: z = (estimate - truth) / predicted_std has
// mean near 0 and rms inside the chi band (tests/sigma_check.h; at 400
// seeds the band is [0.885, 1.118], inside the 15 %), and the
// spread meets every stated target.
//
// ctest runs it as PlanProperty.* (kDefaultSeeds seeds) and as
// large_seed.PlanProperty.* (GRAVCAL_PROPERTY_SEEDS=1001:400).
#include <gtest/gtest.h>

#include <cstdio>

#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "gravcal/workflows/plan.h"
#include "property/method_case.h"
#include "test_util.h"

namespace gravcal {
namespace testing_util {
namespace {

void CheckPlanSpread(const std::string& target, const std::string& pose_set) {
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(SourceDir() + "/configs/twelve_position.yaml", &config, &error))
      << error;
  // predicted_std in the raw counts the simulator writes.
  config.calibration.nominal_scale = kStandardGravity / config.simulation.accel_counts_per_g;
  PlanRequest request;
  request.targets = target;
  request.pose_set = pose_set;
  // The simulator's white noise: sim_accel_noise per sample at sim_sample_rate.
  request.accel_noise_density =
      config.simulation.accel_noise / std::sqrt(config.simulation.sample_rate);
  RecordingPlan plan;
  ASSERT_TRUE(MakeRecordingPlan(config, request, &plan, &error)) << error;
  config.simulation.initial_still_seconds = 0.0;
  for (const PlannedPose& p : plan.poses) {
    config.simulation.planned_poses.push_back({p.up, p.hold_seconds});
  }

  int first = 1, count = kDefaultSeeds;
  PropertySeeds(&first, &count);
  SigmaCheck check;
  std::vector<double> sum_squares(plan.parameter_names.size(), 0.0);
  int used = 0;
  for (int seed = first; seed < first + count; ++seed) {
    SimulatedSession session;
    ASSERT_TRUE(Simulate(config.simulation, seed, &session, &error)) << error;
    PipelineInput input;
    input.log = session.log;
    input.source = "seed " + std::to_string(seed);
    Calibration calibration;
    ASSERT_TRUE(RunCalibration(config, input, &calibration)) << calibration.message;
    ASSERT_EQ(calibration.positions.size(), plan.poses.size()) << "seed " << seed;
    double estimate[9], truth[9];
    const AccelModel& e = calibration.accel.model;
    const AccelModel& t = session.accel_truth;
    e.GetUpper(estimate + 3);
    t.GetUpper(truth + 3);
    for (int i = 0; i < 3; ++i) {
      estimate[i] = e.bias(i);
      truth[i] = t.bias(i);
    }
    for (size_t i = 0; i < plan.parameter_names.size(); ++i) {
      const double error_i = estimate[i] - truth[i];
      check.Add(plan.parameter_names[i], error_i, plan.predicted_std(i));
      sum_squares[i] += error_i * error_i;
    }
    ++used;
  }
  std::printf("plan %s (%s): %zu poses, %.1f s\n%s", target.c_str(), pose_set.c_str(),
              plan.poses.size(), plan.total_seconds, check.Table().c_str());
  check.ExpectHonest("plan " + target);
  // The criterion, asserted where the seeds can resolve it (the
  // 400-seed run): the spread within 15 % of predicted_std.
  if (used >= 200) {
    for (const std::string& name : plan.parameter_names) {
      EXPECT_LT(std::abs(check.Rms(name) - 1.0), 0.15) << name;
    }
  }
  // Every stated target met by the spread actually seen (scale-free), within
  // the band's allowance for a finite number of seeds.
  const SigmaBand band = SigmaBandFor(used);
  for (size_t i = 0; i < plan.parameter_names.size(); ++i) {
    if (!plan.targeted[i]) continue;
    const double spread = std::sqrt(sum_squares[i] / used);
    const double scale_free = i < 3 ? spread * plan.nominal_scale : spread / plan.nominal_scale;
    EXPECT_LT(scale_free, plan.targets_scale_free(i) * band.rms_high)
        << plan.parameter_names[i] << ": spread " << scale_free << " against target "
        << plan.targets_scale_free(i);
  }
}

TEST(PlanProperty, SpreadMatchesPredictionFacesPlus45) {
  CheckPlanSpread("accel_bias=0.05mg accel_scale=20ppm accel_misalignment=0.02mrad", "faces+45");
}

TEST(PlanProperty, SpreadMatchesPredictionFree) {
  CheckPlanSpread("accel_bias=0.05mg accel_scale=20ppm", "free");
}

}  // namespace
}  // namespace testing_util
}  // namespace gravcal
