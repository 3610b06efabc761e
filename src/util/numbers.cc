#include "util/numbers.h"

#include <fast_float/fast_float.h>

#include <cmath>

namespace gravcal {
namespace internal {

namespace {

// std::from_chars's outcome for fast_float's `value` of the finite number
// text [digits, end) (after its sign): fast_float rounds an overflow to
// infinity and an underflow to zero, std::from_chars calls both out of range
// and leaves *x as it was.
std::from_chars_result Outcome(double value, const char* digits, const char* end, double* x) {
  if (std::isinf(value)) return {end, std::errc::result_out_of_range};
  if (value == 0.0) {
    for (const char* p = digits; p < end && *p != 'e' && *p != 'E'; ++p) {
      if (*p >= '1' && *p <= '9') return {end, std::errc::result_out_of_range};
    }
  }
  *x = value;
  return {end, std::errc()};
}

}  // namespace

std::from_chars_result ParseNumberDigits(const char* first, const char* last, const char* end,
                                         uint64_t mantissa, long exponent, bool negative,
                                         double* x) {
  using Binary = fast_float::binary_format<double>;
  fast_float::adjusted_mantissa am = fast_float::compute_float<Binary>(exponent, mantissa);
  if (am.power2 < 0) return ParseNumberSlow(first, last, x);
  double value = 0.0;
  fast_float::to_float(negative, am, value);
  return Outcome(value, first + (negative ? 1 : 0), end, x);
}

std::from_chars_result ParseNumberSlow(const char* first, const char* last, double* x) {
  double value = 0.0;
  const fast_float::from_chars_result result = fast_float::from_chars(first, last, value);
  if (result.ec != std::errc()) return {result.ptr, result.ec};
  const char* const digits = first + (*first == '-' ? 1 : 0);
  if (*digits == 'i' || *digits == 'I' || *digits == 'n' || *digits == 'N') {
    *x = value;  // "inf", "infinity", "nan", "nan(...)"
    return {result.ptr, std::errc()};
  }
  return Outcome(value, digits, result.ptr, x);
}

}  // namespace internal
}  // namespace gravcal
