// util/shortest_double.h (private): a double as the shortest decimal text
// that reads back to it, exactly as std::to_chars(first, last, value) writes
// it (the shorter of the fixed and scientific forms, fixed on a tie), about
// three times as fast: the digits come from Dragonbox (fmt), the layout is
// written here.
#ifndef GRAVCAL_SRC_UTIL_SHORTEST_DOUBLE_H_
#define GRAVCAL_SRC_UTIL_SHORTEST_DOUBLE_H_

namespace gravcal {
namespace internal {

// The longest text WriteShortestDouble writes ("-2.2250738585072014e-308").
constexpr int kMaxShortestDouble = 24;

// Writes v at p (room for kMaxShortestDouble characters) and returns the end
// of the text; the same characters as std::to_chars(p, p + 24, v).
char* WriteShortestDouble(double v, char* p);

}  // namespace internal
}  // namespace gravcal

#endif  // GRAVCAL_SRC_UTIL_SHORTEST_DOUBLE_H_
