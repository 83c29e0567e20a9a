// libFuzzer target over everything a scene file reaches on the host: the glTF loader
// (tinygltf included) and the compile step. candela::Error is the expected answer to
// bad input; anything else is a finding: a crash, an ASan or UBSan report, another
// exception, a hang, or compiled buffers that would make a kernel read out of bounds.
// Built with -DCANDELA_FUZZ=ON (clang); run by scripts/fuzz.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "base/error.hpp"
#include "compile/bvh_builder.hpp"
#include "compile/camera.hpp"
#include "compile/scene_compiler.hpp"
#include "gltf/gltf_loader.hpp"

namespace {

void require(bool ok, const char* what) {
  if (ok) return;
  std::fprintf(stderr, "gltf_fuzz: compiled scene breaks an invariant: %s\n", what);
  std::abort();
}

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// What the kernels assume of the scene buffers: every index lands inside its array
void check_compiled(const candela::CompiledScene& c, const candela::CameraDesc& camera) {
  const candela::dev::SceneBuffers& b = c.buffers;
  size_t vertices = b.positions.size() / 3;
  require(b.positions.size() == 3 * vertices && b.normals.size() == b.positions.size(), "vertex arrays");
  require(c.triangles == b.prims.size() && c.vertices == vertices, "counts");
  for (float p : b.positions) require(std::isfinite(p), "finite positions");
  for (const auto& p : b.prims) {
    for (unsigned v : p.v) require(v < vertices, "prim vertex index");
    require(p.material < b.materials.size(), "prim material index");
  }
  for (const auto& m : b.materials)
    for (const auto* t = m.textures; t != m.textures + candela::TEX_SLOTS; ++t) {
      require(t->index == NO_TEXTURE || (t->index >= 0 && size_t(t->index) < b.textures.size()), "texture index");
      require(t->index == NO_TEXTURE || t->texcoord <= 1, "texcoord set");
    }
  for (const auto& m : b.materials) {
    require(m.medium == NO_MEDIUM || (m.medium >= 0 && size_t(m.medium) < b.media.size()), "material medium index");
  }
  for (const auto& m : b.media) {
    if (m.type != MEDIUM_GRID) continue;
    size_t n = size_t(m.grid_size[0]) * m.grid_size[1] * m.grid_size[2];
    require(m.grid_size[0] >= 2 && m.grid_size[1] >= 2 && m.grid_size[2] >= 2, "grid size");
    require(size_t(m.grid_offset) + n <= b.densities.size(), "grid densities");
  }
  for (const auto& t : b.textures) {
    size_t texels = (t.flags & TEXTURE_FLOAT) ? b.texelsf.size() : b.texels8.size();
    require(t.width > 0 && t.height > 0, "texture size");
    require(size_t(t.offset) + size_t(t.width) * t.height <= texels, "texture texels");
  }
  require(b.light_alias.size() == (b.lights.empty() ? 0 : b.lights.size()), "light alias table");
  for (const auto& bin : b.light_alias) require(bin.alias < b.lights.size(), "light alias");
  double pmf = 0.0;
  for (const auto& l : b.lights) {
    require(l.type != LIGHT_TRIANGLE || l.index < b.prims.size(), "light primitive index");
    require(l.pmf > 0.0f && l.pmf <= 1.0f, "light pmf");
    pmf += l.pmf;
  }
  require(b.lights.empty() || std::fabs(pmf - 1.0) < 1e-4, "light pmfs sum to 1");
  require(
      c.environment_light == NO_LIGHT || (c.environment_light >= 0 && size_t(c.environment_light) < b.lights.size()),
      "environment light index");
  for (const auto& t : b.bvh_tris) require(t.prim < b.prims.size(), "BVH triangle prim");
  require(!b.bvh_nodes.empty(), "BVH root");
  for (const auto& n : b.bvh_nodes)
    for (int i = 0; i < 4; ++i) {
      if (n.lo_x[i] > n.hi_x[i]) continue;  // unused slot
      if (n.child[i] < 0) {                 // leaf run: ends at a BVH_TRI_LAST triangle inside the array
        size_t t = size_t(~n.child[i]);
        while (t < b.bvh_tris.size() && !(b.bvh_tris[t].flags & BVH_TRI_LAST)) ++t;
        require(t < b.bvh_tris.size(), "BVH leaf range");
      } else {
        require(n.child[i] > 0 && size_t(n.child[i]) < b.bvh_nodes.size(), "BVH child index");
      }
    }
  require(c.bvh_depth <= candela::kMaxBvhDepth, "BVH depth");
  require(finite3(camera.position) && finite3(camera.forward) && finite3(camera.up), "finite camera");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    // No base folder: external URIs cannot reach the file system
    candela::Scene scene = candela::load_gltf_from_memory(bytes, "");
    candela::CompiledScene compiled = candela::compile_scene(scene);
    check_compiled(compiled, candela::resolve_camera(scene));
    candela::compile_camera(scene, 64, 48);
  } catch (const candela::Error& e) {
    require(e.what()[0] != '\0', "an Error without a message");  // expected: bad input, told clearly
  }
  return 0;
}
