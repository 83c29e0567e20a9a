// Input size limits of the glTF loader: what a few bytes of a hostile file could otherwise
// make it allocate, decode or recurse into.
#pragma once

#include <cstddef>
#include <cstdint>

namespace candela::gltf {

// A whole .gltf or .glb file (tinygltf takes its size as 32 bits)
constexpr uint64_t kMaxFileBytes = UINT32_MAX;

// Values (elements x components) of one accessor without a bufferView (zero-filled): it
// takes no room in the file, so a few bytes could ask for gigabytes
constexpr size_t kMaxZeroFilledValues = size_t(1) << 24;

// glTF images are PNG or JPEG (3.8.2). Their headers give the size before anything is
// decoded, so a few bytes claiming a huge image cannot make stb_image allocate and fill
// gigabytes.
constexpr uint64_t kMaxImageBytes = uint64_t(1) << 30;  // decoded RGBA: 16384^2 at 8 bits
// stb_image decodes a truncated JPEG as if the rest were there. Huffman coding spends at
// least a bit on each 8x8 block, so a whole JPEG has at most 512 texels a byte: allow twice.
constexpr uint64_t kMaxJpegTexelsPerByte = 1024;

// EXT_meshopt_compression: its codecs spend at least 2 bits on 16 bytes of attribute data
// (64:1), a byte on a triangle's 6 or 12 bytes and on each index: a bufferView may decode to
// at most 64 times its compressed size, and never past the bufferView's own byteLength
constexpr uint64_t kMaxMeshoptExpansion = 64;

// EXT_mesh_gpu_instancing: each instance is a copy of the mesh's triangles (no two-level
// BVH), so the instanced triangles of a scene are bounded (33.5 M: several GB with the BVH);
// and an instance accessor without a bufferView, which takes no room in the file, holds at
// most this many instances
constexpr size_t kMaxInstancedTriangles = size_t(1) << 25;
constexpr size_t kMaxZeroFilledInstances = 1024;

// Array and object nesting of the JSON: tinygltf converts extras and extensions
// recursively, and deep nesting would overflow the stack. glTF itself needs under 10.
constexpr size_t kMaxJsonDepth = 64;

}  // namespace candela::gltf
