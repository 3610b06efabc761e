// Speed of reading contract CSV logs: the target is >= 150 MB/s on one core.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "gravcal/io/log_reader.h"
#include "test_util.h"

namespace gravcal {
namespace {

// Writes (once per process) a contract CSV of about `megabytes` MB with
// realistic values: t with 6 decimals at 100 Hz, accelerometer in m/s^2 and
// gyroscope in rad/s, printed as loggers do (6 to 9 significant digits).
const std::string& TestFile(int megabytes) {
  static std::string paths[2];
  std::string& path = paths[megabytes > 50 ? 1 : 0];
  if (!path.empty()) return path;
  path = testing_util::ScratchFolder() + "gravcal_log_reader_benchmark_" +
         std::to_string(getpid()) + "_" + std::to_string(megabytes) + "mb.csv";
  std::string text = "t,ax,ay,az,gx,gy,gz\n";
  const size_t target = static_cast<size_t>(megabytes) * 1000 * 1000;
  text.reserve(target + 256);
  char line[256];
  unsigned state = 12345;
  auto noise = [&state]() {
    state = state * 1664525u + 1013904223u;
    return (static_cast<double>(state >> 8) / 16777216.0 - 0.5);
  };
  for (long i = 0; text.size() < target; ++i) {
    const double t = 1700000000.0 + i * 0.01;
    const double phase = i * 1e-4;
    const int n = std::snprintf(line, sizeof(line), "%.6f,%.7f,%.7f,%.7f,%.8f,%.8f,%.8f\n", t,
                                9.80665 * std::sin(phase) + 0.02 * noise(), -0.12 + 0.02 * noise(),
                                9.80665 * std::cos(phase) + 0.02 * noise(), 0.003 * noise(),
                                -0.0021 + 0.003 * noise(), 0.0014 + 0.003 * noise());
    text.append(line, static_cast<size_t>(n));
  }
  std::string error;
  if (!WriteFileAtomically(path, text, &error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    path.clear();
  }
  return path;
}

size_t FileSize(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return 0;
  std::fseek(f, 0, SEEK_END);
  const long size = std::ftell(f);
  std::fclose(f);
  return size > 0 ? static_cast<size_t>(size) : 0;
}

void BM_ReadImuLogCsv(benchmark::State& state) {
  const std::string& path = TestFile(static_cast<int>(state.range(0)));
  if (path.empty()) {
    state.SkipWithError("cannot write the test file");
    return;
  }
  const size_t bytes = FileSize(path);
  const LogReaderOptions options;
  for (auto _ : state) {
    ImuLog log;
    std::string error;
    if (!ReadImuLog(path, options, &log, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
    benchmark::DoNotOptimize(log.t.data());
    state.counters["samples"] = static_cast<double>(log.size());
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) * static_cast<int64_t>(bytes));
}
BENCHMARK(BM_ReadImuLogCsv)->Arg(10)->Arg(100)->Unit(benchmark::kMillisecond);

void BM_WriteImuLogCsv(benchmark::State& state) {
  const std::string& input = TestFile(10);
  ImuLog log;
  std::string error;
  if (input.empty() || !ReadImuLog(input, LogReaderOptions(), &log, &error)) {
    state.SkipWithError("cannot read the test file");
    return;
  }
  const std::string output = input + ".out";
  for (auto _ : state) {
    if (!WriteImuLogCsv(log, output, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(FileSize(output)));
  std::remove(output.c_str());
}
BENCHMARK(BM_WriteImuLogCsv)->Unit(benchmark::kMillisecond);

// Removes the generated files when the program ends.
struct Cleanup {
  ~Cleanup() {
    for (int megabytes : {10, 100}) {
      const std::string path = testing_util::ScratchFolder() + "gravcal_log_reader_benchmark_" +
                               std::to_string(getpid()) + "_" + std::to_string(megabytes) +
                               "mb.csv";
      std::remove(path.c_str());
    }
  }
} cleanup;

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
