// RunCalibration: the one entry point shared by `calibrate`, `batch` and
// library users gives exactly what the method's own function gives.
#include "gravcal/workflows/pipeline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "gravcal/io/calibration_io.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/methods/known_attitude.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/simulation/handheld_simulator.h"
#include "gravcal/simulation/simulated_attitudes.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/method_registry.h"
#include "gravcal/workflows/plan.h"
#include "gravcal/workflows/rate_table_segments.h"

namespace gravcal {
namespace {

// A twelve-pose session with 4 s holds (a short start still too).
bool ShortHolds(uint64_t seed, SimulatedSession* session, std::string* error) {
  SimulatorOptions sim;
  sim.hold_seconds = 4.0;
  sim.initial_still_seconds = 4.0;
  return Simulate(sim, seed, session, error);
}

TEST(Pipeline, TwelvePositionEqualsCalibrateAccelerometer) {
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(ShortHolds(11, &session, &error)) << error;
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

// The static poses are detected once, by the pipeline, into the session;
// the method and the coverage check read that detection (the CLI's report
// takes session.detection too). Shown by construction: a session whose
// detection lost one interval gives one position fewer to both, so neither
// detected again.
TEST(Pipeline, MethodAndCheckReadTheSessionsDetection) {
  SimulatedSession simulated;
  std::string error;
  ASSERT_TRUE(ShortHolds(12, &simulated, &error)) << error;
  Config config;
  config.calibration.gravity.gravity = simulated.gravity;
  Session session;
  session.log = simulated.log;
  Calibration c;
  ASSERT_TRUE(RunCalibration(config, SessionFiles(), &session, &c)) << c.message;
  ASSERT_TRUE(session.detected);
  ASSERT_TRUE(session.detection_ok);
  const size_t n = session.detection.intervals.size();
  ASSERT_GE(n, 10u);
  EXPECT_EQ(c.positions.size(), n);

  Session fewer = session;
  fewer.detection.intervals.pop_back();
  Calibration c_fewer;
  ASSERT_TRUE(RunCalibration(config, SessionFiles(), &fewer, &c_fewer)) << c_fewer.message;
  EXPECT_EQ(c_fewer.positions.size(), n - 1);
  CoverageReport report;
  ASSERT_TRUE(CheckRecording(fewer, config, PlanRequest(), &report, &error)) << error;
  EXPECT_EQ(report.positions, static_cast<int>(n - 1));
  ASSERT_TRUE(CheckRecording(session, config, PlanRequest(), &report, &error)) << error;
  EXPECT_EQ(report.positions, static_cast<int>(n));

  // A failed detection is reported by the method, at its own step.
  Session broken;
  broken.log = simulated.log;
  broken.detected = true;
  broken.detection.message = "detector failed (test)";
  Calibration c_broken;
  EXPECT_FALSE(RunCalibration(config, SessionFiles(), &broken, &c_broken));
  EXPECT_EQ(c_broken.message, "detector failed (test)");
}

// A method takes its side data as values: known_attitude on a session
// holding the fixture's rows gives what the pipeline gives from the file.
TEST(Pipeline, SideDataInMemoryEqualsTheFile) {
  SimulatedSession simulated;
  std::string error;
  ASSERT_TRUE(ShortHolds(14, &simulated, &error)) << error;
  const std::vector<FixtureAttitude> rows = SimulatedFixtureAttitudes(simulated, 0.05, 14);
  const std::string path = ::testing::TempDir() + "/pipeline_attitudes.csv";
  std::ofstream(path) << FixtureAttitudesToCsv(rows);
  Config config;
  ASSERT_TRUE(SetConfigValue("method", "known_attitude", &config, &error)) << error;
  config.calibration.gravity.gravity = simulated.gravity;
  PipelineInput input;
  input.log = simulated.log;
  input.attitudes_path = path;
  Calibration from_file;
  ASSERT_TRUE(RunCalibration(config, input, &from_file)) << from_file.message;
  // The rows as the file holds them (its text rounds the simulated values).
  std::vector<FixtureAttitude> read;
  ASSERT_TRUE(ReadFixtureAttitudes(path, &read, &error)) << error;
  std::remove(path.c_str());
  ASSERT_EQ(read.size(), rows.size());
  Session session;
  session.log = simulated.log;
  session.attitudes = read;
  session.attitudes_name = path;
  Calibration in_memory;
  ASSERT_TRUE(CalibrateKnownAttitude(session, {config.calibration}, &in_memory))
      << in_memory.message;
  EXPECT_EQ(in_memory.method, "known_attitude");
  from_file.refinement.solve_seconds = in_memory.refinement.solve_seconds = 0.0;
  EXPECT_EQ(CalibrationToJson(in_memory, true), CalibrationToJson(from_file, true));
}

// The log is read once: the provenance hash comes from the bytes parsed,
// and equals the hash of the file read on its own.
TEST(Pipeline, LogAndProvenanceFromOneRead) {
  SimulatorOptions sim;
  sim.hold_seconds = 2.0;
  SimulatedSession simulated;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 13, &simulated, &error)) << error;
  const std::string path = ::testing::TempDir() + "/pipeline_provenance.csv";
  ASSERT_TRUE(WriteImuLogCsv(simulated.log, path, &error)) << error;
  ImuLog log;
  CalibrationProvenance once;
  ASSERT_TRUE(ReadImuLog(path, LogReaderOptions(), &log, &once, &error)) << error;
  CalibrationProvenance separately;
  ASSERT_TRUE(LogProvenance(path, &separately, &error)) << error;
  std::remove(path.c_str());
  EXPECT_EQ(log.size(), simulated.log.size());
  EXPECT_EQ(once.log_file, path);
  EXPECT_EQ(once.log_hash, separately.log_hash);
  EXPECT_EQ(once.gravcal_version, separately.gravcal_version);
  EXPECT_FALSE(ReadImuLog(path, LogReaderOptions(), &log, &once, &error));
  EXPECT_NE(error.find(path), std::string::npos) << error;
}

TEST(Pipeline, InvalidConfigFailsWithTheKey) {
  Config config;
  config.calibration.nominal_scale = -1.0;
  PipelineInput input;
  Calibration c;
  EXPECT_FALSE(RunCalibration(config, input, &c));
  EXPECT_NE(c.message.find("nominal_scale"), std::string::npos) << c.message;
  EXPECT_FALSE(c.success);
}

TEST(Pipeline, UnknownMethodFailsNamingIt) {
  Config config;
  std::string error;
  EXPECT_FALSE(SetConfigValue("method", "thirteen_position", &config, &error));
  EXPECT_NE(error.find("unknown method 'thirteen_position'"), std::string::npos) << error;
  EXPECT_EQ(config.method, Method::kTwelvePosition);
}

TEST(Pipeline, KeyTheMethodDoesNotUseFailsBeforeRunning) {
  Config config;
  std::string error;
  ASSERT_TRUE(LoadConfigText("method: known_attitude\neffects: [accel_temperature_bias]\n",
                             "c.yaml", &config, &error))
      << error;
  PipelineInput input;
  input.attitudes_path = "attitudes.csv";
  Calibration c;
  EXPECT_FALSE(RunCalibration(config, input, &c));
  EXPECT_EQ(c.message.rfind("key 'effects' is not used by method 'known_attitude'", 0), 0u)
      << c.message;
}

// Every registry method is dispatched to: on an empty log each fails, but
// with its own name in the result (and the side input it needs asked for).
TEST(Pipeline, EveryRegistryMethodIsDispatched) {
  for (const CalibrationMethod& m : CalibrationMethods()) {
    Config config;
    config.method = m.id;
    PipelineInput input;
    Calibration c;
    EXPECT_FALSE(RunCalibration(config, input, &c)) << m.name;
    EXPECT_EQ(c.method, m.name);
    EXPECT_FALSE(c.message.empty()) << m.name;
    if (m.side_input == MethodSideInput::kAttitudes) {
      EXPECT_NE(c.message.find("--attitudes"), std::string::npos) << c.message;
    }
    if (m.side_input == MethodSideInput::kSegments) {
      EXPECT_NE(c.message.find("--segments"), std::string::npos) << c.message;
    }
  }
}

// method: rate_table through the segments file gives what CalibrateRateTable
// gives on the simulator's own segments.
TEST(Pipeline, RateTableFromSegmentsFileEqualsCalibrateRateTable) {
  SimulatorOptions sensor;
  MotionOptions motion;
  motion.profile = MotionProfile::kRateTable;
  motion.rate_dps = 60.0;
  motion.seconds_per_axis = 10.0;
  MotionSession s;
  std::string error;
  ASSERT_TRUE(SimulateMotion(sensor, motion, 4, &s, &error)) << error;
  ASSERT_EQ(s.segments.size(), 6u);
  const std::string text = RateTableSegmentsToCsv(s.segments, s.sensor.log);
  std::vector<RateTableSegment> parsed;
  ASSERT_TRUE(ParseRateTableSegments(text, "segments.csv", s.sensor.log, &parsed, &error)) << error;
  ASSERT_EQ(parsed.size(), s.segments.size());
  for (size_t k = 0; k < parsed.size(); ++k) {
    EXPECT_EQ(parsed[k].begin, s.segments[k].begin) << k;
    EXPECT_EQ(parsed[k].end, s.segments[k].end) << k;
    EXPECT_LT((parsed[k].rate - s.segments[k].rate).norm(), 1e-12) << k;
  }
  const std::string path = ::testing::TempDir() + "/pipeline_segments.csv";
  std::ofstream(path) << text;

  Config config;
  ASSERT_TRUE(SetConfigValue("method", "rate_table", &config, &error)) << error;
  PipelineInput input;
  input.log = s.sensor.log;
  input.segments_path = path;
  Calibration c;
  ASSERT_TRUE(RunCalibration(config, input, &c)) << c.message;
  std::remove(path.c_str());
  EXPECT_EQ(c.method, "rate_table");
  ASSERT_TRUE(c.gyro.estimated);
  ASSERT_FALSE(c.warnings.empty());
  RateTableResult direct;
  ASSERT_TRUE(CalibrateRateTable(s.sensor.log, s.segments, &direct)) << direct.message;
  EXPECT_LT((c.gyro.model.bias - direct.gyro.model.bias).norm(),
            1e-9 * direct.gyro.model.bias.norm() + 1e-12);
  EXPECT_LT((c.gyro.model.matrix - direct.gyro.model.matrix).norm(),
            1e-9 * direct.gyro.model.matrix.norm());
  // And it is a calibration: the truth within four standard deviations.
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::fabs(c.gyro.model.matrix(i, i) - s.sensor.gyro_truth.matrix(i, i)),
              4.0 * c.gyro.matrix_std(i, i))
        << i;
  }
}

