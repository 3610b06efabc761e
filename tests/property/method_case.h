// The one property test of every calibration method, in the spirit of
// Sophus's LieGroupTests<>: a MethodCase says how to simulate a session with
// known truth from a seed, how to calibrate it, and how to read (name,
// error, sigma) per estimated parameter from the Calibration against the
// truth; RunMethodCase runs it over N seeds (on several threads) and feeds
// a SigmaCheck, whose ExpectHonest is the two-sided check of
// tests/sigma_check.h (|mean z| and rms z inside the 99.9 % band for N).
//
// The seeds come from the environment, so the same code is the ordinary
// ctest entry (modest N) and the large-seed one (N >= 400, ctest label
// large_seed):
//   GRAVCAL_PROPERTY_SEEDS       "N" (seeds 1..N) or "F:N" (seeds F..F+N-1);
//                                default kDefaultSeeds from seed 1
//   GRAVCAL_PROPERTY_THREADS     worker threads (default: the cores, at most 2)
#ifndef GRAVCAL_TESTS_PROPERTY_METHOD_CASE_H_
#define GRAVCAL_TESTS_PROPERTY_METHOD_CASE_H_

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "gravcal/core/calibration.h"
#include "gravcal/core/rate_table_segment.h"
#include "gravcal/simulation/simulator.h"
#include "gravcal/workflows/config.h"
#include "sigma_check.h"

namespace gravcal {
namespace testing_util {

// Seeds per case of the ordinary run: enough for the band to catch sigmas
// 1.6 times too small or too large (rms band [0.67, 1.32] at N = 40).
constexpr int kDefaultSeeds = 40;

// One estimated parameter of one seed: estimate - truth and the reported
// standard deviation (NaN when the method reports none).
struct ParameterError {
  std::string name;
  double error = 0.0;
  double sigma = 0.0;
};

// What a simulation gives a method: the sensor session with its truth, and
// the side inputs some methods take.
struct SimulatedInput {
  SimulatedSession session;
  // Rate-table profile: the constant-rate segments with their true rates.
  std::vector<RateTableSegment> segments;
};

struct MethodCase {
  // Shown in failure messages and the table, e.g. "twelve_position/affine".
  std::string name;
  // The shipped configuration of the method (configs/*.yaml loaded with
  // LoadConfigFile), with the changes the case states next to it.
  Config config;
  // Simulates seed `seed` as `gravcal simulate` would with `config`.
  std::function<bool(const Config& config, uint64_t seed, SimulatedInput* input,
                     std::string* error)>
      simulate;
  // Calibrates the simulated input; false with calibration->message.
  std::function<bool(const Config& config, const SimulatedInput& input, uint64_t seed,
                     Calibration* calibration)>
      calibrate;
  // Appends (name, error, sigma) of every parameter the case checks.
  std::function<void(const Calibration& calibration, const SimulatedInput& input,
                     std::vector<ParameterError>* errors)>
      extract;
  // Parameters measured to fail the check (the case says how, with the
  // numbers): still accumulated and printed in their own table, not
  // asserted, so the suite passes while the finding stays visible. Empty
  // unless a method is known to be wrong there.
  std::vector<std::string> known_failures;
};

inline int EnvInt(const char* name, int fallback) {
  const char* value = std::getenv(name);
  return value != nullptr && *value != '\0' ? std::atoi(value) : fallback;
}

// `name` as a gtest parameter name: every character that is not a letter
// or a digit becomes '_'.
inline std::string TestParameterName(std::string name) {
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

// The first seed and the number of seeds of GRAVCAL_PROPERTY_SEEDS.
inline void PropertySeeds(int* first, int* count) {
  *first = 1;
  *count = kDefaultSeeds;
  const char* value = std::getenv("GRAVCAL_PROPERTY_SEEDS");
  if (value == nullptr || *value == '\0') return;
  const std::string text = value;
  const size_t colon = text.find(':');
  if (colon == std::string::npos) {
    *count = std::atoi(text.c_str());
  } else {
    *first = std::atoi(text.substr(0, colon).c_str());
    *count = std::atoi(text.substr(colon + 1).c_str());
  }
}
inline int PropertyThreads() {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, EnvInt("GRAVCAL_PROPERTY_THREADS", std::min(cores, 2)));
}

// The outcome of one seed.
struct SeedOutcome {
  uint64_t seed = 0;
  bool ok = false;
  std::string message;
  std::vector<ParameterError> errors;
};

inline SeedOutcome RunSeed(const MethodCase& method, uint64_t seed) {
  SeedOutcome out;
  out.seed = seed;
  SimulatedInput input;
  std::string error;
  if (!method.simulate(method.config, seed, &input, &error)) {
    out.message = "simulate: " + error;
    return out;
  }
  Calibration calibration;
  if (!method.calibrate(method.config, input, seed, &calibration)) {
    out.message = "calibrate: " + calibration.message;
    return out;
  }
  method.extract(calibration, input, &out.errors);
  out.ok = true;
  return out;
}

// run(seed) for the seeds [first, first + count) on `threads` threads; the
// results in seed order, so what the caller makes of them does not depend
// on the number of threads. `run` must not use gtest's ASSERT_* (a failed
// one would end only its thread's call); it returns what went wrong.
template <typename Run>
auto RunSeeds(int first, int count, int threads, const Run& run)
    -> std::vector<decltype(run(first))> {
  std::vector<decltype(run(first))> outcomes(std::max(count, 0));
  std::atomic<int> next{0};
  auto work = [&]() {
    for (int i = next++; i < count; i = next++) outcomes[i] = run(first + i);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  return outcomes;
}

// Runs seeds [first, first + count) on `threads` threads and adds every
// seed's errors to `check` in seed order (the result does not depend on the
// number of threads), those of method.known_failures to `known` instead.
// Returns the seeds that failed to simulate or calibrate.
inline std::vector<SeedOutcome> RunMethodCase(const MethodCase& method, int first, int count,
                                              int threads, SigmaCheck* check, SigmaCheck* known) {
  const std::vector<SeedOutcome> outcomes = RunSeeds(first, count, threads, [&](int seed) {
    return RunSeed(method, static_cast<uint64_t>(seed));
  });
  std::vector<SeedOutcome> failed;
  for (const SeedOutcome& o : outcomes) {
    if (!o.ok) {
      failed.push_back(o);
      continue;
    }
    for (const ParameterError& e : o.errors) {
      const bool is_known = std::find(method.known_failures.begin(), method.known_failures.end(),
                                      e.name) != method.known_failures.end();
      (is_known ? known : check)->Add(e.name, e.error, e.sigma);
    }
  }
  return failed;
}

}  // namespace testing_util
}  // namespace gravcal

#endif  // GRAVCAL_TESTS_PROPERTY_METHOD_CASE_H_
