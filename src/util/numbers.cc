#include "util/numbers.h"

#include <fast_float/fast_float.h>

#include <cmath>

namespace gravcal {
namespace internal {

std::from_chars_result ParseNumberSlow(const char* first, const char* last, double* x) {
  double value = 0.0;
  const fast_float::from_chars_result result = fast_float::from_chars(first, last, value);
  if (result.ec != std::errc()) return {result.ptr, result.ec};
  // fast_float rounds an overflow to infinity and an underflow to zero;
  // std::from_chars calls both out of range and leaves *x as it was.
  const char* const digits = first + (*first == '-' ? 1 : 0);
  if (std::isinf(value) && *digits != 'i' && *digits != 'I') {
    return {result.ptr, std::errc::result_out_of_range};
  }
  if (value == 0.0) {
    for (const char* p = digits; p < result.ptr && *p != 'e' && *p != 'E'; ++p) {
      if (*p >= '1' && *p <= '9') return {result.ptr, std::errc::result_out_of_range};
    }
  }
  *x = value;
  return {result.ptr, std::errc()};
}

}  // namespace internal
}  // namespace gravcal
