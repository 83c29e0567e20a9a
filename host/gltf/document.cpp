// The glTF document before tinygltf parses it: the JSON of a .gltf or a GLB's JSON chunk,
// its nesting checked and the defaults tinygltf needs written in.
#include <algorithm>
#include <nlohmann/json.hpp>
#include <string_view>

#include "base/error.hpp"
#include "gltf/limits.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

// Deepest array and object nesting of JSON text, counted up to `limit` + 1
size_t json_depth(const char* p, size_t n, size_t limit) {
  size_t depth = 0, deepest = 0;
  bool in_string = false;
  for (size_t i = 0; i < n && deepest <= limit; ++i) {
    if (in_string) {
      if (p[i] == '\\')
        ++i;
      else if (p[i] == '"')
        in_string = false;
    } else if (p[i] == '"') {
      in_string = true;
    } else if (p[i] == '[' || p[i] == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((p[i] == ']' || p[i] == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

void append_u32le(std::string* out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out->push_back(char((v >> (8 * i)) & 0xffu));
}

// KHR_lights_punctual lets a spot light leave out its `spot` object (the cone then takes
// its defaults), but tinygltf 2.7 rejects the file. Gives each such light an empty one:
// *out gets the patched file (JSON text, or GLB with its JSON chunk replaced) and the
// result is true; false, and no copy, when the JSON needs nothing (or does not parse:
// tinygltf then reports it).
bool add_missing_spot_objects(const std::string& data, size_t json_begin, size_t json_size, bool binary,
                              std::string* out) {
  if (binary && json_begin != 20) return false;  // too short for a GLB: tinygltf reports it
  std::string_view text(data.data() + json_begin, json_size);
  if (text.find("KHR_lights_punctual") == std::string_view::npos) return false;
  nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return false;
  auto ext = j.find("extensions");
  if (ext == j.end() || !ext->is_object()) return false;
  auto khr = ext->find("KHR_lights_punctual");
  if (khr == ext->end() || !khr->is_object()) return false;
  auto lights = khr->find("lights");
  if (lights == khr->end() || !lights->is_array()) return false;
  bool changed = false;
  for (nlohmann::json& l : *lights) {
    if (!l.is_object() || l.contains("spot")) continue;
    auto type = l.find("type");
    if (type != l.end() && type->is_string() && type->get<std::string>() == "spot") {
      l["spot"] = nlohmann::json::object();
      changed = true;
    }
  }
  if (!changed) return false;
  std::string patched = j.dump();
  if (!binary) {
    *out = std::move(patched);
    return true;
  }
  // GLB: header, the new JSON chunk (padded with spaces to 4 bytes), the chunks after it
  while (patched.size() % 4) patched.push_back(' ');
  std::string rest = data.substr(json_begin + json_size);
  if (12 + 8 + patched.size() + rest.size() > UINT32_MAX) return false;
  out->assign(data, 0, 8);  // magic and version
  append_u32le(out, uint32_t(12 + 8 + patched.size() + rest.size()));
  append_u32le(out, uint32_t(patched.size()));
  out->append(data, 16, 4);  // chunk type JSON
  *out += patched;
  *out += rest;
  return true;
}

}  // namespace

const std::string& prepare_document(const std::string& data, bool binary, const std::string& name,
                                    std::string* patched) {
  size_t json_begin = 0, json_size = data.size();  // a GLB's JSON is its first chunk
  if (binary && data.size() >= 20) {
    uint32_t length = 0;  // little-endian, at byte 12
    for (int i = 15; i >= 12; --i) length = length << 8 | uint8_t(data[size_t(i)]);
    json_begin = 20;
    json_size = std::min<size_t>(length, data.size() - 20);
  }
  if (json_depth(data.data() + json_begin, json_size, kMaxJsonDepth) > kMaxJsonDepth)
    throw Error("cannot load glTF scene " + name + ": JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                " levels");
  return add_missing_spot_objects(data, json_begin, json_size, binary, patched) ? *patched : data;
}

}  // namespace candela::gltf
