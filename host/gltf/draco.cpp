// KHR_draco_mesh_compression: each compressed primitive decoded with Google's Draco library
// into a buffer of its own; its attribute accessors (same type as declared) and a new index
// accessor read it, and the primitive then loads as an uncompressed one. A primitive that
// does not decode is skipped, with one warning for the file.
#include <draco/compression/decode.h>

#include <cmath>
#include <cstring>
#include <string>

#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

constexpr const char* kExtension = "KHR_draco_mesh_compression";

// Appends `bytes` as a new bufferView of the model's last buffer (4-byte aligned)
int add_view(tinygltf::Model* model, const std::vector<unsigned char>& bytes) {
  std::vector<unsigned char>& data = model->buffers.back().data;
  data.resize((data.size() + 3) & ~size_t(3), 0);
  tinygltf::BufferView view;
  view.buffer = int(model->buffers.size()) - 1;
  view.byteOffset = data.size();
  view.byteLength = bytes.size();
  data.insert(data.end(), bytes.begin(), bytes.end());
  model->bufferViews.push_back(view);
  return int(model->bufferViews.size()) - 1;
}

// The attribute's value at each point, converted to the accessor's own component type
template <typename T>
bool convert(const draco::PointAttribute& attr, size_t points, int comps, std::vector<unsigned char>* out) {
  std::vector<T> values(points * size_t(comps));
  for (size_t p = 0; p < points; ++p)
    if (!attr.ConvertValue<T>(attr.mapped_index(draco::PointIndex(uint32_t(p))), int8_t(comps),
                              values.data() + p * size_t(comps)))
      return false;
  out->resize(values.size() * sizeof(T));
  if (!values.empty()) std::memcpy(out->data(), values.data(), out->size());
  return true;
}

bool attribute_bytes(const draco::PointAttribute& attr, const tinygltf::Accessor& acc, size_t points,
                     std::vector<unsigned char>* out) {
  int comps = tinygltf::GetNumComponentsInType(acc.type);
  if (comps <= 0 || comps > 16) return false;
  switch (acc.componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return convert<int8_t>(attr, points, comps, out);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return convert<uint8_t>(attr, points, comps, out);
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return convert<int16_t>(attr, points, comps, out);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return convert<uint16_t>(attr, points, comps, out);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return convert<uint32_t>(attr, points, comps, out);
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return convert<float>(attr, points, comps, out);
    default:
      return false;
  }
}

// The compressed bytes of the extension's bufferView, or "" with *why set
std::string compressed_bytes(const tinygltf::Model& model, const tinygltf::Value& ext, std::string* why) {
  double v = ext.Has("bufferView") && ext.Get("bufferView").IsNumber() ? ext.Get("bufferView").GetNumberAsDouble() : -1;
  if (!(v >= 0.0 && v < double(model.bufferViews.size()) && v == std::floor(v))) {
    *why = "its bufferView is missing";
    return "";
  }
  const tinygltf::BufferView& view = model.bufferViews[size_t(v)];
  if (view.buffer < 0 || view.buffer >= (int)model.buffers.size() ||
      view.byteOffset > model.buffers[size_t(view.buffer)].data.size() ||
      view.byteLength > model.buffers[size_t(view.buffer)].data.size() - view.byteOffset) {
    *why = "its bufferView lies outside its buffer";
    return "";
  }
  const unsigned char* p = model.buffers[size_t(view.buffer)].data.data() + view.byteOffset;
  return std::string(reinterpret_cast<const char*>(p), view.byteLength);
}

// Decodes the primitive into a new buffer and points its accessors there; "" on success,
// else why it failed (the model is then unchanged)
std::string decode_primitive(tinygltf::Model* model, tinygltf::Primitive* prim, const tinygltf::Value& ext) {
  std::string why;
  std::string bytes = compressed_bytes(*model, ext, &why);
  if (!why.empty()) return why;
  draco::DecoderBuffer buffer;
  buffer.Init(bytes.data(), bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) return decoded.status().error_msg_string();
  const draco::Mesh& mesh = *decoded.value();
  size_t points = mesh.num_points();
  // Every attribute first: nothing changes unless all decode
  if (!ext.Has("attributes") || !ext.Get("attributes").IsObject()) return "it has no attributes";
  const tinygltf::Value& attributes = ext.Get("attributes");
  std::vector<std::pair<int, std::vector<unsigned char>>> decoded_attributes;  // (accessor, bytes)
  for (const std::string& name : attributes.Keys()) {
    auto it = prim->attributes.find(name);
    const tinygltf::Value& id = attributes.Get(name);
    if (it == prim->attributes.end() || it->second < 0 || it->second >= (int)model->accessors.size())
      return "attribute " + name + " is not one of the primitive's";
    const draco::PointAttribute* attr =
        id.IsNumber() && id.GetNumberAsDouble() >= 0.0 && id.GetNumberAsDouble() < 4294967296.0
            ? mesh.GetAttributeByUniqueId(uint32_t(id.GetNumberAsDouble()))
            : nullptr;
    std::vector<unsigned char> data;
    if (!attr || !attribute_bytes(*attr, model->accessors[size_t(it->second)], points, &data))
      return "attribute " + name + " does not decode";
    decoded_attributes.emplace_back(it->second, std::move(data));
  }
  std::vector<unsigned char> indices(size_t(mesh.num_faces()) * 3 * sizeof(uint32_t));
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      uint32_t v = mesh.face(f)[k].value();
      if (v >= points) return "a triangle refers to a missing point";
      std::memcpy(&indices[(size_t(f.value()) * 3 + size_t(k)) * sizeof(uint32_t)], &v, sizeof v);
    }
  model->buffers.emplace_back();
  for (auto& [accessor, data] : decoded_attributes) {
    tinygltf::Accessor& acc = model->accessors[size_t(accessor)];
    acc.bufferView = add_view(model, data);
    acc.byteOffset = 0;
    acc.count = points;
    acc.sparse.isSparse = false;
  }
  tinygltf::Accessor index_accessor;
  index_accessor.bufferView = add_view(model, indices);
  index_accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
  index_accessor.type = TINYGLTF_TYPE_SCALAR;
  index_accessor.count = indices.size() / sizeof(uint32_t);
  model->accessors.push_back(index_accessor);
  prim->indices = int(model->accessors.size()) - 1;
  prim->mode = TINYGLTF_MODE_TRIANGLES;
  return "";
}

}  // namespace

void decode_draco_primitives(tinygltf::Model* model, Warnings* warn) {
  size_t failed = 0;
  std::string first;
  for (tinygltf::Mesh& mesh : model->meshes)
    for (tinygltf::Primitive& prim : mesh.primitives) {
      auto ext = prim.extensions.find(kExtension);
      if (ext == prim.extensions.end()) continue;
      bool triangles = prim.mode == -1 || prim.mode == TINYGLTF_MODE_TRIANGLES ||
                       prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP || prim.mode == TINYGLTF_MODE_TRIANGLE_FAN;
      if (!triangles) continue;  // points and lines are not rendered (meshes.cpp says so)
      std::string why = decode_primitive(model, &prim, ext->second);
      if (why.empty()) {
        prim.extensions.erase(ext);
      } else if (failed++ == 0) {
        first = why;
      }
    }
  if (failed > 0)
    warn->add(std::to_string(failed) + " Draco-compressed primitive" + (failed == 1 ? "" : "s") +
              " (KHR_draco_mesh_compression) could not be decoded and " + (failed == 1 ? "is" : "are") +
              " skipped (the first: " + first + ")");
}

}  // namespace candela::gltf
