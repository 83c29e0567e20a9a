// glTF nodes: the default scene's node trees with their transforms (walked without
// recursion, however deep), the cameras, and EXT_mesh_gpu_instancing's instance transforms.
#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <optional>

#include "base/error.hpp"
#include "gltf/limits.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

// Translation x rotation x scale, each optional (empty: identity), as glTF orders them
glm::mat4 trs(const std::vector<double>& t, const std::vector<double>& r, const std::vector<double>& s) {
  glm::mat4 m(1.0f);
  if (t.size() == 3) m = glm::translate(m, glm::vec3(t[0], t[1], t[2]));
  if (r.size() == 4) {
    glm::quat q(static_cast<float>(r[3]), static_cast<float>(r[0]), static_cast<float>(r[1]), static_cast<float>(r[2]));
    m *= glm::mat4_cast(glm::normalize(q));
  }
  if (s.size() == 3) m = glm::scale(m, glm::vec3(s[0], s[1], s[2]));
  return m;
}

// Thin lens: cameras[i].extras.candela = {"aperture_radius": R, "focus_distance": D}
void read_camera_extras(const tinygltf::Value& extras, CameraDesc* cam) {
  if (!extras.IsObject() || !extras.Has("candela")) return;
  const tinygltf::Value& c = extras.Get("candela");
  auto number = [&](const char* key) -> std::optional<double> {
    if (!c.Has(key)) return std::nullopt;
    const tinygltf::Value& v = c.Get(key);
    if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
      throw Error(std::string("camera extras candela.") + key + " must be a finite number");
    return v.GetNumberAsDouble();
  };
  if (auto r = number("aperture_radius")) {
    if (*r < 0.0) throw Error("camera extras candela.aperture_radius must not be negative");
    if (*r > 0.0 && cam->projection == Projection::Orthographic)
      throw Error(
          "camera extras candela.aperture_radius: an orthographic camera has no lens (depth of field needs a "
          "perspective camera)");
    cam->aperture_radius = float(*r);
  }
  if (auto d = number("focus_distance")) {
    if (!(*d > 0.0)) throw Error("camera extras candela.focus_distance must be positive");
    cam->focus_distance = float(*d);
  }
}

// A camera node, perspective or orthographic, into Scene::cameras (the first met also into
// Scene::camera); znear and zfar are ignored (rays start at the camera and are never clipped)
void read_camera(ReadContext& ctx, int index, const glm::mat4& world) {
  if (index >= (int)ctx.model.cameras.size()) throw Error("glTF camera " + std::to_string(index) + " does not exist");
  const tinygltf::Camera& c = ctx.model.cameras[size_t(index)];
  CameraDesc cam;
  if (c.type == "perspective") {
    cam.yfov = float(c.perspective.yfov);
    cam.aspect = float(c.perspective.aspectRatio);
    if (!(cam.yfov > 0.0f && cam.yfov < 3.14159f)) throw Error("glTF camera has an invalid yfov");
  } else if (c.type == "orthographic") {
    cam.projection = Projection::Orthographic;
    // The spec forbids zero and advises against negative magnifications: take |mag|
    double xmag = std::fabs(c.orthographic.xmag), ymag = std::fabs(c.orthographic.ymag);
    if (!(xmag > 0.0 && ymag > 0.0 && xmag < 1e15 && ymag < 1e15))
      throw Error("glTF orthographic camera needs finite, non-zero xmag and ymag");
    cam.ymag = float(ymag);
    cam.aspect = float(xmag / ymag);
  } else {
    ctx.warn.add("camera type '" + c.type + "' is not supported; it is skipped");
    return;
  }
  cam.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
  cam.forward = glm::normalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)));
  cam.up = glm::normalize(glm::vec3(world * glm::vec4(0, 1, 0, 0)));
  read_camera_extras(c.extras, &cam);
  cam.name = c.name.empty() ? "camera " + std::to_string(index) : c.name;
  ctx.scene.cameras.push_back(cam);
  if (!ctx.scene.camera) ctx.scene.camera = cam;  // the first is the default (render --camera N picks another)
}

// Each node of the default scene once, parents before children, in depth-first order
// (children in their order); glTF 3.5.2 makes nodes disjoint strict trees (no node has two
// parents, no cycles). An explicit stack: a file can nest nodes a million deep.
std::vector<int> walk_scene(ReadContext& ctx, const std::vector<int>& roots) {
  const size_t n = ctx.model.nodes.size();
  ctx.visited.assign(n, false);
  ctx.world.assign(n, glm::mat4(1.0f));
  std::vector<int> order;
  std::vector<std::pair<int, int>> stack;  // (node, parent or -1)
  for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.emplace_back(*r, -1);
  while (!stack.empty()) {
    auto [index, parent] = stack.back();
    stack.pop_back();
    if (index < 0 || index >= (int)n) throw Error("glTF node " + std::to_string(index) + " does not exist");
    if (ctx.visited[size_t(index)])
      throw Error("glTF node " + std::to_string(index) + " has two parents or is part of a cycle");
    ctx.visited[size_t(index)] = true;
    const tinygltf::Node& node = ctx.model.nodes[size_t(index)];
    glm::mat4 local = local_transform(node);
    ctx.world[size_t(index)] = parent < 0 ? glm::mat4(1.0f) * local : ctx.world[size_t(parent)] * local;
    order.push_back(index);
    for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.emplace_back(*c, index);
  }
  return order;
}

