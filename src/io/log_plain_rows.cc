// LogRowParser::ParsePlainCsvRow (io/log_text.h): the plain rows of a CSV
// log, which are nearly all of a long log's lines, read in one pass.
//
// A row of up to 63 bytes is read whole: its commas and its line end are
// found 16 bytes at a time (SSE2), so every cell's bounds are known before
// any is read and the cells are independent work; a cell of at most 8
// digits (raw counts) or a short decimal ("-0.012345") is added 8 bytes at
// a time. Any other cell goes to
// ParseNumber, and any other row to the byte-by-byte loop below, which does
// what ParseRow does for such a row.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <system_error>

#include "io/log_text.h"
#include "util/numbers.h"

#if defined(__SSE2__) && defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#include <emmintrin.h>
#define GRAVCAL_PLAIN_ROWS_SSE2 1
#endif

namespace gravcal {
namespace internal {
namespace {

#ifdef GRAVCAL_PLAIN_ROWS_SSE2
// The bytes of [p, p + 64) equal to c, as bits (bit i: p[i]).
inline uint64_t BytesEqual64(const char* p, char c) {
  const __m128i wanted = _mm_set1_epi8(c);
  uint64_t bits = 0;
  for (int i = 0; i < 4; ++i) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * i));
    bits |=
        static_cast<uint64_t>(static_cast<uint16_t>(_mm_movemask_epi8(_mm_cmpeq_epi8(v, wanted))))
        << (16 * i);
  }
  return bits;
}

// The number of ASCII digits that open the 8 bytes of w (the first byte is
// the lowest). A byte below '0' sets its high bit in w - '0' and one above
// '9' in w + 0x46; the digits before it carry and borrow nothing, so the
// first flagged byte is the first that is not a digit.
inline unsigned LeadingDigits(uint64_t w) {
  const uint64_t flagged =
      ((w + 0x4646464646464646u) | (w - 0x3030303030303030u)) & 0x8080808080808080u;
  return flagged == 0 ? 8u : static_cast<unsigned>(__builtin_ctzll(flagged)) >> 3;
}

// The value of the n (1 to 8) digits that open w: moved to the top bytes
// (the zeros below are leading zeros), then added in pairs, fours, eights.
inline uint64_t DigitsValue(uint64_t w, unsigned n) {
  uint64_t v = (w - 0x3030303030303030u) << (8 * (8 - n));
  v = v * 10 + (v >> 8);
  v = (((v & 0x000000FF000000FFu) * (100 + (uint64_t{1000000} << 32))) +
       (((v >> 16) & 0x000000FF000000FFu) * (1 + (uint64_t{10000} << 32)))) >>
      32;
  return v;
}

// -value when `negative`, without a branch (the signs of readings change
// at random): a product with -1 or 1 is exact, -0 included.
inline double WithSign(double value, bool negative) {
  static constexpr double kSign[2] = {1.0, -1.0};
  return value * kSign[negative ? 1 : 0];
}

// The cell [s, e) as ParseNumber reads it, when that reads all of it and
// the value is finite. Integers of at most 8 digits and decimals of 1-7
// digits, a point and 1-8 digits are added 8 bytes at a time: their
// mantissa is below 2^53, so the value is the mantissa, or the mantissa
// divided by 10^digits once (correctly rounded), as ParseNumber makes it.
inline bool PlainCell(const char* s, const char* e, double* x) {
  static constexpr double kPow10[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8};
  static constexpr uint64_t kPow10Int[] = {1,      10,      100,      1000,     10000,
                                           100000, 1000000, 10000000, 100000000};
  const bool negative = s < e && *s == '-';
  const char* digits = s + (negative ? 1 : 0);
  const size_t length = static_cast<size_t>(e - digits);
  if (length >= 1 && length <= 16) {
    uint64_t w;
    std::memcpy(&w, digits, 8);
    const unsigned lead = LeadingDigits(w);
    if (lead >= length) {  // An integer of at most 8 digits.
      *x = WithSign(static_cast<double>(DigitsValue(w, static_cast<unsigned>(length))), negative);
      return true;
    }
    const size_t fraction = length - lead - 1;
    if (lead >= 1 && lead <= 7 && digits[lead] == '.' && fraction >= 1 && fraction <= 8) {
      uint64_t f;
      std::memcpy(&f, digits + lead + 1, 8);
      if (LeadingDigits(f) >= fraction) {
        const uint64_t mantissa = DigitsValue(w, lead) * kPow10Int[fraction] +
                                  DigitsValue(f, static_cast<unsigned>(fraction));
        *x = WithSign(static_cast<double>(mantissa) / kPow10[fraction], negative);
        return true;
      }
    }
  }
  const std::from_chars_result result = ParseNumber(s, e, x);
  return result.ec == std::errc() && result.ptr == e && std::isfinite(*x);
}
#endif

}  // namespace

