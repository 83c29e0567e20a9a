#include "support/scenes.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "gltf/gltf_loader.hpp"

namespace candela::test {

using nlohmann::json;

json lambert_material(double albedo) {
  return {{"pbrMetallicRoughness", {{"baseColorFactor", {albedo, albedo, albedo, 1}}, {"metallicFactor", 0.0}}},
          {"extensions", {{"KHR_materials_specular", {{"specularFactor", 0.0}}}}}};
}

json emissive_material(glm::vec3 radiance) {
  float m = std::max({radiance.x, radiance.y, radiance.z});
  return {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0.0}}},
          {"emissiveFactor", {radiance.x / m, radiance.y / m, radiance.z / m}},
          {"extensions",
           {{"KHR_materials_emissive_strength", {{"emissiveStrength", m}}},
            {"KHR_materials_specular", {{"specularFactor", 0.0}}}}}};
}

json null_boundary_material(const json& medium) { return {{"extras", {{"candela", {{"medium", medium}}}}}}; }

GltfBuilder::Primitive quad_facing_up(float h, float y, int material) {
  return quad_primitive({{-h, y, h}, {h, y, h}, {h, y, -h}, {-h, y, -h}}, material);
}

GltfBuilder::Primitive quad_facing_down(float h, float y, int material) {
  return quad_primitive({{-h, y, -h}, {h, y, -h}, {h, y, h}, {-h, y, h}}, material);
}

GltfBuilder::Primitive quad_facing_down_rotated(float h, float y, int material) {
  return quad_primitive({{-h, y, h}, {-h, y, -h}, {h, y, -h}, {h, y, h}}, material);
}

GltfBuilder sphere_in_view(const json& material) {
  GltfBuilder g;
  int m = g.add("materials", material);
  g.add_node({{"mesh", g.add_mesh({sphere_primitive(glm::vec3(0.0f), 0.5f, 3, m)})}});
  g.add_camera(glm::vec3(0.0f, 0.3f, 2.0f), glm::vec3(0.0f), 0.6f);
  return g;
}

GltfBuilder furnace_sphere(const json& material) {
  GltfBuilder g = sphere_in_view(material);
  g.set_background(glm::vec3(1.0f));
  return g;
}

GltfBuilder floor_under_square_light(float height, float half, double strength,
                                     const std::vector<GltfBuilder::Primitive>& more) {
  std::vector<GltfBuilder::Primitive> quads = {quad_facing_up(1.0f, 0.0f, 0), quad_facing_down(half, height, 1)};
  quads.insert(quads.end(), more.begin(), more.end());
  GltfBuilder g;
  g.add_node({{"mesh", g.add_mesh(quads)}});
  g.add("materials", lambert_material(0.8));
  g.add("materials", {{"pbrMetallicRoughness", {{"baseColorFactor", {0, 0, 0, 1}}, {"metallicFactor", 0}}},
                      {"emissiveFactor", {1, 1, 1}},
                      {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", strength}}}}}});
  return g;
}

Scene load_scene(const GltfBuilder& g, const std::string& file) {
  std::string path = ::testing::TempDir() + file;
  g.write(path);
  return load_gltf(path);
}

void add_polygon(Scene* s, const std::vector<glm::vec3>& ccw, uint32_t material) {
  MeshDesc m;
  m.positions = ccw;
  for (uint32_t k = 1; k + 1 < ccw.size(); ++k) m.indices.insert(m.indices.end(), {0, k, k + 1});
  m.material = material;
  s->meshes.push_back(m);
}

}  // namespace candela::test
