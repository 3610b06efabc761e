// Batch calibration throughput: units per second for realistic
// twelve-position sessions (12 poses x 30 s at 100 Hz, raw counts with
// gyroscope and temperature columns, about 40 000 samples) read from CSV
// files, on 1 and 2 threads, and the share of the time spent reading,
// detecting and solving. Target: >= 200 units/s on two cores.
//
// The files are written once to /tmp and are in the page cache when timed:
// this measures parsing, not the disk.
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

#include "gravcal/io/log_reader.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/batch.h"
#include "gravcal/workflows/config.h"
#include "test_util.h"

namespace gravcal {
namespace {

constexpr int kUnits = 32;

// The session files, removed at exit.
struct SessionFiles {
  std::vector<BatchUnit> units;
  ~SessionFiles() {
    for (const BatchUnit& u : units) std::remove(u.path.c_str());
  }
};

const std::vector<BatchUnit>& Units() {
  static const SessionFiles files{[] {
    std::vector<BatchUnit> out;
    SimulatorOptions sim;
    sim.scheme = {PoseScheme::kTwelve};
    sim.hold_seconds = 30.0;
    sim.sample_rate = 100.0;
    const std::string prefix =
        testing_util::ScratchFolder() + "gravcal_batch_benchmark_" + std::to_string(getpid()) + "_";
    for (int k = 0; k < kUnits; ++k) {
      SimulatedSession s;
      std::string error;
      BatchUnit unit;
      unit.id = "unit" + std::to_string(k);
      unit.path = prefix + unit.id + ".csv";
      if (!Simulate(sim, 1000 + k, &s, &error) || !WriteImuLogCsv(s.log, unit.path, &error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return std::vector<BatchUnit>();
      }
      out.push_back(unit);
    }
    return out;
  }()};
  return files.units;
}

Config BaseConfig() {
  Config config;
  config.calibration.gravity.gravity = 9.80665;
  config.calibration.nominal_scale = 9.80665 / 16384.0;
  return config;
}

void BM_CalibrateBatch(benchmark::State& state) {
  const std::vector<BatchUnit>& units = Units();
  if (units.empty()) {
    state.SkipWithError("cannot write the session files");
    return;
  }
  const Config config = BaseConfig();
  BatchOptions options;
  options.threads = static_cast<int>(state.range(0));
  options.keep_calibrations = false;
  BatchTimings sum;
  size_t failed = 0;
  // The process's CPU time (every thread's): per unit it is the cost on a
  // thread whatever the load of the machine, which inflates wall time.
  auto cpu_seconds = [] {
    rusage u;
    getrusage(RUSAGE_SELF, &u);
    return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  };
  const double cpu_start = cpu_seconds();
  for (auto _ : state) {
    std::vector<BatchResult> results;
    std::string error;
    if (!CalibrateBatch(units, config, options, &results, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
    for (const BatchResult& r : results) {
      failed += r.status != BatchStatus::kOk;
      sum.read_seconds += r.timings.read_seconds;
      sum.detect_seconds += r.timings.detect_seconds;
      sum.solve_seconds += r.timings.solve_seconds;
    }
  }
  const double busy = sum.read_seconds + sum.detect_seconds + sum.solve_seconds;
  const double n = static_cast<double>(state.iterations()) * units.size();
  const double cpu = cpu_seconds() - cpu_start;
  state.counters["units_per_s"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
  state.counters["cpu_ms_per_unit"] = 1e3 * cpu / n;
  state.counters["units_per_cpu_s"] = n / cpu;
  state.counters["read_share"] = sum.read_seconds / busy;
  state.counters["detect_share"] = sum.detect_seconds / busy;
  state.counters["solve_share"] = sum.solve_seconds / busy;
  state.counters["ms_per_unit_thread"] = 1e3 * busy / n;
  state.counters["failed"] = static_cast<double>(failed);
}
BENCHMARK(BM_CalibrateBatch)->Arg(1)->Arg(2)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
