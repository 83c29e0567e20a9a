// Frame sequences: --frames' ranges and the '#' patterns of their outputs (sequence.hpp).
#include "app/sequence.hpp"

#include <OpenImageIO/imageio.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "base/error.hpp"

namespace candela {
namespace {

// A whole number 0 <= v <= 10^9 from `text`; false otherwise
bool whole_number(const std::string& text, long* v) {
  if (text.empty() || text.size() > 10 || text.find_first_not_of("0123456789") != std::string::npos) return false;
  *v = std::strtol(text.c_str(), nullptr, 10);
  return *v <= 1000000000L;
}

// The start of the file name in `path`
size_t name_start(const std::string& path) {
  size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? 0 : slash + 1;
}

}  // namespace

std::vector<long> parse_frames(const std::string& text) {
  std::vector<std::string> parts;
  size_t at = 0;
  for (size_t colon; (colon = text.find(':', at)) != std::string::npos; at = colon + 1)
    parts.push_back(text.substr(at, colon - at));
  parts.push_back(text.substr(at));
  long first = 0, last = 0, step = 1;
  bool ok = (parts.size() == 2 || parts.size() == 3) && whole_number(parts[0], &first) &&
            whole_number(parts[1], &last) && (parts.size() == 2 || whole_number(parts[2], &step));
  if (!ok || first > last || step < 1)
    throw Error("--frames must be A:B or A:B:STEP, whole numbers with 0 <= A <= B and STEP >= 1, not '" + text + "'");
  if ((last - first) / step >= 1000000L) throw Error("--frames asks for more than 10^6 frames: '" + text + "'");
  std::vector<long> frames;
  for (long f = first; f <= last; f += step) frames.push_back(f);
  return frames;
}

bool has_frame_pattern(const std::string& path) { return path.find('#', name_start(path)) != std::string::npos; }

std::string frame_path(const std::string& path, long frame) {
  size_t end = path.find_last_of('#');
  if (end == std::string::npos || end < name_start(path)) return path;
  size_t begin = end;
  while (begin > 0 && path[begin - 1] == '#') --begin;
  char number[32];
  std::snprintf(number, sizeof number, "%0*ld", int(end - begin + 1), frame);
  return path.substr(0, begin) + number + path.substr(end + 1);
}

bool frame_written(const std::string& path, unsigned spp) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  auto in = OIIO::ImageInput::open(path);
  if (!in) return false;  // unreadable: written again
  const OIIO::ImageSpec& spec = in->spec();
  bool partial = spec.get_string_attribute("candela:partial_pass") == "1";
  std::string samples = spec.get_string_attribute("candela:spp");
  if (samples.empty()) samples = std::to_string(spec.get_int_attribute("candela:spp", -1));
  long written = std::strtol(samples.c_str(), nullptr, 10);
  in->close();
  return !partial && !(spp > 0 && written >= 0 && written < long(spp));
}

}  // namespace candela
