// Handheld Kalman calibration: filter throughput in samples per second, and
// (printed before the timings) the accuracy of each method on the same
// simulated IMU: the handheld filter against the classical baselines
// (six-position accelerometer fit, gyroscope rate table).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>

#include "gravcal/methods/handheld_kalman.h"
#include "gravcal/methods/rate_table.h"
#include "gravcal/methods/twelve_position.h"
#include "gravcal/simulation/handheld_simulator.h"

namespace gravcal {
namespace {

SimulatorOptions Sensor(double sample_rate, double misalignment) {
  SimulatorOptions sensor;
  sensor.raw_counts = false;
  sensor.sample_rate = sample_rate;
  sensor.accel_bias_std = 0.2;
  sensor.accel_misalignment_std = misalignment;
  sensor.gyro_misalignment_std = misalignment;
  return sensor;
}

HandheldKalmanOptions FilterOptions(const SimulatorOptions& sensor, int passes) {
  HandheldKalmanOptions options;
  options.gravity.gravity = sensor.gravity;
  options.accel_noise_density = sensor.accel_noise / std::sqrt(sensor.sample_rate);
  options.gyro_noise_density = sensor.gyro_noise / std::sqrt(sensor.sample_rate);
  options.passes = passes;
  return options;
}

// Throughput on a default handheld session (58 s) at 200 Hz; the counter is
// log samples per second of CPU time (each pass processes every sample).
void BM_HandheldKalman(benchmark::State& state) {
  const SimulatorOptions sensor = Sensor(200.0, 0.0);
  MotionSession session;
  std::string error;
  if (!SimulateMotion(sensor, MotionOptions(), 1, &session, &error)) {
    state.SkipWithError(error.c_str());
    return;
  }
  const HandheldKalmanOptions options = FilterOptions(sensor, static_cast<int>(state.range(0)));
  Calibration c;
  for (auto _ : state) {
    const bool ok = CalibrateHandheld(session.sensor.log, options, &c);
    benchmark::DoNotOptimize(ok);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(session.sensor.log.size()));
  state.counters["samples"] = static_cast<double>(session.sensor.log.size());
}
BENCHMARK(BM_HandheldKalman)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

// Accuracy over `seeds` IMUs: RMS error and mean reported sigma per group
// (accel bias m/s^2, accel scale, gyro bias deg/s, gyro scale; scale as the
// relative error of the diagonal of M).
struct Accuracy {
  double sum_err2[4] = {};
  double sum_sigma[4] = {};
  int n[4] = {};
  void Add(int group, double error, double sigma) {
    sum_err2[group] += error * error;
    sum_sigma[group] += sigma;
    ++n[group];
  }
  void Print(const char* name) const {
    std::printf("| %-34s |", name);
    for (int g = 0; g < 4; ++g) {
      if (n[g] == 0) {
        std::printf(" - |");
      } else {
        std::printf(" %.2e (%.2e) |", std::sqrt(sum_err2[g] / n[g]), sum_sigma[g] / n[g]);
      }
    }
    std::printf("\n");
  }
};

void CompareMethods(double misalignment, int seeds) {
  const SimulatorOptions sensor = Sensor(100.0, misalignment);
  const double deg = 180.0 / M_PI;
  Accuracy handheld, cross, six, table;
  for (int seed = 1; seed <= seeds; ++seed) {
    std::string error;
    // The same seed gives the same truth IMU in both simulators.
    MotionSession hand, rates;
    MotionOptions motion;
    if (!SimulateMotion(sensor, motion, seed, &hand, &error)) return;
    motion.profile = MotionProfile::kRateTable;
    motion.rate_dps = 60.0;
    motion.seconds_per_axis = 60.0;
    if (!SimulateMotion(sensor, motion, seed, &rates, &error)) return;
    SimulatorOptions six_sensor = sensor;
    six_sensor.scheme = {PoseScheme::kSix};
    six_sensor.hold_seconds = 60.0;
    SimulatedSession faces;
    if (!Simulate(six_sensor, seed, &faces, &error)) return;
    const AccelModel& accel_truth = hand.sensor.accel_truth;
    const GyroModel& gyro_truth = hand.sensor.gyro_truth;

    Calibration c;
    if (!CalibrateHandheld(hand.sensor.log, FilterOptions(sensor, 2), &c)) return;
    for (int i = 0; i < 3; ++i) {
      handheld.Add(0, c.accel.model.bias(i) - accel_truth.bias(i), c.accel.bias_std(i));
      handheld.Add(1, c.accel.model.upper(i, i) / accel_truth.matrix()(i, i) - 1.0,
                   c.accel.matrix_std(i, i) / accel_truth.matrix()(i, i));
      handheld.Add(2, deg * (c.gyro.model.bias(i) - gyro_truth.bias(i)), deg * c.gyro.bias_std(i));
      handheld.Add(3, c.gyro.model.matrix(i, i) / gyro_truth.matrix(i, i) - 1.0,
                   c.gyro.matrix_std(i, i) / gyro_truth.matrix(i, i));
    }
    // With cross-axis terms the accelerometer axes define the body frame:
    // truth accelerometer U (M = R U), gyroscope R^T M_g.
    HandheldKalmanOptions cross_options = FilterOptions(sensor, 2);
    cross_options.accel_terms = SensorErrorTerms::ScaleAndUpperCrossAxis();
    cross_options.gyro_terms = SensorErrorTerms::ScaleAndCrossAxis();
    if (!CalibrateHandheld(hand.sensor.log, cross_options, &c)) return;
    const Eigen::Matrix3d gyro_body = accel_truth.rotation.transpose() * gyro_truth.matrix;
    for (int i = 0; i < 3; ++i) {
      cross.Add(0, c.accel.model.bias(i) - accel_truth.bias(i), c.accel.bias_std(i));
      cross.Add(1, c.accel.model.upper(i, i) / accel_truth.upper(i, i) - 1.0,
                c.accel.matrix_std(i, i) / accel_truth.upper(i, i));
      cross.Add(2, deg * (c.gyro.model.bias(i) - gyro_truth.bias(i)), deg * c.gyro.bias_std(i));
      cross.Add(3, c.gyro.model.matrix(i, i) / gyro_body(i, i) - 1.0,
                c.gyro.matrix_std(i, i) / gyro_body(i, i));
    }
    CalibrationOptions options;
    options.gravity.gravity = sensor.gravity;
    options.refinement.parameterization = AccelParameterization::kScale;
    Calibration f;
    if (!CalibrateAccelerometer(faces.log, options, &f)) return;
    for (int i = 0; i < 3; ++i) {
      six.Add(0, f.accel.model.bias(i) - accel_truth.bias(i), f.accel.bias_std(i));
      six.Add(1, f.accel.model.matrix()(i, i) / accel_truth.matrix()(i, i) - 1.0,
              f.accel.matrix_std(i, i) / accel_truth.matrix()(i, i));
    }
    RateTableResult r;
    if (!CalibrateRateTable(rates.sensor.log, rates.segments, &r)) return;
    for (int i = 0; i < 3; ++i) {
      table.Add(2, deg * (r.gyro.model.bias(i) - gyro_truth.bias(i)), deg * r.gyro.bias_std(i));
      table.Add(3, r.gyro.model.matrix(i, i) / gyro_truth.matrix(i, i) - 1.0,
                r.gyro.matrix_std(i, i) / gyro_truth.matrix(i, i));
    }
  }
  std::printf("\nAccuracy over %d simulated IMUs, misalignment %.3f rad: RMS error (mean sigma)\n",
              seeds, misalignment);
  std::printf("| method | accel bias m/s^2 | accel scale | gyro bias deg/s | gyro scale |\n");
  std::printf("|---|---|---|---|---|\n");
  handheld.Print("handheld Kalman (58 s by hand)");
  cross.Print("handheld Kalman, hk_cross_axis");
  six.Print("six-position, 60 s per face");
  table.Print("rate table, 60 deg/s, 60 s per direction");
}

}  // namespace
}  // namespace gravcal

int main(int argc, char** argv) {
  gravcal::CompareMethods(0.0, 10);
  gravcal::CompareMethods(0.005, 10);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
