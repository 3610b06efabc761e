// WriteShortestDouble (util/shortest_double.h), the writer of apply's and
// the simulator's CSV, against std::to_chars, which wrote them before: the
// same characters for random bit patterns, sensor-like decimals, integers,
// powers of two and the neighbours of powers of ten.
#include "util/shortest_double.h"

#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>

namespace gravcal {
namespace {

std::string Library(double v) {
  char text[64];
  return std::string(text, std::to_chars(text, text + sizeof(text), v).ptr);
}

std::string Ours(double v) {
  char text[internal::kMaxShortestDouble];
  return std::string(text, internal::WriteShortestDouble(v, text));
}

TEST(ShortestDouble, SameTextAsToChars) {
  std::mt19937_64 rng(20261127);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  int checked = 0;
  auto check = [&](double v) {
    ASSERT_EQ(Ours(v), Library(v)) << "bits of the value: " << std::hex << [&] {
      uint64_t b;
      std::memcpy(&b, &v, sizeof(b));
      return b;
    }();
    ++checked;
  };
  for (int i = 0; i < 100000; ++i) {
    const uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof(v));
    check(v);
    check(unit(rng) * std::pow(10.0, static_cast<int>(rng() % 44) - 22));
    const double decimal =
        std::round(unit(rng) * 1e7) / std::pow(10.0, static_cast<int>(rng() % 12));
    check(decimal);
    check(std::nextafter(decimal, 1e300));
    check(static_cast<double>(static_cast<int64_t>(rng() >> (rng() % 64))));
    check(std::ldexp(1.0, static_cast<int>(rng() % 2098) - 1074));
  }
  for (int exponent = -325; exponent <= 308; ++exponent) {
    for (int d = 1; d < 10; ++d) {
      const double v = d * std::pow(10.0, exponent);
      check(v);
      check(-std::nextafter(v, 0.0));
      check(std::nextafter(v, 1e308));
    }
  }
  const double limits[] = {0.0,
                           -0.0,
                           std::numeric_limits<double>::infinity(),
                           -std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::quiet_NaN(),
                           std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::min(),
                           std::numeric_limits<double>::denorm_min(),
                           -2.2250738585072014e-308,
                           9007199254740993.0,
                           1e16,
                           9999999999999998.0,
                           123456.0,
                           1e-5,
                           0.0001};
  for (double v : limits) check(v);
  EXPECT_GT(checked, 600000);
}

// Every text fits the stated room and reads back to the same double.
TEST(ShortestDouble, RoundTripsWithinItsRoom) {
  std::mt19937_64 rng(5);
  for (int i = 0; i < 100000; ++i) {
    const uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof(v));
    if (!std::isfinite(v)) continue;
    char text[internal::kMaxShortestDouble];
    char* end = internal::WriteShortestDouble(v, text);
    ASSERT_LE(end - text, internal::kMaxShortestDouble);
    double back = 0.0;
    ASSERT_EQ(std::from_chars(text, end, back).ptr, end);
    ASSERT_EQ(std::memcmp(&back, &v, sizeof(v)), 0) << std::string(text, end);
  }
}

}  // namespace
}  // namespace gravcal
