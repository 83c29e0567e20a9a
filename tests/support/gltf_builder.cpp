#include "support/gltf_builder.hpp"

#include <fstream>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <utility>

namespace candela::test {

using nlohmann::json;

namespace {
enum ComponentType { UNSIGNED_BYTE = 5121, UNSIGNED_SHORT = 5123, FLOAT = 5126 };

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
    for (int k = 3; k >= 0; --k) out += t[(v >> (6 * k)) & 63];
  }
  size_t rest = in.size() - i;
  if (rest > 0) {
    uint32_t v = uint8_t(in[i]) << 16;
    if (rest == 2) v |= uint8_t(in[i + 1]) << 8;
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += rest == 2 ? t[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

json vec(const glm::vec3& v) { return {v.x, v.y, v.z}; }
}  // namespace

GltfBuilder::GltfBuilder() {
  doc = {{"asset", {{"version", "2.0"}}}, {"scenes", {{{"nodes", json::array()}}}}, {"scene", 0}};
}

int GltfBuilder::add(const std::string& array, json item) {
  json& items = doc[array];
  items.push_back(std::move(item));
  return int(items.size()) - 1;
}

template <typename T>
int GltfBuilder::add_accessor(const std::vector<T>& data, int component_type, const char* type, json extra) {
  bin_.resize((bin_.size() + 3) & ~size_t(3), '\0');  // accessors start 4-byte aligned
  size_t bytes = data.size() * sizeof(T);
  int view = add("bufferViews", {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes}});
  bin_.append(reinterpret_cast<const char*>(data.data()), bytes);
  extra.update({{"bufferView", view}, {"componentType", component_type}, {"count", data.size()}, {"type", type}});
  return add("accessors", std::move(extra));
}

namespace {
size_t components(const std::string& type) {
  return type == "SCALAR"                   ? 1
         : type == "VEC2"                   ? 2
         : type == "VEC3"                   ? 3
         : type == "VEC4" || type == "MAT2" ? 4
         : type == "MAT3"                   ? 9
                                            : 16;
}
}  // namespace

int GltfBuilder::add_floats(const std::vector<float>& values, const char* type) {
  int a = add_accessor(values, FLOAT, type);
  doc["accessors"][size_t(a)]["count"] = values.size() / components(type);
  return a;
}

int GltfBuilder::add_ushorts(const std::vector<uint16_t>& values, const char* type) {
  int a = add_accessor(values, UNSIGNED_SHORT, type);
  doc["accessors"][size_t(a)]["count"] = values.size() / components(type);
  return a;
}

int GltfBuilder::add_mesh(const std::vector<Primitive>& primitives) {
  json prims = json::array();
  for (const Primitive& p : primitives) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const glm::vec3& v : p.positions) {
      lo = glm::min(lo, v);
      hi = glm::max(hi, v);
    }
    json prim = {{"mode", p.mode}};
    json& attr = prim["attributes"];
    attr["POSITION"] = add_accessor(p.positions, FLOAT, "VEC3", {{"min", vec(lo)}, {"max", vec(hi)}});
    if (!p.normals.empty()) attr["NORMAL"] = add_accessor(p.normals, FLOAT, "VEC3");
    if (!p.uvs.empty()) attr["TEXCOORD_0"] = add_accessor(p.uvs, FLOAT, "VEC2");
    if (!p.colors.empty()) attr["COLOR_0"] = add_accessor(p.colors, UNSIGNED_BYTE, "VEC4", {{"normalized", true}});
    if (!p.indices.empty()) prim["indices"] = add_accessor(p.indices, UNSIGNED_SHORT, "SCALAR");
    if (p.material >= 0) prim["material"] = p.material;
    prims.push_back(std::move(prim));
  }
  return add("meshes", {{"primitives", std::move(prims)}});
}

int GltfBuilder::add_node(json node) {
  int index = add("nodes", std::move(node));
  doc["scenes"][0]["nodes"].push_back(index);
  return index;
}

