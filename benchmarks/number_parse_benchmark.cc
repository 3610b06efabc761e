// Issue 39: the number parser of the text readers (util/numbers.h
// ParseNumber) beside std::from_chars (libstdc++) and fast_float alone, on
// the tokens sensor logs hold: raw counts, fixed decimals, short mantissas
// with exponents (a logger's "%e"), and 17-digit round-trip numbers.
// Bytes/s counts the tokens' characters.
#include <benchmark/benchmark.h>
#include <fast_float/fast_float.h>

#include <charconv>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "util/numbers.h"

namespace gravcal {
namespace {

// 4096 tokens of one kind, each ended by a comma.
const std::string& Tokens(int kind) {
  static std::string texts[4];
  std::string& text = texts[kind];
  if (!text.empty()) return text;
  std::mt19937_64 rng(kind);
  std::uniform_real_distribution<double> value(-20.0, 20.0);
  const char* formats[] = {"%.0f", "%.7f", "%.7e", "%.17g"};
  char token[64];
  for (int i = 0; i < 4096; ++i) {
    const double x = kind == 0 ? value(rng) * 1638.4 : value(rng);
    std::snprintf(token, sizeof(token), formats[kind], x);
    text += token;
    text += ',';
  }
  return text;
}

template <typename Parse>
void Run(benchmark::State& state, Parse parse) {
  const std::string& text = Tokens(static_cast<int>(state.range(0)));
  const char* const end = text.data() + text.size();
  double sum = 0.0;
  for (auto _ : state) {
    for (const char* p = text.data(); p < end;) {
      double x = 0.0;
      p = parse(p, end, &x) + 1;
      sum += x;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * text.size()));
  state.SetLabel(std::vector<const char*>{"counts", "%.7f", "%.7e", "%.17g"}[state.range(0)]);
}

void BM_ParseNumber(benchmark::State& state) {
  Run(state, [](const char* p, const char* end, double* x) {
    return internal::ParseNumber(p, end, x).ptr;
  });
}
void BM_StdFromChars(benchmark::State& state) {
  Run(state,
      [](const char* p, const char* end, double* x) { return std::from_chars(p, end, *x).ptr; });
}
void BM_FastFloat(benchmark::State& state) {
  Run(state, [](const char* p, const char* end, double* x) {
    return fast_float::from_chars(p, end, *x).ptr;
  });
}
BENCHMARK(BM_ParseNumber)->DenseRange(0, 3);
BENCHMARK(BM_StdFromChars)->DenseRange(0, 3);
BENCHMARK(BM_FastFloat)->DenseRange(0, 3);

}  // namespace
}  // namespace gravcal

BENCHMARK_MAIN();
