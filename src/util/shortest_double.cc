#include "util/shortest_double.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

// fmt's Dragonbox, compiled into this file only (no libfmt at run time).
#define FMT_HEADER_ONLY
#include <fmt/format.h>

namespace gravcal {
namespace internal {
namespace {

constexpr char kPairs[] =
    "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
    "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
    "8081828384858687888990919293949596979899";

// Writes the 8 digits of x < 10^8 (leading zeros included) at p: four
// independent pairs, not a chain of divisions.
inline void WriteEightDigits(uint32_t x, char* p) {
  const uint32_t high = x / 10000, low = x % 10000;
  std::memcpy(p, kPairs + 2 * (high / 100), 2);
  std::memcpy(p + 2, kPairs + 2 * (high % 100), 2);
  std::memcpy(p + 4, kPairs + 2 * (low / 100), 2);
  std::memcpy(p + 6, kPairs + 2 * (low % 100), 2);
}

// Writes the `count` digits of x at p (x has exactly that many digits),
// eight at a time from the right.
inline void WriteDigits(uint64_t x, int count, char* p) {
  char* end = p + count;
  while (x >= 100000000) {
    const uint64_t q = x / 100000000;
    end -= 8;
    WriteEightDigits(static_cast<uint32_t>(x - q * 100000000), end);
    x = q;
  }
  uint32_t y = static_cast<uint32_t>(x);
  while (y >= 100) {
    end -= 2;
    std::memcpy(end, kPairs + 2 * (y % 100), 2);
    y /= 100;
  }
  if (y >= 10) {
    std::memcpy(end - 2, kPairs + 2 * y, 2);
  } else {
    end[-1] = static_cast<char>('0' + y);
  }
}

}  // namespace

char* WriteShortestDouble(double v, char* p) {
  // Zero, infinities, NaN and integers from 10^16 on (where the fixed form
  // holds the exact value, not the shortest digits) go to the library.
  if (!std::isfinite(v) || v == 0.0 || std::fabs(v) >= 1e16) {
    return std::to_chars(p, p + kMaxShortestDouble, v).ptr;
  }
  const auto decimal = fmt::detail::dragonbox::to_decimal(v);
  const uint64_t digits = decimal.significand;
  const int k = fmt::detail::count_digits(digits);
  const int e = decimal.exponent;  // v = digits * 10^e
  const int sci_exponent = e + k - 1;
  if (std::signbit(v)) *p++ = '-';
  // Lengths without the sign: scientific d[.ddd]e+XX, fixed as printf %f.
  const int abs_exponent = sci_exponent < 0 ? -sci_exponent : sci_exponent;
  const int sci_length = k + (k > 1 ? 1 : 0) + 2 + (abs_exponent >= 100 ? 3 : 2);
  int fixed_length;
  if (e >= 0) {
    fixed_length = k + e;
  } else if (sci_exponent >= 0) {
    fixed_length = k + 1;
  } else {
    fixed_length = 1 - sci_exponent + k;  // "0." and -sci_exponent - 1 zeros
  }
  if (fixed_length <= sci_length) {
    if (e >= 0) {
      WriteDigits(digits, k, p);
      std::memset(p + k, '0', static_cast<size_t>(e));
      return p + k + e;
    }
    if (sci_exponent >= 0) {
      // ddd.ddd: the integer part has sci_exponent + 1 digits.
      const int whole = sci_exponent + 1;
      WriteDigits(digits, k, p + 1);
      std::memmove(p, p + 1, static_cast<size_t>(whole));
      p[whole] = '.';
      return p + k + 1;
    }
    const int zeros = -sci_exponent - 1;
    p[0] = '0';
    p[1] = '.';
    std::memset(p + 2, '0', static_cast<size_t>(zeros));
    WriteDigits(digits, k, p + 2 + zeros);
    return p + 2 + zeros + k;
  }
  // d.ddde+XX
  WriteDigits(digits, k, p + 1);
  p[0] = p[1];
  if (k > 1) {
    p[1] = '.';
    p += k + 1;
  } else {
    p += 1;
  }
  *p++ = 'e';
  *p++ = sci_exponent < 0 ? '-' : '+';
  if (abs_exponent >= 100) {
    *p++ = static_cast<char>('0' + abs_exponent / 100);
    std::memcpy(p, kPairs + 2 * (abs_exponent % 100), 2);
  } else {
    std::memcpy(p, kPairs + 2 * abs_exponent, 2);
  }
  return p + 2;
}

}  // namespace internal
}  // namespace gravcal
