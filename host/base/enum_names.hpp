// Name tables of enums: one row per value with the name the command line, --stats and the
// image metadata spell it with, and a note for the option's help.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace candela {

template <typename E>
struct EnumName {
  E value;
  const char* name;
  const char* help;  // "" for none
};

// The value's name ("?" for a value the table lacks)
template <typename E, size_t N>
const char* enum_name(const EnumName<E> (&table)[N], E value) {
  for (const EnumName<E>& row : table)
    if (row.value == value) return row.name;
  return "?";
}

// The value called `name`, if any
template <typename E, size_t N>
std::optional<E> enum_value(const EnumName<E> (&table)[N], const std::string& name) {
  for (const EnumName<E>& row : table)
    if (name == row.name) return row.value;
  return std::nullopt;
}

// "a, b or c"; with_help: "a (help), b (help) or c", a row without help bare
template <typename E, size_t N>
std::string enum_names(const EnumName<E> (&table)[N], bool with_help = false) {
  std::string s;
  for (size_t i = 0; i < N; ++i) {
    s += i == 0 ? "" : i + 1 == N ? " or " : ", ";
    s += table[i].name;
    if (with_help && *table[i].help) s += std::string(" (") + table[i].help + ")";
  }
  return s;
}

}  // namespace candela
