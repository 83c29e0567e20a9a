// glTF accessors: component decoding, bufferViews read within bounds, sparse substitution.
#include <algorithm>
#include <cstring>

#include "base/error.hpp"
#include "gltf/limits.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

// One component as a float: normalized integers map to [0,1] / [-1,1] (glTF 3.11)
float decode_float(const unsigned char* p, int ctype, bool normalized) {
  switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
      float f;
      std::memcpy(&f, p, 4);
      return f;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return normalized ? *p / 255.0f : float(*p);
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t v = int8_t(*p);
      return normalized ? std::max(v / 127.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? v / 65535.0f : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t v;
      std::memcpy(&v, p, 2);
      return normalized ? std::max(v / 32767.0f, -1.0f) : float(v);
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return float(v);
    }
    default:
      throw Error("glTF accessor has an unsupported component type");
  }
}

// One unsigned integer component (indices)
uint32_t decode_uint(const unsigned char* p, int ctype, bool) {
  switch (ctype) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return *p;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t v;
      std::memcpy(&v, p, 2);
      return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
      uint32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    default:
      throw Error("glTF indices must be unsigned bytes, shorts or ints");
  }
}

// Reads `count` elements of `ncomp` components from a bufferView, `offset` bytes in,
// after checking every byte lies inside the view and the buffer (no overflow possible:
// only subtractions of checked values and one division).
template <typename T, typename Decode>
void read_view(const tinygltf::Model& model, int view_index, size_t offset, size_t count, int ncomp, int ctype,
               bool normalized, Decode decode, std::vector<T>* out) {
  if (view_index < 0 || view_index >= (int)model.bufferViews.size())
    throw Error("glTF accessor refers to a missing bufferView");
  const tinygltf::BufferView& view = model.bufferViews[view_index];
  if (view.buffer < 0 || view.buffer >= (int)model.buffers.size())
    throw Error("glTF bufferView refers to a missing buffer");
  const std::vector<unsigned char>& buf = model.buffers[view.buffer].data;
  int csize = tinygltf::GetComponentSizeInBytes(ctype);
  if (csize <= 0) throw Error("glTF accessor has an unsupported component type");
  size_t elem = size_t(ncomp) * size_t(csize);
  size_t stride = view.byteStride ? view.byteStride : elem;
  if (stride < elem) throw Error("glTF bufferView byteStride is smaller than its elements");
  if (view.byteOffset > buf.size() || view.byteLength > buf.size() - view.byteOffset)
    throw Error("glTF bufferView lies outside its buffer (is the .bin file complete?)");
  out->clear();
  if (count == 0) return;
  if (offset > view.byteLength || elem > view.byteLength - offset ||
      count - 1 > (view.byteLength - offset - elem) / stride)
    throw Error("glTF accessor reads past the end of its bufferView");
  out->resize(count * ncomp);
  const unsigned char* base = buf.data() + view.byteOffset + offset;
  for (size_t i = 0; i < count; ++i)
    for (int c = 0; c < ncomp; ++c)
      (*out)[i * ncomp + c] = decode(base + i * stride + size_t(c) * csize, ctype, normalized);
}

// Accessor elements as T (count * components values), sparse substitution applied
template <typename T, typename Decode>
std::vector<T> read_accessor_as(const tinygltf::Model& model, int index, int want_components, Decode decode) {
  if (index < 0 || index >= (int)model.accessors.size())
    throw Error("glTF accessor " + std::to_string(index) + " does not exist");
  const tinygltf::Accessor& acc = model.accessors[index];
  int comps = tinygltf::GetNumComponentsInType(acc.type);
  if (comps <= 0) throw Error("glTF accessor " + std::to_string(index) + " has an invalid type");
  if (want_components > 0 && comps != want_components)
    throw Error("glTF accessor " + std::to_string(index) + " has " + std::to_string(comps) + " components, expected " +
                std::to_string(want_components));
  std::vector<T> values;
  if (acc.bufferView >= 0) {
    read_view(model, acc.bufferView, acc.byteOffset, acc.count, comps, acc.componentType, acc.normalized, decode,
              &values);
  } else {
    if (acc.count > kMaxZeroFilledValues / size_t(comps))
      throw Error("glTF accessor " + std::to_string(index) + " is too large for one without a bufferView (" +
                  std::to_string(acc.count) + " elements)");
    values.assign(acc.count * comps, T(0));
  }
  if (acc.sparse.isSparse) {
    if (acc.sparse.count < 0 || size_t(acc.sparse.count) > acc.count || acc.sparse.indices.byteOffset < 0 ||
        acc.sparse.values.byteOffset < 0)
      throw Error("glTF sparse accessor " + std::to_string(index) + " is malformed");
    std::vector<uint32_t> idx;
    std::vector<T> vals;
    read_view(model, acc.sparse.indices.bufferView, size_t(acc.sparse.indices.byteOffset), size_t(acc.sparse.count), 1,
              acc.sparse.indices.componentType, false, decode_uint, &idx);
    read_view(model, acc.sparse.values.bufferView, size_t(acc.sparse.values.byteOffset), size_t(acc.sparse.count),
              comps, acc.componentType, acc.normalized, decode, &vals);
    for (size_t i = 0; i < idx.size(); ++i) {
      if (idx[i] >= acc.count) throw Error("glTF sparse accessor index out of range");
      for (int c = 0; c < comps; ++c) values[size_t(idx[i]) * comps + c] = vals[i * comps + c];
    }
  }
  return values;
}

}  // namespace

std::vector<float> read_accessor(const tinygltf::Model& model, int index, int want_components) {
  return read_accessor_as<float>(model, index, want_components, decode_float);
}

std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index) {
  return read_accessor_as<uint32_t>(model, index, 1, decode_uint);
}

}  // namespace candela::gltf
