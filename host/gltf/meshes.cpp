// glTF meshes: each primitive's vertex attributes (placed in the world) and triangles,
// and the tangents a normal-mapped primitive without TANGENT needs.
#include <algorithm>
#include <cmath>

#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

bool renderable(ReadContext& ctx, const tinygltf::Primitive& prim) {
  if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      prim.mode != TINYGLTF_MODE_TRIANGLE_FAN && prim.mode != -1) {
    ctx.warn.add("point and line primitives are not rendered");
    return false;
  }
  if (!prim.targets.empty()) ctx.warn.add("morph targets are not supported yet: base geometry is rendered");
  if (prim.extensions.count("KHR_draco_mesh_compression")) {
    ctx.warn.add("Draco-compressed primitives (KHR_draco_mesh_compression) are not supported: they are skipped");
    return false;
  }
  if (!prim.attributes.count("POSITION")) {
    ctx.warn.add("a primitive without POSITION was skipped");
    return false;
  }
  return true;
}

// Attribute `name` with `comps` components per vertex (0: VEC3 or VEC4), or empty
std::vector<float> attribute(const ReadContext& ctx, const tinygltf::Primitive& prim, const std::string& name,
                             int comps, size_t nverts, int* got_comps = nullptr) {
  auto it = prim.attributes.find(name);
  if (it == prim.attributes.end()) return {};
  std::vector<float> v = read_accessor(ctx.model, it->second, comps);
  int c = tinygltf::GetNumComponentsInType(ctx.model.accessors[size_t(it->second)].type);
  if (got_comps) *got_comps = c;
  if (v.size() != nverts * size_t(c)) throw Error("glTF primitive attributes have different vertex counts");
  return v;
}

// COLOR_0: RGB or RGBA (its alpha is not used, alphaMode reads the base colour's), linear, in [0, 1]
void read_colors(const ReadContext& ctx, const tinygltf::Primitive& prim, size_t n, MeshDesc* m) {
  int comps = 0;
  std::vector<float> col = attribute(ctx, prim, "COLOR_0", 0, n, &comps);
  if (col.empty()) return;
  if (comps != 3 && comps != 4) throw Error("glTF COLOR_0 must be VEC3 or VEC4");
  for (float c : col)
    if (!(c >= 0.0f && c <= 1.0f))
      throw Error("glTF COLOR_0 values must lie in [0, 1] (integer colors must be normalized)");
  for (size_t v = 0; v < n; ++v) m->colors.push_back(glm::vec3(col[comps * v], col[comps * v + 1], col[comps * v + 2]));
}

void read_attributes(const ReadContext& ctx, const tinygltf::Primitive& prim, const glm::mat4& world, MeshDesc* m) {
  std::vector<float> pos = read_accessor(ctx.model, prim.attributes.at("POSITION"), 3);
  size_t n = pos.size() / 3;
  glm::mat3 linear(world), normal_matrix = glm::transpose(glm::inverse(linear));
  for (size_t v = 0; v < n; ++v) {
    glm::vec3 p = glm::vec3(world * glm::vec4(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2], 1.0f));
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error("glTF mesh has non-finite vertex positions");
    m->positions.push_back(p);
  }
  auto unit_or_zero = [](glm::vec3 v) {
    float len = glm::length(v);
    return len > 0.0f && std::isfinite(len) ? v / len : glm::vec3(0.0f);
  };
  std::vector<float> nrm = attribute(ctx, prim, "NORMAL", 3, n);
  for (size_t v = 0; v < nrm.size() / 3; ++v)
    m->normals.push_back(unit_or_zero(normal_matrix * glm::vec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2])));
  std::vector<float> tan = attribute(ctx, prim, "TANGENT", 4, n);
  for (size_t v = 0; v < tan.size() / 4; ++v)
    m->tangents.push_back(glm::vec4(unit_or_zero(linear * glm::vec3(tan[4 * v], tan[4 * v + 1], tan[4 * v + 2])),
                                    tan[4 * v + 3] < 0.0f ? -1.0f : 1.0f));
  for (int set = 0; set < 2; ++set) {
    std::vector<float> uv = attribute(ctx, prim, "TEXCOORD_" + std::to_string(set), 2, n);
    auto& out = set == 0 ? m->uv0 : m->uv1;
    for (size_t v = 0; v < uv.size() / 2; ++v) out.push_back(glm::vec2(uv[2 * v], uv[2 * v + 1]));
  }
  read_colors(ctx, prim, n, m);
}

// The TEXCOORD set of the primitive's normal texture, -1 without one
int normal_texcoord(const tinygltf::Model& model, const tinygltf::Primitive& prim) {
  if (prim.material < 0 || prim.material >= (int)model.materials.size()) return -1;
  const tinygltf::NormalTextureInfo& n = model.materials[size_t(prim.material)].normalTexture;
  return n.index >= 0 && (n.texCoord == 0 || n.texCoord == 1) ? n.texCoord : -1;
}

