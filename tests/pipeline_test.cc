// RunCalibration: the one entry point shared by `calibrate`, `batch` and
// library users gives exactly what the method's own function gives.
#include "gravcal/workflows/pipeline.h"

#include <gtest/gtest.h>

#include "gravcal/io/calibration_io.h"
#include "gravcal/simulation/simulator.h"

namespace gravcal {
namespace {

TEST(Pipeline, TwelvePositionEqualsCalibrateAccelerometer) {
  SimulatorOptions sim;
  sim.hold_seconds = 4.0;
  sim.initial_still_seconds = 4.0;
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 11, &session, &error)) << error;
  Config config;
  config.calibration.gravity.gravity = session.gravity;
  PipelineInput input;
  input.log = session.log;
  Calibration via_pipeline;
  ASSERT_TRUE(RunCalibration(config, input, &via_pipeline)) << via_pipeline.message;
  Calibration direct;
  ASSERT_TRUE(CalibrateAccelerometer(session.log, config.calibration, &direct)) << direct.message;
  direct.method = "twelve_position";
  EXPECT_EQ(via_pipeline.method, "twelve_position");
  // Timing fields differ from run to run; everything else must be identical.
  via_pipeline.refinement.solve_seconds = direct.refinement.solve_seconds = 0.0;
  EXPECT_EQ(CalibrationToJson(via_pipeline, true), CalibrationToJson(direct, true));
}

TEST(Pipeline, InvalidConfigFailsWithTheKey) {
  Config config;
  config.method = "nine_position";
  PipelineInput input;
  Calibration c;
  EXPECT_FALSE(RunCalibration(config, input, &c));
  EXPECT_NE(c.message.find("method"), std::string::npos) << c.message;
  EXPECT_FALSE(c.success);
}

}  // namespace
}  // namespace gravcal
