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
#include <functional>

#include "gravcal/methods/known_attitude.h"
#include "gravcal/simulation/simulated_attitudes.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "gravcal/workflows/plan.h"
#include "property/method_case.h"
#include "test_util.h"

namespace gravcal {
namespace testing_util {
namespace {

// One planned sensor's prediction and how to read each parameter's error
// from a calibrated seed.
struct PlannedParameters {
  SensorPrediction sensor;
  std::function<std::vector<double>(const SimulatedSession&, const Calibration&)> errors;
};

// Simulates config.simulation for every seed of the run, calibrates each as
// gravcal calibrate would, and checks z = error / predicted_std: honest
// (tests/sigma_check.h), within 15 % of 1 where the seeds resolve it
// (>= 200), and the spread of every stated target below it.
void CheckSpread(const Config& config, size_t poses, const std::string& label,
                 const PlannedParameters& p) {
  const SensorPrediction& s = p.sensor;
  int first = 1, count = kDefaultSeeds;
  PropertySeeds(&first, &count);
  // Each seed's parameter errors, or what went wrong with it.
  struct Seed {
    std::string failure;
    std::vector<double> errors;
  };
  const std::vector<Seed> seeds = RunSeeds(first, count, PropertyThreads(), [&](int seed) {
    Seed out;
    SimulatedSession session;
    if (!Simulate(config.simulation, seed, &session, &out.failure)) return out;
    PipelineInput input;
    input.log = session.log;
    input.source = "seed " + std::to_string(seed);
    Calibration calibration;
    if (!RunCalibration(config, input, &calibration)) {
      out.failure = "seed " + std::to_string(seed) + ": " + calibration.message;
    } else if (calibration.positions.size() != poses) {
      out.failure = "seed " + std::to_string(seed) + ": " +
                    std::to_string(calibration.positions.size()) + " positions";
    } else {
      out.errors = p.errors(session, calibration);
    }
    return out;
  });
  SigmaCheck check;
  std::vector<double> sum_squares(s.parameter_names.size(), 0.0);
  for (const Seed& seed : seeds) {
    ASSERT_TRUE(seed.failure.empty()) << seed.failure;
    for (size_t i = 0; i < s.parameter_names.size(); ++i) {
      check.Add(s.parameter_names[i], seed.errors[i], s.predicted_std(i));
      sum_squares[i] += seed.errors[i] * seed.errors[i];
    }
  }
  std::printf("%s: %zu poses\n%s", label.c_str(), poses, check.Table().c_str());
  check.ExpectHonest(label);
  // The criterion, asserted where the seeds can resolve it (the
  // 400-seed run): the spread within 15 % of predicted_std.
  if (count >= 200) {
    for (const std::string& name : s.parameter_names) {
      EXPECT_LT(std::abs(check.Rms(name) - 1.0), 0.15) << label << " " << name;
    }
  }
  // Every stated target met by the spread actually seen (scale-free), within
  // the band's allowance for a finite number of seeds.
  const SigmaBand band = SigmaBandFor(count);
  for (size_t i = 0; i < s.parameter_names.size(); ++i) {
    if (!s.targeted[i]) continue;
    const double spread = std::sqrt(sum_squares[i] / count);
    const double scale_free = i < 3 ? spread * s.nominal_scale : spread / s.nominal_scale;
    EXPECT_LT(scale_free, s.targets_scale_free(i) * band.rms_high)
        << label << " " << s.parameter_names[i] << ": spread " << scale_free << " against target "
        << s.targets_scale_free(i);
  }
}

// `by_hand`: the shipped session's pose scatter (sim_pose_disturbance,
// poses placed by hand) is simulated and stated to the plan, as a user
// states it with --pose_disturbance; else the session is on a table (no
// scatter, none stated).
void CheckPlanSpread(const std::string& target, const std::string& pose_set, bool by_hand) {
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(SourceDir() + "/configs/twelve_position.yaml", &config, &error))
      << error;
  // predicted_std in the raw counts the simulator writes.
  config.calibration.nominal_scale = kStandardGravity / config.simulation.accel_counts_per_g;
  PlanRequest request;
  request.targets = target;
  ASSERT_TRUE(FromString(pose_set, &request.pose_set)) << pose_set;
  // The simulator's white noise: sim_accel_noise per sample at sim_sample_rate.
  request.accel_noise_density =
      config.simulation.accel_noise / std::sqrt(config.simulation.sample_rate);
  if (!by_hand) config.simulation.pose_disturbance = 0.0;
  request.pose_disturbance = config.simulation.pose_disturbance;
  EXPECT_EQ(request.pose_disturbance > 0.0, by_hand);
  RecordingPlan plan;
  ASSERT_TRUE(MakeRecordingPlan(config, request, &plan, &error)) << error;
  config.simulation.initial_still_seconds = 0.0;
  for (const PlannedPose& p : plan.poses) {
    config.simulation.planned_poses.push_back({p.up, p.hold_seconds});
  }

