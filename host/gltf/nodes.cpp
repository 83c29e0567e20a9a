// glTF nodes: the default scene's node trees with their transforms, and the first camera.
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <optional>

#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

glm::mat4 local_transform(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = float(node.matrix[i]);  // column-major
    return m;
  }
  glm::mat4 m(1.0f);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]), float(node.rotation[2]));
    m *= glm::mat4_cast(glm::normalize(q));
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
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

// Each node once: glTF 3.5.2 makes nodes disjoint strict trees (no node has two parents,
// no cycles)
void visit(ReadContext& ctx, int index, const glm::mat4& parent) {
  if (index < 0 || index >= (int)ctx.model.nodes.size())
    throw Error("glTF node " + std::to_string(index) + " does not exist");
  if (ctx.visited[size_t(index)])
    throw Error("glTF node " + std::to_string(index) + " has two parents or is part of a cycle");
  ctx.visited[size_t(index)] = true;
  const tinygltf::Node& node = ctx.model.nodes[size_t(index)];
  glm::mat4 world = parent * local_transform(node);
  if (node.mesh >= 0) {
    if (node.mesh >= (int)ctx.model.meshes.size())
      throw Error("glTF node " + std::to_string(index) + " refers to a missing mesh");
    read_mesh(ctx, ctx.model.meshes[size_t(node.mesh)], world);
    if (!node.weights.empty() || !ctx.model.meshes[size_t(node.mesh)].weights.empty())
      ctx.warn.add("morph targets are not supported yet: base geometry is rendered");
  }
  if (node.camera >= 0) read_camera(ctx, node.camera, world);
  if (auto ext = node.extensions.find("KHR_lights_punctual"); ext != node.extensions.end())
    read_node_light(ctx, index, ext->second, world);
  for (int child : node.children) visit(ctx, child, world);
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

void read_nodes(ReadContext& ctx) {
  std::vector<int> roots = root_nodes(ctx);
  ctx.visited.assign(ctx.model.nodes.size(), false);
  for (int r : roots) visit(ctx, r, glm::mat4(1.0f));
  if (ctx.degenerate > 0) ctx.warn.add(std::to_string(ctx.degenerate) + " zero-area triangles were skipped");
}

}  // namespace candela::gltf
