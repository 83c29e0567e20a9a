// glTF meshes: each primitive's vertex attributes with the default morph weights applied,
// placed in the world by the node's transform, its skin's joints or each of its
// EXT_mesh_gpu_instancing instances (every instance a copy), its triangles, and the
// tangents a normal-mapped primitive without TANGENT needs.
#include <algorithm>
#include <cmath>

#include "base/error.hpp"
#include "gltf/limits.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

// A primitive's vertex data in its mesh's space, morph targets applied, before placement
struct LocalPrimitive {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec4> tangents;
  std::vector<glm::vec2> uv0, uv1;
  std::vector<glm::vec3> colors;
  std::vector<uint32_t> indices;       // as stored (or 0, 1, ...), each below the vertex count
  std::vector<float> joints, weights;  // JOINTS_n / WEIGHTS_n: 4 or 8 influences a vertex
  int influences = 0;
  size_t vertices() const { return positions.size(); }
};

bool renderable(ReadContext& ctx, const tinygltf::Primitive& prim) {
  if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
      prim.mode != TINYGLTF_MODE_TRIANGLE_FAN && prim.mode != -1) {
    ctx.warn.add("point and line primitives are not rendered");
    return false;
  }
  if (prim.extensions.count("KHR_draco_mesh_compression")) return false;  // did not decode (draco.cpp warned)
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
void read_colors(const ReadContext& ctx, const tinygltf::Primitive& prim, size_t n, LocalPrimitive* m) {
  int comps = 0;
  std::vector<float> col = attribute(ctx, prim, "COLOR_0", 0, n, &comps);
  if (col.empty()) return;
  if (comps != 3 && comps != 4) throw Error("glTF COLOR_0 must be VEC3 or VEC4");
  for (float c : col)
    if (!(c >= 0.0f && c <= 1.0f))
      throw Error("glTF COLOR_0 values must lie in [0, 1] (integer colors must be normalized)");
  for (size_t v = 0; v < n; ++v) m->colors.push_back(glm::vec3(col[comps * v], col[comps * v + 1], col[comps * v + 2]));
}

void read_attributes(const ReadContext& ctx, const tinygltf::Primitive& prim, LocalPrimitive* m) {
  std::vector<float> pos = read_accessor(ctx.model, prim.attributes.at("POSITION"), 3);
  size_t n = pos.size() / 3;
  for (size_t v = 0; v < n; ++v) m->positions.push_back(glm::vec3(pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]));
  std::vector<float> nrm = attribute(ctx, prim, "NORMAL", 3, n);
  for (size_t v = 0; v < nrm.size() / 3; ++v)
    m->normals.push_back(glm::vec3(nrm[3 * v], nrm[3 * v + 1], nrm[3 * v + 2]));
  std::vector<float> tan = attribute(ctx, prim, "TANGENT", 4, n);
  for (size_t v = 0; v < tan.size() / 4; ++v)
    m->tangents.push_back(glm::vec4(tan[4 * v], tan[4 * v + 1], tan[4 * v + 2], tan[4 * v + 3]));
  for (int set = 0; set < 2; ++set) {
    std::vector<float> uv = attribute(ctx, prim, "TEXCOORD_" + std::to_string(set), 2, n);
    auto& out = set == 0 ? m->uv0 : m->uv1;
    for (size_t v = 0; v < uv.size() / 2; ++v) out.push_back(glm::vec2(uv[2 * v], uv[2 * v + 1]));
  }
  read_colors(ctx, prim, n, m);
}

// The morph weights (glTF 3.7.2.2): the node's, else the mesh's, else 0
const std::vector<double>& morph_weights(const tinygltf::Node& node, const tinygltf::Mesh& mesh) {
  return node.weights.empty() ? mesh.weights : node.weights;
}

// POSITION, NORMAL and TANGENT displacements of each target times its weight (glTF 3.7.2.2),
// sparse or not; targets of weight 0 are not read
void apply_morph_targets(ReadContext& ctx, const tinygltf::Primitive& prim, const std::vector<double>& weights,
                         LocalPrimitive* m) {
  size_t n = m->vertices();
  for (size_t t = 0; t < prim.targets.size(); ++t) {
    double w = t < weights.size() ? weights[t] : 0.0;
    if (!std::isfinite(w)) throw Error("glTF morph target weights must be finite");
    if (w == 0.0) continue;
    float wf = float(w);
    for (const auto& [name, accessor] : prim.targets[t]) {
      if (name != "POSITION" && name != "NORMAL" && name != "TANGENT") {
        ctx.warn.add("morph target " + name + " displacements are not applied (only POSITION, NORMAL and TANGENT)");
        continue;
      }
      std::vector<float> d = read_accessor(ctx.model, accessor, 3);
      if (d.size() != 3 * n) throw Error("glTF morph target " + name + " has a different vertex count");
      for (size_t v = 0; v < n; ++v) {
        glm::vec3 delta = wf * glm::vec3(d[3 * v], d[3 * v + 1], d[3 * v + 2]);
        if (name == "POSITION") {
          m->positions[v] += delta;
        } else if (name == "NORMAL" && !m->normals.empty()) {
          m->normals[v] += delta;
        } else if (name == "TANGENT" && !m->tangents.empty()) {
          m->tangents[v] += glm::vec4(delta, 0.0f);
        }
      }
    }
  }
}

