// The glTF document before tinygltf parses it: the JSON of a .gltf or a GLB's JSON chunk,
// its nesting checked, image views bounds-checked, and what tinygltf 2.7 needs to read
// files glTF allows written in.
#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>
#include <set>
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

using nlohmann::json;

// j[key] when j is an object that has it, else nullptr
const json* member(const json& j, const char* key) {
  if (!j.is_object()) return nullptr;
  auto it = j.find(key);
  return it == j.end() ? nullptr : &*it;
}

// KHR_lights_punctual lets a spot light leave out its `spot` object (the cone then takes
// its defaults), but tinygltf 2.7 rejects the file: gives each such light an empty one
bool add_missing_spot_objects(json& j) {
  const json* ext = member(j, "extensions");
  const json* khr = ext ? member(*ext, "KHR_lights_punctual") : nullptr;
  const json* lights = khr ? member(*khr, "lights") : nullptr;
  if (!lights || !lights->is_array()) return false;
  bool changed = false;
  for (json& l : j["extensions"]["KHR_lights_punctual"]["lights"]) {
    const json* type = member(l, "type");
    if (!type || member(l, "spot") || !type->is_string() || type->get<std::string>() != "spot") continue;
    l["spot"] = json::object();
    changed = true;
  }
  return changed;
}

// A KHR_draco_mesh_compression primitive's indices accessor has no bufferView (the
// extension's data replaces it), which tinygltf 2.7 rejects before any extension is read:
// such a primitive loses its `indices` (draco.cpp decodes the triangles)
bool drop_draco_indices(json& j) {
  const json* accessors = member(j, "accessors");
  const json* meshes = member(j, "meshes");
  if (!meshes || !meshes->is_array()) return false;
  bool changed = false;
  for (json& mesh : j["meshes"]) {
    const json* prims = member(mesh, "primitives");
    if (!prims || !prims->is_array()) continue;
    for (json& prim : mesh["primitives"]) {
      const json* ext = member(prim, "extensions");
      const json* indices = member(prim, "indices");
      if (!ext || !member(*ext, "KHR_draco_mesh_compression") || !indices || !indices->is_number_unsigned()) continue;
      size_t a = indices->get<size_t>();
      if (accessors && accessors->is_array() && a < accessors->size() && member((*accessors)[a], "bufferView"))
        continue;
      prim.erase("indices");
      changed = true;
    }
  }
  return changed;
}

// EXT_meshopt_compression lets a buffer that only holds the uncompressed layout have no
// URI (a placeholder), which tinygltf 2.7 cannot load outside a GLB's first buffer. When
// bufferViews with the extension are all that use it, it gets a 4-byte stand-in:
// meshopt.cpp points every such view at its decoded data, and a view that would still
// read it fails its bounds check.
bool fill_meshopt_placeholders(json& j, bool binary) {
  const json* buffers = member(j, "buffers");
  if (!buffers || !buffers->is_array()) return false;
  std::vector<bool> placeholder(buffers->size(), false);
  for (size_t b = binary ? 1 : 0; b < buffers->size(); ++b)
    placeholder[b] = (*buffers)[b].is_object() && !member((*buffers)[b], "uri");
  const json* views = member(j, "bufferViews");
  if (views && views->is_array())
    for (const json& v : *views) {
      const json* buffer = member(v, "buffer");
      const json* ext = member(v, "extensions");
      if (buffer && buffer->is_number_unsigned() && buffer->get<size_t>() < placeholder.size() &&
          !(ext && member(*ext, "EXT_meshopt_compression")))
        placeholder[buffer->get<size_t>()] = false;
    }
  bool changed = false;
  for (size_t b = 0; b < placeholder.size(); ++b) {
    if (!placeholder[b]) continue;
    j["buffers"][b]["uri"] = "data:application/octet-stream;base64,AAAAAA==";
    j["buffers"][b]["byteLength"] = 4;
    changed = true;
  }
  return changed;
}

// KHR_animation_pointer's channels name no node, which tinygltf 2.7 requires (it drops the
// channel): each such target gets node -1 (none), its pointer staying in its extensions
bool add_pointer_target_nodes(json& j) {
  const json* animations = member(j, "animations");
  if (!animations || !animations->is_array()) return false;
  bool changed = false;
  for (json& anim : j["animations"]) {
    const json* channels = member(anim, "channels");
    if (!channels || !channels->is_array()) continue;
    for (json& ch : anim["channels"]) {
      const json* target = member(ch, "target");
      if (!target || !target->is_object() || member(*target, "node")) continue;
      ch["target"]["node"] = -1;
      changed = true;
    }
  }
  return changed;
}