const char* LogRowParser::ParsePlainCsvRow(const char* begin, const char* end,
                                           const char* readable_end, double* row) const {
  if (format_ != LogFormat::kCsv || !have_layout_ || begin >= end) return nullptr;
  // A comment or a line with leading blanks (which may hide one) is Line's.
  if (*begin == '#' || *begin == ' ' || *begin == '\t') return nullptr;
  const size_t fields = slot_of_field_.size();
  const int* const slot_of_field = slot_of_field_.data();
  for (int slot = 0; slot < kNumSlots; ++slot) row[slot] = 0.0;
#ifdef GRAVCAL_PLAIN_ROWS_SSE2
  // 64 bytes for the row, and 17 after a cell that opens at most at byte 63.
  if (readable_end - begin >= kPlainRowReadAhead) {
    const size_t limit = static_cast<size_t>(end - begin);
    const uint64_t in_text = limit >= 64 ? ~uint64_t{0} : (uint64_t{1} << limit) - 1;
    const uint64_t newlines = BytesEqual64(begin, '\n') & in_text;
    if (newlines != 0) {
      const unsigned line_bytes = static_cast<unsigned>(__builtin_ctzll(newlines));
      uint64_t commas = BytesEqual64(begin, ',') & ((uint64_t{1} << line_bytes) - 1);
      const char* const stop =
          begin + line_bytes - (line_bytes > 0 && begin[line_bytes - 1] == '\r' ? 1 : 0);
      const char* s = begin;
      bool plain = true;
      for (size_t field = 0; field < fields && plain; ++field) {
        const char* e = stop;
        if (field + 1 < fields) {
          plain = commas != 0;  // else too few fields
          e = begin + __builtin_ctzll(commas | (uint64_t{1} << 63));
          commas &= commas - 1;
        }
        const int slot = slot_of_field[field];
        if (plain && slot >= 0) plain = PlainCell(s, e, &row[slot]);
        s = e + 1;
      }
      if (plain && commas == 0) {  // (commas left: too many fields)
        if (has_[kTemp]) row[kTemp] = options_.temp_offset + options_.temp_scale * row[kTemp];
        return begin + line_bytes + 1;
      }
      for (int slot = 0; slot < kNumSlots; ++slot) row[slot] = 0.0;
    }
  }
#endif
  (void)readable_end;
  const char* p = begin;
  for (size_t field = 0;; ++field) {
    const int slot = slot_of_field[field];
    if (slot >= 0) {
      // A number ends at the first byte that cannot continue it (',', '\r',
      // '\n'), so reading up to `end` rather than the line end reads the same.
      double x = 0.0;
      const std::from_chars_result result = ParseNumber(p, end, &x);
      if (result.ec != std::errc() || !std::isfinite(x)) return nullptr;
      row[slot] = x;
      p = result.ptr;
    } else {
      while (p < end && *p != ',' && *p != '\n' && *p != '\r') ++p;
    }
    if (field + 1 < fields) {
      if (p == end || *p != ',') return nullptr;
      ++p;
      continue;
    }
    if (p < end && *p == '\r') ++p;
    if (p < end) {
      if (*p != '\n') return nullptr;
      ++p;
    }
    break;
  }
  if (static_cast<size_t>(p - begin) > kMaxLogLineBytes) return nullptr;
  if (has_[kTemp]) row[kTemp] = options_.temp_offset + options_.temp_scale * row[kTemp];
  return p;
}

}  // namespace internal
}  // namespace gravcal
