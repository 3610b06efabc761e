// Private: the one way an enum gets its string forms. Each enum has one
// table of (value, name) rows in the .cc beside its other code, and
// GRAVCAL_ENUM_STRINGS(Type, table) defines its ToString, FromString and
// AcceptedNames from that table (declared in the enum's public header:
// core/types.h says what they return). A new value is one row: parsing,
// error messages and the help of every key and flag that takes the enum
// follow.
#ifndef GRAVCAL_SRC_CORE_ENUM_NAMES_H_
#define GRAVCAL_SRC_CORE_ENUM_NAMES_H_

#include <cstddef>
#include <string>

namespace gravcal {
namespace internal {

// One row of an enum's table: a value and its string form.
template <typename E>
struct EnumName {
  E value;
  const char* name;
};

template <typename E, std::size_t N>
const char* NameOf(const EnumName<E> (&table)[N], E value) {
  for (const EnumName<E>& row : table) {
    if (row.value == value) return row.name;
  }
  return "unknown";
}

template <typename E, std::size_t N>
bool ValueOf(const EnumName<E> (&table)[N], const std::string& name, E* value) {
  if (value == nullptr) return false;
  for (const EnumName<E>& row : table) {
    if (name == row.name) {
      *value = row.value;
      return true;
    }
  }
  return false;
}

// "a, b or c".
template <typename E, std::size_t N>
std::string NamesOf(const EnumName<E> (&table)[N]) {
  std::string s;
  for (std::size_t i = 0; i < N; ++i) {
    s += std::string(i == 0 ? "" : i + 1 == N ? " or " : ", ") + table[i].name;
  }
  return s;
}

}  // namespace internal
}  // namespace gravcal

// ToString and FromString of `Type` from `table` (at namespace gravcal
// scope).
#define GRAVCAL_ENUM_TO_FROM_STRING(Type, table)                                               \
  [[maybe_unused]] const char* ToString(Type value) { return internal::NameOf(table, value); } \
  [[maybe_unused]] bool FromString(const std::string& name, Type* value) {                     \
    return internal::ValueOf(table, name, value);                                              \
  }
// The same and AcceptedNames.
#define GRAVCAL_ENUM_STRINGS(Type, table)  \
  GRAVCAL_ENUM_TO_FROM_STRING(Type, table) \
  [[maybe_unused]] std::string AcceptedNames(Type) { return internal::NamesOf(table); }

#endif  // GRAVCAL_SRC_CORE_ENUM_NAMES_H_
