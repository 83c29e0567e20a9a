// Parsing helpers of the command line (options.hpp).
#include "app/options.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>

namespace candela {

glm::vec3 parse_vec3(const std::string& text, const std::string& option) {
  std::stringstream ss(text);
  glm::vec3 v;
  char comma1 = 0, comma2 = 0;
  if (!(ss >> v.x >> comma1 >> v.y >> comma2 >> v.z) || comma1 != ',' || comma2 != ',' || !(ss >> std::ws).eof() ||
      !std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw Error(option + " expects three comma-separated numbers, e.g. 1,0.5,0; got '" + text + "'");
  return v;
}

namespace {

// `text` as a whole number, if all of it is one
std::optional<double> number(const std::string& text) {
  std::stringstream ss(text);
  double v;
  if (!(ss >> v) || !(ss >> std::ws).eof()) {
    // stringstream does not read inf and nan; strtod does
    char* end = nullptr;
    v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size()) return std::nullopt;
  }
  return v;
}

}  // namespace

CLI::Validator finite_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        auto v = number(text);
        return v && std::isfinite(*v) ? "" : "must be a finite number, not '" + text + "'";
      },
      "NUMBER");
}

CLI::Validator positive_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        auto v = number(text);
        return v && std::isfinite(*v) && *v > 0 ? "" : "must be a finite number above 0, not '" + text + "'";
      },
      "NUMBER > 0");
}

CLI::Validator integer_in(long long lo, long long hi) {
  std::string range = std::to_string(lo) + " to " + std::to_string(hi);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        size_t used = 0;
        long long v = 0;
        try {
          v = std::stoll(text, &used);
        } catch (...) {
          used = 0;
        }
        if (used == 0 || used != text.size() || v < lo || v > hi)
          return "must be a whole number from " + range + ", not '" + text + "'";
        return "";
      },
      "INT in " + range);
}

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return text;
}

std::string trim_blanks(std::string text) {
  text.erase(0, text.find_first_not_of(" \t"));
  text.erase(text.find_last_not_of(" \t") + 1);
  return text;
}

}  // namespace candela