// Per-vertex tangents for a normal-mapped mesh without TANGENT, as the glTF specification
// asks (MikkTSpace-style, not bit-identical to it): each triangle's dp/du from the normal
// texture's coordinates, summed at its corners weighted by the corner angle, made
// orthogonal to the vertex normal; the bitangent sign w says whether cross(n, t) points
// toward decreasing v (+Y of the normal texture, glTF's convention) or away (mirrored
// UVs). Vertices without a usable tangent keep 0 (the kernel then uses dp/du).
void add_corner_tangents(const MeshDesc& m, const std::vector<glm::vec2>& uv, size_t t, std::vector<glm::vec3>* sum,
                         std::vector<float>* handed) {
  uint32_t idx[3] = {m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]};
  glm::vec3 e1 = m.positions[idx[1]] - m.positions[idx[0]], e2 = m.positions[idx[2]] - m.positions[idx[0]];
  glm::vec2 d1 = uv[idx[1]] - uv[idx[0]], d2 = uv[idx[2]] - uv[idx[0]];
  float det = d1.x * d2.y - d2.x * d1.y;
  if (!(std::fabs(det) > 1e-20f)) return;
  glm::vec3 dpdu = (d2.y * e1 - d1.y * e2) / det, dpdv = (d1.x * e2 - d2.x * e1) / det;
  float len = glm::length(dpdu);
  if (!(len > 0.0f) || !std::isfinite(len)) return;
  dpdu /= len;
  glm::vec3 face = glm::cross(e1, e2);
  for (int k = 0; k < 3; ++k) {
    glm::vec3 a = m.positions[idx[(k + 1) % 3]] - m.positions[idx[k]];
    glm::vec3 b = m.positions[idx[(k + 2) % 3]] - m.positions[idx[k]];
    float la = glm::length(a), lb = glm::length(b);
    if (!(la > 0.0f && lb > 0.0f)) continue;
    float angle = std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0f, 1.0f));
    glm::vec3 nv = m.normals.empty() || glm::dot(m.normals[idx[k]], m.normals[idx[k]]) == 0.0f ? glm::normalize(face)
                                                                                               : m.normals[idx[k]];
    (*sum)[idx[k]] += angle * dpdu;
    (*handed)[idx[k]] += angle * (glm::dot(glm::cross(nv, dpdu), -dpdv) < 0.0f ? -1.0f : 1.0f);
  }
}

void generate_tangents(int texcoord, MeshDesc* m) {
  const std::vector<glm::vec2>& uv = texcoord == 1 ? m->uv1 : m->uv0;
  if (texcoord < 0 || uv.size() != m->positions.size()) return;
  size_t n = m->positions.size();
  std::vector<glm::vec3> sum(n, glm::vec3(0.0f));
  std::vector<float> handed(n, 0.0f);
  for (size_t t = 0; t < m->triangles(); ++t) add_corner_tangents(*m, uv, t, &sum, &handed);
  m->tangents.assign(n, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
  for (size_t v = 0; v < n; ++v) {
    glm::vec3 t = sum[v];
    if (!m->normals.empty()) t -= glm::dot(m->normals[v], t) * m->normals[v];
    float len = glm::length(t);
    if (len > 1e-12f && std::isfinite(len)) m->tangents[v] = glm::vec4(t / len, handed[v] < 0.0f ? -1.0f : 1.0f);
  }
}

// The primitive's indices, or 0, 1, ... without them; each below nverts
std::vector<uint32_t> primitive_indices(const ReadContext& ctx, const tinygltf::Primitive& prim, size_t nverts) {
  std::vector<uint32_t> indices;
  if (prim.indices >= 0) {
    indices = read_indices(ctx.model, prim.indices);
  } else {
    for (uint32_t i = 0; i < nverts; ++i) indices.push_back(i);
  }
  for (uint32_t i : indices)
    if (i >= nverts) throw Error("glTF primitive index out of range");
  return indices;
}

// Triangles from TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN, zero-area ones skipped
void read_triangles(ReadContext& ctx, const tinygltf::Primitive& prim, const glm::mat4& world, MeshDesc* m) {
  std::vector<uint32_t> indices = primitive_indices(ctx, prim, m->positions.size());
  bool mirrored = glm::determinant(glm::mat3(world)) < 0.0f;
  auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (mirrored) std::swap(b, c);  // a mirroring transform flips the winding
    double area;
    triangle_normal_area(m->positions[a], m->positions[b], m->positions[c], &area);
    if (!(area > 0.0)) {
      ++ctx.degenerate;  // zero area: invisible, and it has no normal
      return;
    }
    m->indices.insert(m->indices.end(), {a, b, c});
  };
  int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    for (size_t i = 0; i + 2 < indices.size(); i += 3) emit(indices[i], indices[i + 1], indices[i + 2]);
  } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
    for (size_t i = 0; i + 2 < indices.size(); ++i) {
      if (i % 2 == 0)
        emit(indices[i], indices[i + 1], indices[i + 2]);
      else
        emit(indices[i + 1], indices[i], indices[i + 2]);
    }
  } else {
    for (size_t i = 1; i + 1 < indices.size(); ++i) emit(indices[i], indices[i + 1], indices[0]);
  }
}

}  // namespace

void read_mesh(ReadContext& ctx, const tinygltf::Mesh& mesh, const glm::mat4& world) {
  for (const auto& prim : mesh.primitives) {
    if (!renderable(ctx, prim)) continue;
    MeshDesc m;
    m.material = prim.material >= 0 && prim.material < (int)ctx.model.materials.size()
                     ? uint32_t(prim.material)
                     : uint32_t(ctx.model.materials.size());  // the default material
    read_attributes(ctx, prim, world, &m);
    read_triangles(ctx, prim, world, &m);
    if (m.tangents.empty()) generate_tangents(normal_texcoord(ctx.model, prim), &m);
    if (m.triangles() > 0) ctx.scene.meshes.push_back(std::move(m));
  }
}

}  // namespace candela::gltf