// A node's mesh, camera and light, placed by its world transform
void read_node(ReadContext& ctx, int index) {
  const tinygltf::Node& node = ctx.model.nodes[size_t(index)];
  const glm::mat4& world = ctx.world[size_t(index)];
  if (node.mesh >= 0) read_node_mesh(ctx, index);
  if (node.camera >= 0) read_camera(ctx, node.camera, world);
  if (auto ext = node.extensions.find("KHR_lights_punctual"); ext != node.extensions.end())
    read_node_light(ctx, index, ext->second, world);
}

// The default scene's roots (and its extras); without scenes, every node no other names
std::vector<int> root_nodes(ReadContext& ctx) {
  std::vector<int> roots;
  int scene_index = ctx.model.defaultScene >= 0 ? ctx.model.defaultScene : 0;
  if (ctx.model.defaultScene >= (int)ctx.model.scenes.size())
    throw Error("glTF 'scene' " + std::to_string(ctx.model.defaultScene) + " does not exist");
  if (scene_index < (int)ctx.model.scenes.size()) {
    const tinygltf::Scene& s = ctx.model.scenes[size_t(scene_index)];
    roots = s.nodes;
    read_scene_extras(ctx, s.extras);
    return roots;
  }
  std::vector<bool> is_child(ctx.model.nodes.size(), false);
  for (const auto& n : ctx.model.nodes)
    for (int c : n.children)
      if (c >= 0 && c < (int)is_child.size()) is_child[size_t(c)] = true;
  for (size_t i = 0; i < ctx.model.nodes.size(); ++i)
    if (!is_child[i]) roots.push_back(int(i));
  return roots;
}

}  // namespace

glm::mat4 local_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(node.matrix[i]);  // column-major
    return m;
  }
  return trs(node.translation, node.rotation, node.scale);
}

std::vector<glm::mat4> instance_transforms(ReadContext& ctx, int node_index) {
  const tinygltf::Node& node = ctx.model.nodes[size_t(node_index)];
  auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
  if (ext == node.extensions.end() || !ext->second.Has("attributes")) return {};
  const tinygltf::Value& attributes = ext->second.Get("attributes");
  const std::string where = "glTF node " + std::to_string(node_index) + " EXT_mesh_gpu_instancing";
  std::vector<double> columns[3];  // TRANSLATION, ROTATION, SCALE
  const char* kNames[3] = {"TRANSLATION", "ROTATION", "SCALE"};
  size_t count = 0;
  bool any = false;
  for (int a = 0; a < 3; ++a) {
    if (!attributes.Has(kNames[a])) continue;
    const tinygltf::Value& v = attributes.Get(kNames[a]);
    int accessor = v.IsNumber() ? int(std::clamp(v.GetNumberAsDouble(), -1.0, 1e9)) : -1;
    if (accessor < 0 || accessor >= (int)ctx.model.accessors.size())
      throw Error(where + ": " + kNames[a] + " is not a valid accessor");
    const tinygltf::Accessor& acc = ctx.model.accessors[size_t(accessor)];
    if (acc.bufferView < 0 && acc.count > kMaxZeroFilledInstances)
      throw Error(where + ": " + kNames[a] + " has " + std::to_string(acc.count) +
                  " instances but no bufferView (at most " + std::to_string(kMaxZeroFilledInstances) + ")");
    std::vector<float> values = read_accessor(ctx.model, accessor, a == 1 ? 4 : 3);
    size_t n = acc.count;
    if (any && n != count) throw Error(where + ": its accessors have different counts");
    count = n;
    any = true;
    columns[a].assign(values.begin(), values.end());
  }
  std::vector<glm::mat4> out;
  out.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    auto part = [&](int a, int comps) {
      return columns[a].empty() ? std::vector<double>()
                                : std::vector<double>(columns[a].begin() + ptrdiff_t(i * comps),
                                                      columns[a].begin() + ptrdiff_t((i + 1) * comps));
    };
    out.push_back(trs(part(0, 3), part(1, 4), part(2, 3)));
  }
  return out;
}

void read_nodes(ReadContext& ctx) {
  std::vector<int> roots = root_nodes(ctx);
  for (int index : walk_scene(ctx, roots)) read_node(ctx, index);
  if (ctx.degenerate > 0) ctx.warn.add(std::to_string(ctx.degenerate) + " zero-area triangles were skipped");
}

}  // namespace candela::gltf