// An unsigned integer member, or `fallback` when it is missing or not one
uint64_t unsigned_or(const json& j, const char* key, uint64_t fallback) {
  const json* v = member(j, key);
  return v && v->is_number_unsigned() ? v->get<uint64_t>() : fallback;
}

// tinygltf 2.7 hands an image's bufferView to the image decoder without checking that it
// lies inside its buffer (whose loaded size is its byteLength): an image that reads past
// it is an error here
void check_image_views(const json& j, const std::string& name) {
  const json* images = member(j, "images");
  const json* views = member(j, "bufferViews");
  const json* buffers = member(j, "buffers");
  if (!images || !images->is_array() || !views || !views->is_array() || !buffers || !buffers->is_array()) return;
  for (size_t i = 0; i < images->size(); ++i) {
    uint64_t v = unsigned_or((*images)[i], "bufferView", UINT64_MAX);
    if (v >= views->size()) continue;  // none, or tinygltf reports it
    const json& view = (*views)[v];
    uint64_t b = unsigned_or(view, "buffer", UINT64_MAX);
    if (b >= buffers->size()) continue;
    uint64_t size = unsigned_or((*buffers)[b], "byteLength", 0);
    uint64_t offset = unsigned_or(view, "byteOffset", 0), length = unsigned_or(view, "byteLength", 0);
    if (offset > size || length > size - offset)
      throw Error("cannot load glTF scene " + name + ": image " + std::to_string(i) +
                  " reads past the end of its buffer");
  }
}

// Whether `uri` is a data: URI whose payload tinygltf 2.7 could not decode (not base64):
// tinygltf then fails the whole file, where glTF's images are optional
bool undecodable_data_uri(const std::string& uri) {
  if (uri.compare(0, 5, "data:") != 0) return false;
  size_t comma = uri.find(',');
  if (comma == std::string::npos || uri.compare(comma - 7, 7, ";base64") != 0) return true;
  size_t payload = 0;
  for (size_t i = comma + 1; i < uri.size(); ++i) {
    char c = uri[i];
    bool b64 = std::isalnum(static_cast<unsigned char>(c)) || c == '+' || c == '/' || c == '=';
    if (!b64) return true;
    payload += c != '=';
  }
  return payload < 2;  // under one byte
}

// Images whose data: URI cannot be decoded get a stand-in that decodes to bytes that are no
// image: load_checked_image then drops them with a warning; *bad gets their indices
bool replace_undecodable_images(json& j, std::set<int>* bad) {
  const json* images = member(j, "images");
  if (!images || !images->is_array()) return false;
  bool changed = false;
  for (size_t i = 0; i < images->size(); ++i) {
    json& img = j["images"][i];
    const json* uri = member(img, "uri");
    if (!uri || !uri->is_string() || !undecodable_data_uri(uri->get<std::string>())) continue;
    img["uri"] = "data:application/octet-stream;base64,AAAA";
    img.erase("mimeType");
    bad->insert(int(i));
    changed = true;
  }
  return changed;
}

// The document with what tinygltf needs written in (JSON text, or a GLB with its JSON chunk
// replaced) into *out, and true; false, and no copy, when it needs nothing (or does not
// parse: tinygltf then reports it)
bool patch_document(const std::string& data, size_t json_begin, size_t json_size, bool binary, const std::string& name,
                    std::string* out, std::set<int>* bad_images) {
  if (binary && json_begin != 20) return false;  // too short for a GLB: tinygltf reports it
  std::string_view text(data.data() + json_begin, json_size);
  bool lights = text.find("KHR_lights_punctual") != std::string_view::npos;
  bool draco = text.find("KHR_draco_mesh_compression") != std::string_view::npos;
  bool meshopt = text.find("EXT_meshopt_compression") != std::string_view::npos;
  bool images = text.find("\"images\"") != std::string_view::npos;
  bool pointers = text.find("KHR_animation_pointer") != std::string_view::npos;
  if (!lights && !draco && !meshopt && !images && !pointers) return false;
  json j = json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return false;
  if (images) check_image_views(j, name);
  bool changed = false;
  if (lights) changed |= add_missing_spot_objects(j);
  if (draco) changed |= drop_draco_indices(j);
  if (meshopt) changed |= fill_meshopt_placeholders(j, binary);
  if (images) changed |= replace_undecodable_images(j, bad_images);
  if (pointers) changed |= add_pointer_target_nodes(j);
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

const std::string& prepare_document(const std::string& data, bool binary, const std::string& name, std::string* patched,
                                    std::set<int>* bad_images) {
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
  return patch_document(data, json_begin, json_size, binary, name, patched, bad_images) ? *patched : data;
}

}  // namespace candela::gltf
