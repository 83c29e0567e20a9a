// glTF skins (specification 3.7.3): joint matrices from the node transforms, the pose a
// viewer shows without animation. Joints outside the default scene are placed by their own
// node trees, walked up without recursion.
#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

// Each node's parent, or -1 (the first parent met when a malformed file gives two)
std::vector<int> parents(const tinygltf::Model& model) {
  std::vector<int> parent(model.nodes.size(), -1);
  for (size_t p = 0; p < model.nodes.size(); ++p)
    for (int c : model.nodes[p].children)
      if (c >= 0 && c < (int)parent.size() && parent[size_t(c)] < 0) parent[size_t(c)] = int(p);
  return parent;
}

}  // namespace

glm::mat4 node_world(ReadContext& ctx, int node) {
  if (node < 0 || node >= (int)ctx.model.nodes.size())
    throw Error("glTF node " + std::to_string(node) + " does not exist");
  if (size_t(node) < ctx.visited.size() && ctx.visited[size_t(node)]) return ctx.world[size_t(node)];
  // Up to a node of the default scene or a root, then the local transforms back down
  if (ctx.parent.empty()) ctx.parent = parents(ctx.model);
  const std::vector<int>& parent = ctx.parent;
  std::vector<int> chain;
  int n = node;
  for (; n >= 0 && !(size_t(n) < ctx.visited.size() && ctx.visited[size_t(n)]); n = parent[size_t(n)]) {
    if (chain.size() > ctx.model.nodes.size()) throw Error("glTF node " + std::to_string(node) + " is part of a cycle");
    chain.push_back(n);
  }
  glm::mat4 world = n >= 0 ? ctx.world[size_t(n)] : glm::mat4(1.0f);
  for (auto it = chain.rbegin(); it != chain.rend(); ++it)
    world = world * local_transform(ctx.model.nodes[size_t(*it)]);
  return world;
}

const std::vector<glm::mat4>& joint_matrices(ReadContext& ctx, int skin) {
  if (auto it = ctx.skin_joints.find(skin); it != ctx.skin_joints.end()) return it->second;
  if (skin < 0 || skin >= (int)ctx.model.skins.size())
    throw Error("glTF skin " + std::to_string(skin) + " does not exist");
  const tinygltf::Skin& s = ctx.model.skins[size_t(skin)];
  const std::string where = "glTF skin " + std::to_string(skin);
  std::vector<float> inverse_bind;
  if (s.inverseBindMatrices >= 0) {
    inverse_bind = read_accessor(ctx.model, s.inverseBindMatrices, 16);
    if (inverse_bind.size() < 16 * s.joints.size()) throw Error(where + ": fewer inverseBindMatrices than joints");
  }
  std::vector<glm::mat4> joints;
  joints.reserve(s.joints.size());
  for (size_t j = 0; j < s.joints.size(); ++j) {
    glm::mat4 ibm(1.0f);
    if (!inverse_bind.empty())
      for (int k = 0; k < 16; ++k) ibm[k / 4][k % 4] = inverse_bind[16 * j + size_t(k)];  // column-major
    joints.push_back(node_world(ctx, s.joints[j]) * ibm);
  }
  return ctx.skin_joints[skin] = std::move(joints);
}

}  // namespace candela::gltf
