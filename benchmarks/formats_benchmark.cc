// Reading speed per sample of every log format against the contract CSV
// (issue 19: the bag and MCAP readers should be at least as fast per sample).
// One session of 200 000 samples (100 Hz) is written once as contract CSV by
// gravcal, then as EuRoC CSV, rosbag2 .db3 and ROS 1 bags (none, bz2, lz4)
// by tests/formats/write_formats.py, and as MCAP (plain, zstd, lz4) by
// tests/formats/write_mcap.mjs when <build>/npm_formats has @mcap/core.
// A format whose writer is missing is skipped with a message. The session is
// written under /tmp, or read from GRAVCAL_FORMATS_DIR when set.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "gravcal/io/log_reader.h"
#include "test_util.h"

namespace gravcal {
namespace {

constexpr int kSamples = 200000;

const std::string& Folder() {
  static const std::string folder = [] {
    // GRAVCAL_FORMATS_DIR: a folder already written (the writers take minutes).
    if (const char* ready = std::getenv("GRAVCAL_FORMATS_DIR")) return std::string(ready);
    const std::string dir =
        testing_util::ScratchFolder() + "gravcal_formats_benchmark_" + std::to_string(getpid());
    std::filesystem::create_directories(dir);
    ImuLog log;
    for (int i = 0; i < kSamples; ++i) {
      log.t.push_back(1700000000.0 + i * 0.01);
      const double phase = i * 1e-4;
      log.accel.emplace_back(9.80665 * std::sin(phase), -0.12 + 1e-3 * std::sin(7.0 * i),
                             9.80665 * std::cos(phase));
      log.gyro.emplace_back(1e-3 * std::cos(3.0 * i), -0.0021, 0.0014 + 1e-3 * std::sin(5.0 * i));
    }
    std::string error;
    WriteImuLogCsv(log, dir + "/raw.csv", &error);
    const std::string source = std::filesystem::path(__FILE__).parent_path().parent_path();
    const std::string python =
        "/usr/bin/python3 " + source + "/tests/formats/write_formats.py " + dir + "/raw.csv " + dir;
    if (std::system(python.c_str()) != 0) return dir;
    const char* modules = std::getenv("GRAVCAL_NPM_MODULES");
    if (modules != nullptr) {
      const std::string node = std::string("node ") + source + "/tests/formats/write_mcap.mjs " +
                               modules + " " + dir + "/euroc.csv " + dir;
      if (std::system(node.c_str()) != 0) return dir;
    }
    return dir;
  }();
  return folder;
}

void BM_ReadFormat(benchmark::State& state, const char* file) {
  const std::string path = Folder() + "/" + file;
  if (!std::filesystem::exists(path)) {
    state.SkipWithError((path + " was not written (writer absent)").c_str());
    return;
  }
  int64_t samples = 0;
  for (auto _ : state) {
    ImuLog log;
    std::string error;
    if (!ReadImuLog(path, LogReaderOptions(), &log, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
    samples += static_cast<int64_t>(log.size());
    benchmark::DoNotOptimize(log.t.data());
  }
  state.counters["samples_per_s"] =
      benchmark::Counter(static_cast<double>(samples), benchmark::Counter::kIsRate);
  state.counters["bytes"] = static_cast<double>(std::filesystem::file_size(path));
}

BENCHMARK_CAPTURE(BM_ReadFormat, contract_csv, "contract.csv")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadFormat, euroc_csv, "euroc.csv")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadFormat, rosbag2_db3, "session.db3")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadFormat, ros1_none, "ros1_none.bag")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadFormat, ros1_bz2, "ros1_bz2.bag")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadFormat, ros1_lz4, "ros1_lz4.bag")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadFormat, mcap_plain, "mcap_plain.mcap")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadFormat, mcap_zstd, "mcap_zstd.mcap")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadFormat, mcap_lz4, "mcap_lz4.mcap")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
