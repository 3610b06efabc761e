// util/numbers.h (private): a double's infinity, its text as gravcal writes
// it into files, and the one parser of the numbers gravcal reads from text
// (logs, CSV tables, fixture files).
#ifndef GRAVCAL_SRC_UTIL_NUMBERS_H_
#define GRAVCAL_SRC_UTIL_NUMBERS_H_

#include <charconv>
#include <cstdint>
#include <limits>
#include <string>
#include <system_error>

namespace gravcal {
namespace internal {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The shortest decimal text that reads back to the same double.
inline std::string ExactNumber(double v) {
  char text[32];
  return std::string(text, std::to_chars(text, text + sizeof(text), v).ptr);
}

// --- Parsing -----------------------------------------------------------------

// ParseNumber's general path (numbers.cc): fast_float, with the outcome
// std::from_chars gives.
std::from_chars_result ParseNumberSlow(const char* first, const char* last, double* x);
// The nearest double to (-1)^negative mantissa 10^exponent, the number
// [first, end) that ParseNumber read as at most 19 digits, by fast_float's
// Eisel-Lemire step (the rare case it cannot decide goes to ParseNumberSlow,
// which reads the text again).
std::from_chars_result ParseNumberDigits(const char* first, const char* last, const char* end,
                                         uint64_t mantissa, long exponent, bool negative,
                                         double* x);

// Reads the number at the start of [first, last) and says where it ends,
// exactly as std::from_chars(first, last, *x) does (chars_format::general):
// an optional '-' (no '+', no blanks), digits with an optional '.' and an
// optional exponent, or "inf", "infinity", "nan", "nan(...)"; the nearest
// double, ties to even (subnormals included); errc::invalid_argument when no
// number starts there, errc::result_out_of_range (*x unchanged) when a
// finite text overflows to infinity or a nonzero one underflows to zero.
// tests/number_parse_test.cc holds it to strtod and std::from_chars.
//
// Sensor logs are short decimals (raw counts "-1234", "0.01234",
// "3.3108000e+04"): those with at most 19 digits, a value below 2^53 and a
// decimal exponent within +-22 are read here in one pass, exactly (Clinger:
// the digits and the power of ten are exact doubles, so one correctly
// rounded multiply or divide is the nearest double); other numbers of at
// most 19 digits go on to fast_float's Eisel-Lemire step with the digits
// read here, the rest to fast_float from the start (exact for every input).
inline std::from_chars_result ParseNumber(const char* first, const char* last, double* x) {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  auto digit = [](char c) { return static_cast<unsigned>(c - '0'); };
  const char* p = first;
  const bool negative = p < last && *p == '-';
  if (negative) ++p;
  uint64_t mantissa = 0;
  const char* const integer = p;
  while (p < last && digit(*p) < 10u) mantissa = mantissa * 10 + digit(*p++);
  long digits = p - integer;
  long exponent = 0;
  if (p < last && *p == '.') {
    const char* const fraction = ++p;
    while (p < last && digit(*p) < 10u) mantissa = mantissa * 10 + digit(*p++);
    exponent = -(p - fraction);
    digits -= exponent;
  }
  // More than 19 digits may have wrapped the mantissa: fast_float reads them.
  if (digits == 0 || digits > 19) return ParseNumberSlow(first, last, x);
  if (p < last && (*p == 'e' || *p == 'E')) {
    const char* q = p + 1;
    const bool exponent_negative = q < last && *q == '-';
    if (q < last && (*q == '-' || *q == '+')) ++q;
    if (q < last && digit(*q) < 10u) {
      long value = 0;
      while (q < last && digit(*q) < 10u) {
        if (value < 100000) value = value * 10 + digit(*q);
        ++q;
      }
      exponent += exponent_negative ? -value : value;
      p = q;
    }  // else "1e", "1e+": the number ends before the 'e', as in from_chars.
  }
  if (mantissa > (uint64_t{1} << 53) || exponent < -22 || exponent > 22) {
    return ParseNumberDigits(first, last, p, mantissa, exponent, negative, x);
  }
  const double value = static_cast<double>(mantissa);
  const double scaled = exponent < 0 ? value / kPow10[-exponent] : value * kPow10[exponent];
  *x = negative ? -scaled : scaled;
  return {p, std::errc()};
}

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_NUMBERS_H_
