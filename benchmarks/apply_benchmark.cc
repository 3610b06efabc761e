// Speed of `gravcal apply`'s loop: stream a contract CSV (with gyroscope and
// temperature), correct every sample with every effect term, write the
// corrected CSV. Target: >= 100 MB/s of input CSV on one core.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "gravcal/core/imu_corrector.h"
#include "gravcal/io/files.h"
#include "gravcal/io/imu_stream.h"
#include "test_util.h"
#include "util/shortest_double.h"

namespace gravcal {
namespace {

// A contract CSV of about 60 MB, values printed as loggers do.
const std::string& InputFile() {
  static std::string path;
  if (!path.empty()) return path;
  path = testing_util::ScratchFolder() + "gravcal_apply_benchmark_" + std::to_string(getpid()) +
         ".csv";
  std::string text = "t,ax,ay,az,gx,gy,gz,temp\n";
  const size_t target = size_t{60} * 1000 * 1000;
  text.reserve(target + 256);
  char line[256];
  for (long i = 0; text.size() < target; ++i) {
    const double phase = i * 1e-4;
    const int n = std::snprintf(
        line, sizeof(line), "%.6f,%.7f,%.7f,%.7f,%.8f,%.8f,%.8f,%.3f\n", 1700000000.0 + i * 0.01,
        9.80665 * std::sin(phase), -0.12 + 1e-7 * (i % 97), 9.80665 * std::cos(phase),
        0.003 * std::sin(i * 0.37), -0.0021 + 1e-8 * (i % 89), 0.0014, 25.0 + 1e-5 * i);
    text.append(line, static_cast<size_t>(n));
  }
  std::string error;
  if (!WriteFileAtomically(path, text, &error)) std::fprintf(stderr, "%s\n", error.c_str());
  return path;
}

ImuCorrector FullCorrector() {
  ImuCorrector c;
  c.accel.bias << 0.1, -0.05, 0.2;
  c.accel.upper << 1.01, 0.002, -0.001, 0.0, 0.99, 0.003, 0.0, 0.0, 1.005;
  c.has_gyro = true;
  c.gyro.bias << 0.01, -0.02, 0.003;
  c.gyro.matrix << 1.002, 0.001, 0.0, -0.002, 0.998, 0.001, 0.0, 0.001, 1.001;
  c.effects.Vector(Effect::kAccelTemperatureBias) << 1e-3, -2e-3, 5e-4;
  c.effects.Vector(Effect::kAccelTemperatureScale) << 1e-4, -1e-4, 2e-4;
  c.effects.Vector(Effect::kAccelBiasDrift) << 1e-6, 2e-6, -1e-6;
  c.effects.Vector(Effect::kAccelQuadratic) << 1e-4, 2e-4, -1e-4;
  c.effects.Matrix(Effect::kGyroGSensitivity).setConstant(1e-4);
  c.effects.Vector(Effect::kGyroTemperatureBias) << 1e-4, 2e-4, 3e-4;
  c.effects.Vector(Effect::kGyroBiasDrift) << 1e-7, 1e-7, 1e-7;
  c.effects.reference_temperature = 25.0;
  c.effects.reference_time = 1700000000.0;
  c.active_effects = {Effect::kAccelTemperatureBias, Effect::kAccelTemperatureScale,
                      Effect::kAccelBiasDrift,       Effect::kAccelQuadratic,
                      Effect::kGyroGSensitivity,     Effect::kGyroTemperatureBias,
                      Effect::kGyroBiasDrift};
  return c;
}

void BM_ApplyEveryTerm(benchmark::State& state) {
  const std::string& input = InputFile();
  const std::string output = input + ".out.csv";
  const ImuCorrector corrector = FullCorrector();
  std::string bytes, error;
  ReadFileBytes(input, &bytes, &error);
  for (auto _ : state) {
    ImuCsvStreamReader reader;
    ImuCsvStreamWriter writer;
    if (!reader.Open(input, &error) || !writer.Open(output, true, true, {"benchmark"}, &error)) {
      state.SkipWithError(error.c_str());
      return;
    }
    ImuSample s;
    while (reader.Next(&s, &error)) {
      corrector.CorrectRow(s.temperature, s.t, &s.accel, &s.gyro);
      writer.Write(s, &error);
    }
    if (!error.empty() || !writer.Commit(&error)) {
      state.SkipWithError(error.c_str());
      return;
    }
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(bytes.size()));
  std::remove(output.c_str());
}
BENCHMARK(BM_ApplyEveryTerm)->Unit(benchmark::kMillisecond);

// The writer's share and its limit: one corrected row's eight numbers
// formatted, range(0) = 0 with std::to_chars (the writer before), 1 with
// WriteShortestDouble (the writer now, the same characters). Bytes are
// those written.
void BM_FormatRow(benchmark::State& state) {
  std::vector<double> values;
  for (int i = 0; i < 80000; ++i) {
    const double phase = i * 1e-4;
    values.push_back(1700000000.0 + i * 0.01);
    values.push_back(9.80665 * std::sin(phase) * 1.0012 + 0.1);
    values.push_back(-0.12 * 0.998 + 1e-7 * (i % 97));
    values.push_back(9.80665 * std::cos(phase) * 1.003 - 0.2);
    values.push_back(0.003 * std::sin(i * 0.37) * 1.002 - 0.01);
    values.push_back(-0.0021 + 1e-8 * (i % 89) + 0.02);
    values.push_back(0.0014 * 0.998 - 0.003);
    values.push_back(25.0 + 1e-5 * i);
  }
  char text[64];
  int64_t bytes = 0;
  for (auto _ : state) {
    for (double v : values) {
      char* end = state.range(0) == 0 ? std::to_chars(text, text + sizeof(text), v).ptr
                                      : internal::WriteShortestDouble(v, text);
      bytes += end - text;
      benchmark::DoNotOptimize(text);
    }
  }
  state.SetBytesProcessed(bytes);
}
BENCHMARK(BM_FormatRow)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gravcal

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  std::remove(gravcal::InputFile().c_str());
  return 0;
}
