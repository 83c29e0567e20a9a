// Parsing helpers of the command line: vectors, enum names, case and blanks.
#pragma once

#include <CLI/CLI.hpp>
#include <cstddef>
#include <glm/glm.hpp>
#include <string>

#include "base/enum_names.hpp"
#include "base/error.hpp"

namespace candela {

// "X,Y,Z": three finite comma-separated numbers; Error naming `option` otherwise
glm::vec3 parse_vec3(const std::string& text, const std::string& option);

// The value `table` calls `name`; Error "OPTION must be a, b or c, not 'NAME'" otherwise
template <typename E, size_t N>
E parse_enum(const EnumName<E> (&table)[N], const std::string& option, const std::string& name) {
  if (auto value = enum_value(table, name)) return *value;
  throw Error(option + " must be " + enum_names(table) + ", not '" + name + "'");
}

// Option checks for the command-line parser, each failing with one short line:
// a finite number; a finite number > 0; an integer in [lo, hi]
CLI::Validator finite_number();
CLI::Validator positive_number();
CLI::Validator integer_in(long long lo, long long hi);

std::string lowercase(std::string text);
std::string trim_blanks(std::string text);  // spaces and tabs at both ends

}  // namespace candela
