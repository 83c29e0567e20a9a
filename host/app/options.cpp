// Parsing helpers of the command line (options.hpp).
#include "app/options.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
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
