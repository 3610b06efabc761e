// Long logs in bounded memory (issue 39, io/log_reader.h max_samples): a log
// of at most max_samples rows is read exactly as without a limit; a longer
// one holds at most max_samples block means whatever its length, and the
// noise model and the calibration from those means agree with the ones from
// every row.
#include "gravcal/io/long_log.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "gravcal/estimation/noise_characterisation.h"
#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/noise_process.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/noise_workflow.h"
#include "gravcal/workflows/pipeline.h"
#include "still_log.h"

namespace gravcal {
namespace {

// A still log of white noise (accelerometer 2e-3 m/s^2/sqrt(Hz), gyroscope
// 1e-4 rad/s/sqrt(Hz), at 100 Hz) with a temperature column, written to `path`.
ImuLog WriteStillLog(const std::string& path, double seconds) {
  NoiseProcessOptions accel;
  accel.white_noise = 2e-3;
  NoiseProcessOptions gyro;
  gyro.white_noise = 1e-4;
  ImuLog log = testing_util::StillLog(accel, gyro, 1.0, 7, seconds);
  log.temperature.resize(log.size());
  for (size_t i = 0; i < log.size(); ++i) log.temperature[i] = 25.0 + 1e-4 * i;
  std::string error;
  EXPECT_TRUE(WriteImuLogCsv(log, path, &error)) << error;
  return log;
}

// Reads `path` holding at most `max_samples` entries; *reading says how.
bool ReadBounded(const std::string& path, size_t max_samples, ImuLog* log, LongLogReading* reading,
                 std::string* error) {
  reading->max_samples = max_samples;
  return ReadImuLogBounded(path, LogReaderOptions(), reading, log, nullptr, error);
}

TEST(LongLog, LogOfAtMostMaxSamplesIsReadExactly) {
  const std::string path = ::testing::TempDir() + "/long_log_exact.csv";
  WriteStillLog(path, 30.0);  // 3000 rows
  ImuLog whole, bounded;
  LongLogReading reading;
  std::string error;
  ASSERT_TRUE(ReadImuLog(path, LogReaderOptions(), &whole, &error)) << error;
  ASSERT_TRUE(ReadBounded(path, 3000, &bounded, &reading, &error)) << error;
  std::remove(path.c_str());
  ASSERT_EQ(whole.size(), 3000u);
  EXPECT_EQ(reading.samples_averaged, 1u);
  EXPECT_EQ(reading.rows_read, 3000u);
  EXPECT_EQ(reading.Describe(), "");
  EXPECT_EQ(bounded.t, whole.t);
  EXPECT_EQ(bounded.accel, whole.accel);
  EXPECT_EQ(bounded.gyro, whole.gyro);
  EXPECT_EQ(bounded.temperature, whole.temperature);
}

// The entries held stay at most max_samples (their capacity too: the
// vectors do not grow with the log), and each is the mean of its rows.
TEST(LongLog, LongerLogHoldsAtMostMaxSamplesBlockMeans) {
  const std::string path = ::testing::TempDir() + "/long_log_blocks.csv";
  WriteStillLog(path, 200.0);  // 20000 rows
  ImuLog whole, bounded;
  LongLogReading reading;
  std::string error;
  ASSERT_TRUE(ReadImuLog(path, LogReaderOptions(), &whole, &error)) << error;
  ASSERT_TRUE(ReadBounded(path, 1000, &bounded, &reading, &error)) << error;
  std::remove(path.c_str());
  // 1000 entries of 16 rows hold 16000 rows; 20000 rows need blocks of 32
  // (625 entries).
  EXPECT_EQ(reading.samples_averaged, 32u);
  EXPECT_EQ(reading.rows_read, 20000u);
  ASSERT_EQ(bounded.size(), 625u);
  EXPECT_LE(bounded.t.capacity(), 1000u);
  EXPECT_LE(bounded.accel.capacity(), 1000u);
  EXPECT_LE(bounded.gyro.capacity(), 1000u);
  EXPECT_LE(bounded.temperature.capacity(), 1000u);
  const size_t b = reading.samples_averaged;
  for (size_t k = 0; k < bounded.size(); ++k) {
    double t = 0.0, temperature = 0.0;
    Eigen::Vector3d accel = Eigen::Vector3d::Zero(), gyro = Eigen::Vector3d::Zero();
    for (size_t i = k * b; i < (k + 1) * b; ++i) {
      t += whole.t[i];
      accel += whole.accel[i];
      gyro += whole.gyro[i];
      temperature += whole.temperature[i];
    }
    const double inv = 1.0 / static_cast<double>(b);
    ASSERT_NEAR(bounded.t[k], t * inv, 1e-12 * (1.0 + std::abs(t * inv))) << k;
    ASSERT_NEAR((bounded.accel[k] - accel * inv).norm(), 0.0, 1e-12) << k;
    ASSERT_NEAR((bounded.gyro[k] - gyro * inv).norm(), 0.0, 1e-16) << k;
    ASSERT_NEAR(bounded.temperature[k], temperature * inv, 1e-12) << k;
  }
}

// A log made on the fly into a pipe (a FIFO a thread writes) streams in
// bounded memory too: the same entries as from a regular file with the same
// text, its capacity at most max_samples.
TEST(LongLog, PipeStreamsInBoundedMemory) {
  std::string text = "t,ax,ay,az,gx,gy,gz\n";
  for (int i = 0; i < 5000; ++i) {
    text += std::to_string(i * 0.01) + "," + std::to_string(0.001 * (i % 7)) + ",0.2,9.8," +
            std::to_string(1e-3 * (i % 5)) + ",0,0\n";
  }
  const std::string file = ::testing::TempDir() + "/long_log_pipe.csv";
  const std::string fifo = ::testing::TempDir() + "/long_log_pipe.fifo";
  std::ofstream(file) << text;
  std::remove(fifo.c_str());
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&]() { std::ofstream(fifo) << text; });
  ImuLog from_pipe, from_file;
  LongLogReading pipe_reading, file_reading;
  std::string error;
  const bool ok = ReadBounded(fifo, 256, &from_pipe, &pipe_reading, &error);
  writer.join();
  std::remove(fifo.c_str());
  ASSERT_TRUE(ok) << error;
  ASSERT_TRUE(ReadBounded(file, 256, &from_file, &file_reading, &error)) << error;
  std::remove(file.c_str());
  // 256 entries of 16 rows hold 4096 rows: 5000 need means of 32.
  EXPECT_EQ(pipe_reading.samples_averaged, 32u);
  EXPECT_EQ(pipe_reading.rows_read, 5000u);
  EXPECT_EQ(from_pipe.size(), 156u);
  EXPECT_LE(from_pipe.t.capacity(), 256u);
  EXPECT_LE(from_pipe.accel.capacity(), 256u);
  EXPECT_EQ(from_pipe.t, from_file.t);
  EXPECT_EQ(from_pipe.accel, from_file.accel);
  EXPECT_EQ(from_pipe.gyro, from_file.gyro);
}

