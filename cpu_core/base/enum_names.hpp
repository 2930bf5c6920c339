// Names of enum values for options, files and messages: one constexpr table of
// {value, name} pairs per enum, read both ways by the two functions below.
#pragma once
#include <cstddef>
#include <string>

namespace abcube {

template <class E>
struct EnumName {
  E value;
  const char* name;
};

// The name of `value` in `table`, or `unknown` when the table does not list it.
template <class E, size_t N>
constexpr const char* enum_name(const EnumName<E> (&table)[N], E value, const char* unknown = "?") {
  for (const EnumName<E>& e : table) {
    if (e.value == value) return e.name;
  }
  return unknown;
}

// The value named `s` in `table` into *out; false (out untouched) when none is.
template <class E, size_t N>
bool parse_enum(const EnumName<E> (&table)[N], const std::string& s, E* out) {
  for (const EnumName<E>& e : table) {
    if (s == e.name) {
      *out = e.value;
      return true;
    }
  }
  return false;
}

}  // namespace abcube
