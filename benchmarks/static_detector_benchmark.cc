// Throughput of the static detector on a long synthetic counts log.
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "gravcal/core/position.h"
#include "gravcal/detection/static_detector.h"
#include "util/random_vector.h"

namespace gravcal {
namespace {

// `n` samples at 100 Hz: 10 s still poses joined by 3 s rotations, raw int16
// counts with white noise, accelerometer and gyroscope.
ImuLog MakeBenchmarkLog(size_t n) {
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  ImuLog log;
  log.source = "benchmark";
  log.t.reserve(n);
  log.accel.reserve(n);
  log.gyro.reserve(n);
  const double rate = 100.0;
  const size_t still = 1000;
  const size_t move = 300;
  Eigen::Vector3d up(0.0, 0.0, 1.0);
  while (log.size() < n) {
    const Eigen::Vector3d next = internal::DrawVector3([&] { return uniform(rng); }).normalized();
    const Eigen::Vector3d axis = up.cross(next).normalized();
    const double angle = std::acos(std::max(-1.0, std::min(1.0, up.dot(next))));
    for (size_t i = 0; i < still + move && log.size() < n; ++i) {
      Eigen::Vector3d f = up;
      Eigen::Vector3d w = Eigen::Vector3d::Zero();
      if (i >= still) {
        const double tau = (i - still + 0.5) / move;
        f = Eigen::AngleAxisd(angle * 0.5 * (1.0 - std::cos(M_PI * tau)), axis) * up;
        w = -axis * angle * 0.5 * M_PI * std::sin(M_PI * tau) * rate / move;
      }
      log.t.push_back(log.size() / rate);
      Eigen::Vector3d a = f * 16384.0 + Eigen::Vector3d(120.0, -80.0, 300.0);
      Eigen::Vector3d g = w * 180.0 / M_PI * 131.0 + Eigen::Vector3d(-40.0, 20.0, 10.0);
      for (int k = 0; k < 3; ++k) {
        a[k] = std::round(a[k] + 30.0 * noise(rng));
        g[k] = std::round(g[k] + 15.0 * noise(rng));
      }
      log.accel.push_back(a);
      log.gyro.push_back(g);
    }
    up = next;
  }
  return log;
}

void BM_DetectStaticIntervals(benchmark::State& state) {
  const ImuLog log = MakeBenchmarkLog(static_cast<size_t>(state.range(0)));
  const StaticDetectorOptions options;
  StaticDetection detection;
  for (auto _ : state) {
    const bool ok = DetectStaticIntervals(log, options, &detection);
    benchmark::DoNotOptimize(ok);
    benchmark::DoNotOptimize(detection.intervals.data());
  }
  if (detection.intervals.empty()) state.SkipWithError("no interval found");
  state.counters["intervals"] = static_cast<double>(detection.intervals.size());
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(log.size()));
}
BENCHMARK(BM_DetectStaticIntervals)->Arg(1000000)->Unit(benchmark::kMillisecond);

void BM_PositionsFromIntervals(benchmark::State& state) {
  const ImuLog log = MakeBenchmarkLog(100000);
  StaticDetection detection;
  DetectStaticIntervals(log, StaticDetectorOptions(), &detection);
  for (auto _ : state) {
    std::vector<Position> positions = PositionsFromIntervals(detection.intervals);
    benchmark::DoNotOptimize(positions.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(detection.intervals.size()));
}
BENCHMARK(BM_PositionsFromIntervals);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
