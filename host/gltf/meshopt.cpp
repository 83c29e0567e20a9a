// EXT_meshopt_compression: each compressed bufferView decoded with meshoptimizer (attribute,
// triangle and index codecs, then the octahedral, quaternion or exponential filter) into a
// buffer of its own, which the view then reads as an uncompressed one.
#include <meshoptimizer.h>

#include <cmath>
#include <string>

#include "base/error.hpp"
#include "gltf/limits.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

// A non-negative integer of the extension object, `fallback` when absent; Error otherwise
uint64_t integer(const tinygltf::Value& ext, const char* key, const std::string& where, int64_t fallback = -1) {
  if (!ext.Has(key)) {
    if (fallback < 0) throw Error(where + " has no " + key);
    return uint64_t(fallback);
  }
  const tinygltf::Value& v = ext.Get(key);
  double d = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
  if (!(d >= 0.0 && d <= 9007199254740992.0 && d == std::floor(d)))
    throw Error(where + ": " + key + " must be a non-negative integer");
  return uint64_t(d);
}

std::string string_or(const tinygltf::Value& ext, const char* key, const std::string& fallback) {
  return ext.Has(key) && ext.Get(key).IsString() ? ext.Get(key).Get<std::string>() : fallback;
}

// The extension's layout checked against the specification's rules
void check_layout(const std::string& mode, const std::string& filter, uint64_t stride, uint64_t count,
                  const std::string& where) {
  bool ok = false;
  if (mode == "ATTRIBUTES") {
    ok = stride % 4 == 0 && stride > 0 && stride <= 256;
    if (filter == "OCTAHEDRAL") ok = ok && (stride == 4 || stride == 8);
    if (filter == "QUATERNION") ok = ok && stride == 8;
    if (filter != "NONE" && filter != "OCTAHEDRAL" && filter != "QUATERNION" && filter != "EXPONENTIAL")
      throw Error(where + ": unknown filter '" + filter + "'");
  } else if (mode == "TRIANGLES" || mode == "INDICES") {
    ok = (stride == 2 || stride == 4) && filter == "NONE" && (mode == "INDICES" || count % 3 == 0);
  } else {
    throw Error(where + ": unknown mode '" + mode + "'");
  }
  if (!ok)
    throw Error(where + ": byteStride " + std::to_string(stride) + " does not suit mode " + mode +
                (filter == "NONE" ? "" : " and filter " + filter) + " (or count is not a multiple of 3)");
}

// The view's data, decoded
std::vector<unsigned char> decode_view(const tinygltf::Model& model, const tinygltf::BufferView& view,
                                       const tinygltf::Value& ext, const std::string& where) {
  uint64_t buffer = integer(ext, "buffer", where), offset = integer(ext, "byteOffset", where, 0);
  uint64_t length = integer(ext, "byteLength", where), stride = integer(ext, "byteStride", where);
  uint64_t count = integer(ext, "count", where);
  std::string mode = string_or(ext, "mode", ""), filter = string_or(ext, "filter", "NONE");
  check_layout(mode, filter, stride, count, where);
  if (buffer >= model.buffers.size()) throw Error(where + " refers to a missing buffer");
  const std::vector<unsigned char>& data = model.buffers[size_t(buffer)].data;
  if (offset > data.size() || length > data.size() - offset)
    throw Error(where + ": its compressed data lies outside its buffer");
  if (count > view.byteLength / stride || count * stride != view.byteLength)
    throw Error(where + ": the bufferView's byteLength must be byteStride x count");
  if (count * stride > kMaxMeshoptExpansion * length)
    throw Error(where + ": " + std::to_string(length) + " bytes cannot hold " + std::to_string(count * stride));
  std::vector<unsigned char> out(size_t(count * stride));
  if (out.empty()) return out;
  const unsigned char* src = data.data() + offset;
  int rc = mode == "ATTRIBUTES"  ? meshopt_decodeVertexBuffer(out.data(), count, stride, src, length)
           : mode == "TRIANGLES" ? meshopt_decodeIndexBuffer(out.data(), count, stride, src, length)
                                 : meshopt_decodeIndexSequence(out.data(), count, stride, src, length);
  if (rc != 0) throw Error(where + " does not decode (meshoptimizer error " + std::to_string(rc) + ")");
  if (filter == "OCTAHEDRAL") meshopt_decodeFilterOct(out.data(), count, stride);
  if (filter == "QUATERNION") meshopt_decodeFilterQuat(out.data(), count, stride);
  if (filter == "EXPONENTIAL") meshopt_decodeFilterExp(out.data(), count, stride);
  return out;
}

}  // namespace

void decode_meshopt_views(tinygltf::Model* model) {
  for (size_t i = 0; i < model->bufferViews.size(); ++i) {
    tinygltf::BufferView& view = model->bufferViews[i];
    auto ext = view.extensions.find("EXT_meshopt_compression");
    if (ext == view.extensions.end()) continue;
    std::vector<unsigned char> data =
        decode_view(*model, view, ext->second, "EXT_meshopt_compression bufferView " + std::to_string(i));
    tinygltf::Buffer decoded;
    decoded.data = std::move(data);
    view.buffer = int(model->buffers.size());
    view.byteOffset = 0;
    view.byteLength = decoded.data.size();
    model->buffers.push_back(std::move(decoded));
    view.extensions.erase(ext);
  }
}

}  // namespace candela::gltf