// A bad row deep in a long log is still one line naming the file and line.
TEST(LongLog, BadRowAfterAveragingNamesFileAndLine) {
  const std::string path = ::testing::TempDir() + "/long_log_bad.csv";
  {
    std::ofstream out(path);
    out << "t,ax,ay,az\n";
    for (int i = 0; i < 5000; ++i) {
      out << i * 0.01 << ",0.1," << (i == 4319 ? "abc" : "0.2") << ",9.8\n";
    }
  }
  ImuLog log;
  LongLogReading reading;
  std::string error;
  EXPECT_FALSE(ReadBounded(path, 64, &log, &reading, &error));
  EXPECT_NE(error.find(path + ":4321:"), std::string::npos) << error;
  EXPECT_NE(error.find("'abc'"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_TRUE(log.t.empty());
  EXPECT_FALSE(ReadBounded(path, 8, &log, &reading, &error));
  std::remove(path.c_str());
  EXPECT_NE(error.find("max_samples"), std::string::npos) << error;
}

// The noise model from means of 4 rows agrees with the one from every row:
// the white noise densities within 5 %, the rate per row.
TEST(LongLog, NoiseFromBlockMeansAgreesWithEveryRow) {
  const std::string path = ::testing::TempDir() + "/long_log_noise.csv";
  WriteStillLog(path, 600.0);  // 60000 rows
  ImuLog whole, bounded;
  LongLogReading every_row, reading;
  std::string error;
  ASSERT_TRUE(ReadBounded(path, 0, &whole, &every_row, &error)) << error;
  ASSERT_TRUE(ReadBounded(path, 16384, &bounded, &reading, &error)) << error;
  std::remove(path.c_str());
  ASSERT_EQ(reading.samples_averaged, 4u);
  NoiseOptions options;
  ImuNoise a, b;
  ASSERT_TRUE(CharacteriseLongLogNoise(whole, every_row, options, &a, &error)) << error;
  ASSERT_TRUE(CharacteriseLongLogNoise(bounded, reading, options, &b, &error)) << error;
  EXPECT_NEAR(b.model.rate_hz, 100.0, 1e-6);
  EXPECT_NEAR(b.model.still_end - b.model.still_begin, a.model.still_end - a.model.still_begin,
              1000.0);
  EXPECT_NE(b.timing.message.find("means of 4 rows"), std::string::npos) << b.timing.message;
  EXPECT_NE(b.message.find("means of 4 rows"), std::string::npos) << b.message;
  // The white noise densities simulated: 2e-3 and 1e-4 per sqrt(Hz).
  for (int axis = 0; axis < 3; ++axis) {
    const double na = a.model.accel[axis].white_noise.value;
    const double nb = b.model.accel[axis].white_noise.value;
    EXPECT_NEAR(nb / na, 1.0, 0.05) << axis;
    EXPECT_NEAR(nb / 2e-3, 1.0, 0.05) << axis;
    const double ga = a.model.gyro[axis].white_noise.value;
    const double gb = b.model.gyro[axis].white_noise.value;
    EXPECT_NEAR(gb / ga, 1.0, 0.05) << axis;
    EXPECT_NEAR(gb / 1e-4, 1.0, 0.05) << axis;
    EXPECT_NEAR(b.accel_curves[axis].points.front().tau, 0.04, 1e-9);
    EXPECT_EQ(b.accel_curves[axis].points.front().m, 4u);
  }
}

// A twelve-pose session with the gyroscope, calibrated from every row and
// from means of 2 rows: the parameters agree within their standard
// deviations, and the warning says what was done.
TEST(LongLog, CalibrationFromBlockMeansAgreesWithEveryRow) {
  SimulatorOptions sim;
  sim.hold_seconds = 4.0;
  sim.initial_still_seconds = 4.0;
  SimulatedSession session;
  std::string error;
  ASSERT_TRUE(Simulate(sim, 21, &session, &error)) << error;
  const std::string path = ::testing::TempDir() + "/long_log_poses.csv";
  ASSERT_TRUE(WriteImuLogCsv(session.log, path, &error)) << error;
  const size_t rows = session.log.size();
  Config config;
  config.calibration.gravity.gravity = session.gravity;
  config.gyro.parameterization = GyroParameterization::kFull;
  Calibration c[2];
  for (int k = 0; k < 2; ++k) {
    // The second holds at most 3/4 of the rows: means of 2 rows.
    PipelineInput input;
    LongLogReading reading;
    ASSERT_TRUE(ReadBounded(path, k == 0 ? 0 : rows * 3 / 4, &input.log, &reading, &error))
        << error;
    EXPECT_EQ(reading.samples_averaged, k == 0 ? 1u : 2u);
    ASSERT_TRUE(RunCalibration(config, input, &c[k])) << c[k].message;
    AddLongLogWarning(reading, &c[k]);
  }
  std::remove(path.c_str());
  // Each parameter within its standard deviation (bias) or two (matrix) of
  // the calibration from every row; a held parameter (no deviation) equal.
  auto near = [](double b, double a, double sigma, const std::string& what) {
    if (std::isnan(sigma)) {
      EXPECT_EQ(b, a) << what;
    } else {
      EXPECT_NEAR(b, a, sigma) << what;
    }
  };
  const AccelCalibration& a = c[0].accel;
  const AccelCalibration& b = c[1].accel;
  ASSERT_TRUE(c[0].gyro.estimated && c[1].gyro.estimated);
  const GyroCalibration& ga = c[0].gyro;
  const GyroCalibration& gb = c[1].gyro;
  for (int i = 0; i < 3; ++i) {
    near(b.model.bias[i], a.model.bias[i], a.bias_std[i], "b_a " + std::to_string(i));
    near(gb.model.bias[i], ga.model.bias[i], ga.bias_std[i], "b_g " + std::to_string(i));
    for (int j = 0; j < 3; ++j) {
      const std::string at = std::to_string(i) + std::to_string(j);
      near(b.model.matrix()(i, j), a.model.matrix()(i, j), 2.0 * a.matrix_std(i, j), "M_a " + at);
      near(gb.model.matrix(i, j), ga.model.matrix(i, j), 2.0 * ga.matrix_std(i, j), "M_g " + at);
    }
  }
  bool said = false;
  for (const std::string& w : c[1].warnings) said |= w.find("means of 2 rows") != std::string::npos;
  EXPECT_TRUE(said);
}

}  // namespace
}  // namespace gravcal