// JOINTS_0/WEIGHTS_0 and JOINTS_1/WEIGHTS_1: four influences each, interleaved per vertex
void read_skin_attributes(const ReadContext& ctx, const tinygltf::Primitive& prim, LocalPrimitive* m) {
  size_t n = m->vertices();
  std::vector<float> joints[2], weights[2];
  for (int set = 0; set < 2; ++set) {
    joints[set] = attribute(ctx, prim, "JOINTS_" + std::to_string(set), 4, n);
    weights[set] = attribute(ctx, prim, "WEIGHTS_" + std::to_string(set), 4, n);
    if (joints[set].empty() != weights[set].empty())
      throw Error("glTF JOINTS_" + std::to_string(set) + " and WEIGHTS_" + std::to_string(set) + " come in pairs");
    if (!joints[set].empty()) m->influences += 4;
  }
  if (m->influences == 0) return;
  m->joints.reserve(n * size_t(m->influences));
  m->weights.reserve(n * size_t(m->influences));
  for (size_t v = 0; v < n; ++v)
    for (int set = 0; set < 2; ++set)
      for (size_t k = 0; !joints[set].empty() && k < 4; ++k) {
        m->joints.push_back(joints[set][4 * v + k]);
        m->weights.push_back(weights[set][4 * v + k]);
      }
}

glm::vec3 unit_or_zero(glm::vec3 v) {
  float len = glm::length(v);
  return len > 0.0f && std::isfinite(len) ? v / len : glm::vec3(0.0f);
}

// The vertices placed in the world, vertex v by matrix_of(v) (a reference that stays valid;
// one matrix for many vertices is inverted once)
template <typename MatrixOf>
void place_vertices(const LocalPrimitive& lp, MatrixOf matrix_of, MeshDesc* m) {
  const glm::mat4* last = nullptr;
  glm::mat3 linear(1.0f), normal_matrix(1.0f);
  auto matrices = [&](size_t v) -> const glm::mat4& {
    const glm::mat4& world = matrix_of(v);
    if (&world != last) {
      last = &world;
      linear = glm::mat3(world);
      normal_matrix = glm::transpose(glm::inverse(linear));
    }
    return world;
  };
  for (size_t v = 0; v < lp.vertices(); ++v) {
    glm::vec3 p = glm::vec3(matrices(v) * glm::vec4(lp.positions[v], 1.0f));
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw Error("glTF mesh has non-finite vertex positions");
    m->positions.push_back(p);
  }
  for (size_t v = 0; v < lp.normals.size(); ++v) {
    matrices(v);
    m->normals.push_back(unit_or_zero(normal_matrix * lp.normals[v]));
  }
  for (size_t v = 0; v < lp.tangents.size(); ++v) {
    matrices(v);
    const glm::vec4& t = lp.tangents[v];
    m->tangents.push_back(glm::vec4(unit_or_zero(linear * glm::vec3(t)), t.w < 0.0f ? -1.0f : 1.0f));
  }
  m->uv0 = lp.uv0;
  m->uv1 = lp.uv1;
  m->colors = lp.colors;
}

