// The pieces every pipeline property case shares: a shipped config with
// changes, `gravcal simulate` and `gravcal calibrate` in memory, and the
// readers of the accelerometer and gyroscope errors against the truth.
#ifndef GRAVCAL_TESTS_PROPERTY_PIPELINE_CASE_H_
#define GRAVCAL_TESTS_PROPERTY_PIPELINE_CASE_H_

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "gravcal/io/attitude_fixture.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/simulated_attitudes.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "gravcal/workflows/pipeline.h"
#include "property/method_case.h"
#include "property/parameter_errors.h"
#include "test_util.h"

namespace gravcal {
namespace testing_util {

// configs/<file> as `--config configs/<file>` loads it, then the `changes`
// as command-line flags would set them.
inline Config ShippedConfig(const std::string& file,
                            const std::vector<std::pair<std::string, std::string>>& changes = {}) {
  Config config;
  std::string error;
  EXPECT_TRUE(LoadConfigFile(SourceDir() + "/configs/" + file, &config, &error)) << error;
  for (const auto& [key, value] : changes) {
    EXPECT_TRUE(SetConfigValue(key, value, &config, &error)) << error;
  }
  EXPECT_TRUE(config.IsValid(&error)) << file << ": " << error;
  return config;
}

// `gravcal simulate`: the motion simulator when sim_motion names a profile,
// the multi-position one otherwise.
inline bool SimulateAsCli(const Config& config, uint64_t seed, SimulatedInput* input,
                          std::string* error) {
  if (!config.sim_motion) return Simulate(config.simulation, seed, &input->session, error);
  MotionOptions motion = config.motion;
  motion.profile = *config.sim_motion;
  MotionSession moving;
  if (!SimulateMotion(config.simulation, motion, seed, &moving, error)) return false;
  input->session = std::move(moving.sensor);
  input->segments = std::move(moving.segments);
  return true;
}

// `gravcal calibrate`: RunCalibration on the simulated log (in memory: the
// CSV round trip is another helper's test), with the attitudes file
// `simulate` writes for known_attitude.
inline bool CalibrateAsCli(const Config& config, const SimulatedInput& input, uint64_t seed,
                           Calibration* calibration) {
  PipelineInput pipeline;
  pipeline.log = input.session.log;
  pipeline.source = "seed " + std::to_string(seed);
  std::string attitudes;
  if (config.method == Method::kKnownAttitude) {
    std::string path = testing_util::ScratchFileTemplate("gravcal_property_");
    const int fd = mkstemp(path.data());
    if (fd < 0) {
      calibration->message = "cannot create a temporary attitudes file";
      return false;
    }
    close(fd);
    attitudes = path;
    std::ofstream(attitudes) << FixtureAttitudesToCsv(SimulatedFixtureAttitudes(
        input.session, config.simulation.fixture_attitude_noise_deg, seed));
    pipeline.attitudes_path = attitudes;
  }
  const bool ok = RunCalibration(config, pipeline, calibration);
  if (!attitudes.empty()) std::remove(attitudes.c_str());
  return ok;
}

// The accelerometer's covariance parameters against the truth.
inline void AccelErrors(const Calibration& c, const SimulatedInput& input,
                        std::vector<ParameterError>* out) {
  AddAccelErrors("accel.", c.accel, input.session.accel_truth, out);
}

// The truth of the gyroscope in the calibrated accelerometer's frame: a
// magnitude fit (R = I) sees R_a^T f, R_a the truth accelerometer's housing
// rotation, so the gyroscope must give R_a^T w: M = R_a^T M_g, G = R_a^T G
// R_a (gyro_calibration.h).
inline GyroTruth GyroInAccelFrame(const SimulatedSession& s) {
  GyroTruth t;
  const Eigen::Matrix3d ra = s.accel_truth.rotation;
  t.bias = s.gyro_truth.bias;
  t.matrix = ra.transpose() * s.gyro_truth.matrix;
  t.g_sensitivity = ra.transpose() * s.gyro_g_sensitivity * ra;
  return t;
}

inline void AccelAndGyroErrors(const Calibration& c, const SimulatedInput& input,
                               std::vector<ParameterError>* out) {
  AccelErrors(c, input, out);
  EXPECT_TRUE(c.gyro.estimated);
  AddGyroErrors("gyro.", c.gyro, GyroInAccelFrame(input.session), out);
}

// Ten positions: the step-4 covariance parameters (bias and U in the
// sensor's own frame, the model that covariance describes) and the diagonal
// of K the calibration reports with matrix_std (ten_position.h).
inline void TenPositionErrors(const Calibration& c, const SimulatedInput& input,
                              std::vector<ParameterError>* out) {
  const AccelModel& truth = input.session.accel_truth;
  AddAccelErrors("accel.", c.accel.covariance_names, c.accel.covariance, c.refinement.model, truth,
                 out);
  const char* axes[3] = {"xx", "yy", "zz"};
  for (int i = 0; i < 3; ++i) {
    out->push_back({std::string("accel.K_") + axes[i],
                    c.accel.model.upper(i, i) - truth.upper(i, i), c.accel.matrix_std(i, i)});
  }
}

inline MethodCase PipelineCase(const std::string& name, const Config& config) {
  MethodCase m;
  m.name = name;
  m.config = config;
  m.simulate = SimulateAsCli;
  m.calibrate = CalibrateAsCli;
  m.extract = AccelErrors;
  return m;
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_PROPERTY_PIPELINE_CASE_H_