  PlannedParameters p{plan.accel,
                      [](const SimulatedSession& session, const Calibration& calibration) {
                        double estimate[9], truth[9];
                        const AccelModel& e = calibration.accel.model;
                        const AccelModel& t = session.accel_truth;
                        e.GetUpper(estimate + 3);
                        t.GetUpper(truth + 3);
                        std::vector<double> errors(9);
                        for (int i = 0; i < 3; ++i) {
                          estimate[i] = e.bias(i);
                          truth[i] = t.bias(i);
                        }
                        for (int i = 0; i < 9; ++i) errors[i] = estimate[i] - truth[i];
                        return errors;
                      }};
  CheckSpread(config, plan.poses.size(),
              "plan " + target + " (" + pose_set + (by_hand ? ", by hand" : "") + ")", p);
}

// The gyroscope half: the plan's turns (and any extra poses) simulated with
// the smooth profile, calibrated by the twelve_position pipeline with the
// gyroscope between poses (configs/twelve_position_gyro.yaml), and the
// spread of b_g and M_g (in the calibrated accelerometer's frame, as
// gyro_calibration_test.cc compares it) against gyro_predicted_std.
void CheckGyroPlanSpread(const std::string& target, const std::string& pose_set) {
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(SourceDir() + "/configs/twelve_position_gyro.yaml", &config, &error))
      << error;
  config.simulation.rotation_profile = RotationProfile::kSmooth;
  config.calibration.nominal_scale = kStandardGravity / config.simulation.accel_counts_per_g;
  config.ten_position.gyro_nominal_scale = M_PI / 180.0 / config.simulation.gyro_counts_per_dps;
  PlanRequest request;
  request.targets = target;
  ASSERT_TRUE(FromString(pose_set, &request.pose_set)) << pose_set;
  request.accel_noise_density =
      config.simulation.accel_noise / std::sqrt(config.simulation.sample_rate);
  request.gyro_noise_density =
      config.simulation.gyro_noise / std::sqrt(config.simulation.sample_rate);
  RecordingPlan plan;
  ASSERT_TRUE(MakeRecordingPlan(config, request, &plan, &error)) << error;
  ASSERT_FALSE(plan.gyro.parameter_names.empty()) << plan.message;
  ASSERT_EQ(plan.rotations.size() + 1, plan.poses.size());
  config.simulation.initial_still_seconds = 0.0;
  for (size_t k = 0; k < plan.poses.size(); ++k) {
    PlannedHold hold{plan.poses[k].up, plan.poses[k].hold_seconds};
    if (k > 0) {
      const PlannedRotation& r = plan.rotations[k - 1];
      hold.turn_axis = r.axis;
      hold.turn_angle_deg = r.angle_deg;
      hold.turn_seconds = r.seconds;
    }
    config.simulation.planned_poses.push_back(hold);
  }