TEST(Pipeline, BadSegmentsFileNamesFileAndLine) {
  ImuLog log;
  log.source = "log.csv";
  for (int i = 0; i < 100; ++i) {
    log.t.push_back(0.01 * i);
    log.accel.push_back(Eigen::Vector3d::UnitZ());
    log.gyro.push_back(Eigen::Vector3d::Zero());
  }
  std::vector<RateTableSegment> segments;
  std::string error;
  EXPECT_FALSE(ParseRateTableSegments("t_begin,t_end,rate_x_dps,rate_y_dps\n0,1,2,3\n", "s.csv",
                                      log, &segments, &error));
  EXPECT_NE(error.find("rate_z_dps"), std::string::npos) << error;
  EXPECT_FALSE(ParseRateTableSegments(
      "t_begin,t_end,rate_x_dps,rate_y_dps,rate_z_dps\n0,0.5,10,0,0\n0.6,x,0,0,0\n", "s.csv", log,
      &segments, &error));
  EXPECT_EQ(error.rfind("s.csv:3:", 0), 0u) << error;
  EXPECT_FALSE(
      ParseRateTableSegments("t_begin,t_end,rate_x_dps,rate_y_dps,rate_z_dps\n5,6,10,0,0\n",
                             "s.csv", log, &segments, &error));
  EXPECT_NE(error.find("fewer than 2 samples"), std::string::npos) << error;
  ASSERT_TRUE(ParseRateTableSegments(
      "# comment\nt_begin,t_end,rate_x_dps,rate_y_dps,rate_z_dps\n0.1,0.5,10,0,0\n", "s.csv", log,
      &segments, &error))
      << error;
  ASSERT_EQ(segments.size(), 1u);
  EXPECT_EQ(segments[0].begin, 10u);
  EXPECT_EQ(segments[0].end, 51u);
}

}  // namespace
}  // namespace gravcal