// Each vertex's skinning matrix (glTF 3.7.3.3): the weighted sum of its joints' matrices,
// weights normalized to sum 1; a vertex without weight keeps the node's transform
std::vector<glm::mat4> skinning_matrices(const LocalPrimitive& lp, const std::vector<glm::mat4>& joints,
                                         const glm::mat4& node_world) {
  std::vector<glm::mat4> out(lp.vertices());
  size_t k = size_t(lp.influences);
  for (size_t v = 0; v < lp.vertices(); ++v) {
    glm::mat4 sum(0.0f);
    float total = 0.0f;
    for (size_t i = v * k; i < (v + 1) * k; ++i) {
      float w = lp.weights[i];
      if (!(w >= 0.0f) || !std::isfinite(w)) throw Error("glTF WEIGHTS must be finite and non-negative");
      if (w == 0.0f) continue;
      if (!(lp.joints[i] < float(joints.size())))
        throw Error("glTF JOINTS refers to joint " + std::to_string(size_t(lp.joints[i])) + " of a skin of " +
                    std::to_string(joints.size()));
      sum += w * joints[size_t(lp.joints[i])];
      total += w;
    }
    out[v] = total > 0.0f ? sum * (1.0f / total) : node_world;
  }
  return out;
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

// Triangles from TRIANGLES, TRIANGLE_STRIP or TRIANGLE_FAN, zero-area ones skipped; a
// triangle whose first vertex is placed by a mirroring transform has its winding flipped
template <typename Mirrored>
void add_triangles(ReadContext& ctx, const tinygltf::Primitive& prim, const std::vector<uint32_t>& indices,
                   Mirrored mirrored, MeshDesc* m) {
  auto emit = [&](uint32_t a, uint32_t b, uint32_t c) {
    if (mirrored(a)) std::swap(b, c);  // a mirroring transform flips the winding
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

// Triangles the primitive's indices make (before zero-area ones are skipped)
size_t triangle_count(const tinygltf::Primitive& prim, size_t indices) {
  int mode = prim.mode == -1 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
  return mode == TINYGLTF_MODE_TRIANGLES ? indices / 3 : indices > 2 ? indices - 2 : 0;
}

void add_mesh(ReadContext& ctx, MeshDesc&& m, int normal_texcoord) {
  if (m.tangents.empty()) generate_tangents(normal_texcoord, &m);
  if (m.triangles() > 0) ctx.scene.meshes.push_back(std::move(m));
}

// The primitive once, by one transform
void place_rigid(ReadContext& ctx, const tinygltf::Primitive& prim, const LocalPrimitive& lp, const glm::mat4& world) {
  MeshDesc m;
  m.material = uint32_t(primitive_material(ctx, prim));
  place_vertices(
      lp, [&](size_t) -> const glm::mat4& { return world; }, &m);
  bool mirrored = glm::determinant(glm::mat3(world)) < 0.0f;
  add_triangles(
      ctx, prim, lp.indices, [&](uint32_t) { return mirrored; }, &m);
  add_mesh(ctx, std::move(m), normal_texcoord(ctx.model, prim));
}

// The primitive posed by its skin's joints
void place_skinned(ReadContext& ctx, const tinygltf::Primitive& prim, const LocalPrimitive& lp,
                   const std::vector<glm::mat4>& joints, const glm::mat4& node_world) {
  std::vector<glm::mat4> skin = skinning_matrices(lp, joints, node_world);
  MeshDesc m;
  m.material = uint32_t(primitive_material(ctx, prim));
  place_vertices(
      lp, [&](size_t v) -> const glm::mat4& { return skin[v]; }, &m);
  add_triangles(
      ctx, prim, lp.indices, [&](uint32_t v) { return glm::determinant(glm::mat3(skin[v])) < 0.0f; }, &m);
  add_mesh(ctx, std::move(m), normal_texcoord(ctx.model, prim));
}

}  // namespace

void read_node_mesh(ReadContext& ctx, int node_index) {
  const tinygltf::Node& node = ctx.model.nodes[size_t(node_index)];
  if (node.mesh >= (int)ctx.model.meshes.size())
    throw Error("glTF node " + std::to_string(node_index) + " refers to a missing mesh");
  const tinygltf::Mesh& mesh = ctx.model.meshes[size_t(node.mesh)];
  const glm::mat4& world = ctx.world[size_t(node_index)];
  std::vector<glm::mat4> instances = instance_transforms(ctx, node_index);
  bool skinned = node.skin >= 0;
  if (skinned && !instances.empty()) {
    ctx.warn.add("EXT_mesh_gpu_instancing on a skinned mesh is ignored: the skinned mesh renders once");
    instances.clear();
  }
  for (const auto& prim : mesh.primitives) {
    if (!renderable(ctx, prim)) continue;
    LocalPrimitive lp;
    read_attributes(ctx, prim, &lp);
    apply_morph_targets(ctx, prim, morph_weights(node, mesh), &lp);
    lp.indices = primitive_indices(ctx, prim, lp.vertices());
    if (skinned) read_skin_attributes(ctx, prim, &lp);
    if (lp.influences > 0) {
      place_skinned(ctx, prim, lp, joint_matrices(ctx, node.skin), world);
    } else if (!instances.empty()) {
      ctx.instanced_triangles += triangle_count(prim, lp.indices.size()) * instances.size();
      if (ctx.instanced_triangles > kMaxInstancedTriangles)
        throw Error("EXT_mesh_gpu_instancing: the instances add up to over " + std::to_string(kMaxInstancedTriangles) +
                    " triangles, and candela copies every instance");
      for (const glm::mat4& instance : instances) place_rigid(ctx, prim, lp, world * instance);
    } else {
      place_rigid(ctx, prim, lp, world);
    }
  }
}

}  // namespace candela::gltf