int GltfBuilder::add_camera(const glm::vec3& eye, const glm::vec3& target, float yfov) {
  // Rotation taking -z to the viewing direction, +y up
  glm::vec3 f = glm::normalize(target - eye);
  glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
  glm::vec3 u = glm::cross(r, f);
  glm::quat rot = glm::quat_cast(glm::mat3(r, u, -f));
  int camera = add("cameras", {{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", 0.001}}}});
  return add_node({{"camera", camera}, {"translation", vec(eye)}, {"rotation", {rot.x, rot.y, rot.z, rot.w}}});
}

void GltfBuilder::set_background(const glm::vec3& rgb) {
  doc["scenes"][0]["extras"]["candela"]["background"] = vec(rgb);
}

json GltfBuilder::document() const {
  json j = doc;
  if (!bin_.empty())
    j["buffers"] = {{{"byteLength", bin_.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin_)}}};
  return j;
}

void GltfBuilder::write(const std::string& path) const { std::ofstream(path) << document().dump(); }

GltfBuilder::Primitive quad_primitive(const float (&p)[4][3], int material) {
  GltfBuilder::Primitive q;
  for (const auto& corner : p) q.positions.push_back(glm::make_vec3(corner));
  q.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  q.indices = {0, 1, 2, 0, 2, 3};
  q.material = material;
  return q;
}

std::vector<GltfBuilder::Primitive> box_primitives(glm::vec3 lo, glm::vec3 hi, int material) {
  std::vector<GltfBuilder::Primitive> out;
  glm::vec3 c = 0.5f * (lo + hi), h = 0.5f * (hi - lo);
  for (int axis = 0; axis < 3; ++axis)
    for (float s : {-1.0f, 1.0f}) {
      glm::vec3 n(0.0f), a(0.0f), b(0.0f);
      n[axis] = s;
      a[(axis + 1) % 3] = h[(axis + 1) % 3];
      b[(axis + 2) % 3] = h[(axis + 2) % 3];
      if (s < 0.0f) std::swap(a, b);  // a x b along n
      glm::vec3 fc = c + n * h[axis];
      glm::vec3 p[4] = {fc - a - b, fc + a - b, fc + a + b, fc - a + b};
      float q[4][3];
      for (int k = 0; k < 4; ++k)
        for (int j = 0; j < 3; ++j) q[k][j] = p[k][j];
      out.push_back(quad_primitive(q, material));
    }
  return out;
}

GltfBuilder::Primitive sphere_primitive(const glm::vec3& center, float radius, int subdivisions, int material) {
  const float t = 1.6180339887f;
  std::vector<glm::vec3> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<glm::ivec3> f = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                               {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                               {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& x : v) x = glm::normalize(x);
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      auto key = std::minmax(a, b);
      if (auto it = mid.find(key); it != mid.end()) return it->second;
      v.push_back(glm::normalize(v[size_t(a)] + v[size_t(b)]));
      return mid[key] = int(v.size()) - 1;
    };
    std::vector<glm::ivec3> next;
    for (auto tri : f) {
      int a = midpoint(tri.x, tri.y), b = midpoint(tri.y, tri.z), c = midpoint(tri.z, tri.x);
      next.insert(next.end(), {{tri.x, a, c}, {tri.y, b, a}, {tri.z, c, b}, {a, b, c}});
    }
    f = next;
  }
  GltfBuilder::Primitive p;
  for (const auto& x : v) p.positions.push_back(center + radius * x);
  for (auto tri : f) {
    glm::vec3 a = v[size_t(tri.x)], b = v[size_t(tri.y)], c = v[size_t(tri.z)];
    bool outward = glm::dot(glm::cross(b - a, c - a), a + b + c) > 0.0f;
    for (int k : {tri.x, outward ? tri.y : tri.z, outward ? tri.z : tri.y}) p.indices.push_back(uint16_t(k));
  }
  p.material = material;
  return p;
}

}  // namespace candela::test