  const std::vector<std::string> names = plan.gyro.parameter_names;
  PlannedParameters p{plan.gyro,
                      [names](const SimulatedSession& session, const Calibration& calibration) {
                        EXPECT_TRUE(calibration.gyro.estimated);
                        const Eigen::Matrix3d truth_matrix =
                            session.accel_truth.rotation.transpose() * session.gyro_truth.matrix;
                        std::vector<double> errors(names.size());
                        for (size_t i = 0; i < names.size(); ++i) {
                          if (i < 3) {
                            errors[i] = calibration.gyro.model.bias(i) - session.gyro_truth.bias(i);
                            continue;
                          }
                          const int r = names[i][2] - 'x', c = names[i][3] - 'x';
                          errors[i] = calibration.gyro.model.matrix(r, c) - truth_matrix(r, c);
                        }
                        return errors;
                      }};
  CheckSpread(config, plan.poses.size(),
              "gyro plan " + target + " (" + pose_set + ", " +
                  std::to_string(plan.gyro_extra_poses) + " extra poses)",
              p);
}

TEST(PlanProperty, GyroSpreadMatchesPredictionFacesPlus45) {
  CheckGyroPlanSpread("accel_bias=0.5mg gyro_scale=300ppm gyro_misalignment=0.5mrad", "faces+45");
}

// The known-attitude model: the plan for method known_attitude (the
// fixture's attitude noise stated), simulated with that fixture noise and
// calibrated by CalibrateKnownAttitude; the spread of b and M (raw units)
// against predicted_std.
void CheckKnownAttitudePlanSpread(const std::string& target) {
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigFile(SourceDir() + "/configs/known_attitude.yaml", &config, &error))
      << error;
  config.calibration.nominal_scale = kStandardGravity / config.simulation.accel_counts_per_g;
  PlanRequest request;
  request.targets = target;
  request.accel_noise_density =
      config.simulation.accel_noise / std::sqrt(config.simulation.sample_rate);
  request.attitude_std_deg = config.simulation.fixture_attitude_noise_deg;
  RecordingPlan plan;
  ASSERT_TRUE(MakeRecordingPlan(config, request, &plan, &error)) << error;
  ASSERT_EQ(plan.accel.parameter_names.size(), 12u);
  config.simulation.initial_still_seconds = 0.0;
  for (const PlannedPose& p : plan.poses) {
    config.simulation.planned_poses.push_back({p.up, p.hold_seconds});
  }
  int first = 1, count = kDefaultSeeds;
  PropertySeeds(&first, &count);
  SigmaCheck check;
  for (int seed = first; seed < first + count; ++seed) {
    SimulatedSession session;
    ASSERT_TRUE(Simulate(config.simulation, seed, &session, &error)) << error;
    Calibration c;
    ASSERT_TRUE(CalibrateKnownAttitude(
        session.log,
        SimulatedFixtureAttitudes(session, config.simulation.fixture_attitude_noise_deg,
                                  static_cast<uint64_t>(seed)),
        "attitudes", config.calibration, &c))
        << c.message;
    const Eigen::Matrix3d m = c.accel.model.matrix() - session.accel_truth.matrix();
    for (size_t i = 0; i < 12; ++i) {
      const double error_i =
          i < 3 ? c.accel.model.bias(i) - session.accel_truth.bias(i) : m((i - 3) / 3, (i - 3) % 3);
      check.Add(plan.accel.parameter_names[i], error_i, plan.accel.predicted_std(i));
    }
  }
  std::printf("known-attitude plan %s: %zu poses, %.1f s\n%s", target.c_str(), plan.poses.size(),
              plan.total_seconds, check.Table().c_str());
  // Conservative, not exact: with x vertical the fixture's roll is the
  // angle of the placement error, so the direction its pitch error moves
  // gravity in varies from seed to seed; the plan averages that covariance
  // (an upper bound on the spread; averaging the information instead gave a
  // lower bound, rms z up to 2.3). Asserted: no sigma too small, no bias.
  const SigmaBand band = SigmaBandFor(count);
  for (const std::string& name : plan.accel.parameter_names) {
    EXPECT_LT(check.Rms(name), band.rms_high) << name;
    EXPECT_LT(std::abs(check.Mean(name)), band.mean_bound) << name;
  }
}

TEST(PlanProperty, KnownAttitudeSpreadMatchesPrediction) {
  CheckKnownAttitudePlanSpread("accel_bias=0.2mg accel_scale=100ppm accel_misalignment=0.5mrad");
}

// Placed by hand: the scatter limits the scale to about 50 ppm in a
// session of 18 poses (20 ppm is out of reach within 40 poses).
TEST(PlanProperty, SpreadMatchesPredictionFacesPlus45ByHand) {
  CheckPlanSpread("accel_bias=0.05mg accel_scale=50ppm accel_misalignment=0.1mrad", "faces+45",
                  /*by_hand=*/true);
}

TEST(PlanProperty, SpreadMatchesPredictionFree) {
  CheckPlanSpread("accel_bias=0.05mg accel_scale=20ppm", "free", /*by_hand=*/false);
}

}  // namespace
}  // namespace testing_util
}  // namespace gravcal
