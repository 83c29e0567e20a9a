// Test scenes that more than one test file uses: glTF materials, quads and small scenes for
// GltfBuilder, and meshes added to a Scene directly.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "scene/scene.hpp"
#include "support/gltf_builder.hpp"

namespace candela::test {

// ---- glTF materials -----------------------------------------------------------------------

// A Lambertian of `albedo`: metallic 0, no specular layer (KHR_materials_specular 0)
nlohmann::json lambert_material(double albedo);

// A black emitter of `radiance` without a specular layer: emissiveFactor radiance / m and
// KHR_materials_emissive_strength m, m the largest channel (emissiveFactor holds at most 1)
nlohmann::json emissive_material(glm::vec3 radiance);

// A null boundary: a material with no surface of its own that bounds `medium` (candela's
// extras.candela.medium, docs/volumes.md)
nlohmann::json null_boundary_material(const nlohmann::json& medium);

// ---- Horizontal squares |x|, |z| <= half at height y ----------------------------------------

// Facing +y (a floor, an occluder seen from below a light): corners (-h, h) (h, h) (h, -h)
// (-h, -h) in (x, z)
GltfBuilder::Primitive quad_facing_up(float half, float y, int material);
// Facing -y (a light over a floor): corners (-h, -h) (h, -h) (h, h) (-h, h)
GltfBuilder::Primitive quad_facing_down(float half, float y, int material);
// The same square facing -y from corner (-h, h): (-h, h) (-h, -h) (h, -h) (h, h), split into
// its two triangles along the other diagonal
GltfBuilder::Primitive quad_facing_down_rotated(float half, float y, int material);

// ---- Scenes -----------------------------------------------------------------------------------

// A sphere of `material` (radius 0.5 at the origin, 3 subdivisions) filling most of the
// view of a camera at (0, 0.3, 2) looking at the origin (yfov 0.6)
GltfBuilder sphere_in_view(const nlohmann::json& material);
// The same under a uniform background of 1: a closed sphere that neither absorbs nor
// emits is invisible there (a white furnace)
GltfBuilder furnace_sphere(const nlohmann::json& material);

// A 2 x 2 floor (y = 0, facing +y; material 0: Lambertian of albedo 0.8) under a square
// light of half-size `half` at `height` (facing down; material 1: black, emissive strength
// `strength`, with the default specular layer), black background, no camera. `more`
// primitives join the floor and light in their mesh.
GltfBuilder floor_under_square_light(float height, float half, double strength,
                                     const std::vector<GltfBuilder::Primitive>& more = {});

// `g` written as ::testing::TempDir() + file, and loaded
Scene load_scene(const GltfBuilder& g, const std::string& file);

// ---- Scene descriptions ---------------------------------------------------------------------

// A convex polygon (counter-clockwise seen from its front) as a triangle fan from its first
// vertex: a quad p0 p1 p2 p3 is the triangles (p0, p1, p2) and (p0, p2, p3)
void add_polygon(Scene* s, const std::vector<glm::vec3>& ccw, uint32_t material);

}  // namespace candela::test
