// The tests' one glTF writer: meshes, materials, cameras and nodes in a self-contained
// .gltf (one buffer, embedded as a base64 data URI).
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace candela::test {

class GltfBuilder {
 public:
  // One primitive's vertex data; empty attributes (and indices) are left out
  struct Primitive {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;   // NORMAL
    std::vector<glm::vec2> uvs;       // TEXCOORD_0
    std::vector<glm::u8vec4> colors;  // COLOR_0, normalized unsigned bytes
    std::vector<uint16_t> indices;
    int material = -1;  // -1: none (the default material)
    int mode = 4;       // triangles (5: strip)
  };

  // The document without its buffer: tests may edit it directly
  nlohmann::json doc;

  GltfBuilder();  // an asset and scene 0 without nodes
  // Appends an item to a top-level array ("materials", "images", "textures", ...)
  int add(const std::string& array, nlohmann::json item);
  int add_mesh(const std::vector<Primitive>& primitives);
  int add_node(nlohmann::json node);  // a root node of scene 0
  // A perspective camera node at `eye` looking at `target`, +y up
  int add_camera(const glm::vec3& eye, const glm::vec3& target, float yfov);
  void set_background(const glm::vec3& rgb);  // candela's scene extras
  // An accessor of `type` ("SCALAR", "VEC3", "MAT4", ...) over raw values: FLOAT, or
  // UNSIGNED_SHORT (JOINTS_n)
  int add_floats(const std::vector<float>& values, const char* type);
  int add_ushorts(const std::vector<uint16_t>& values, const char* type);

  nlohmann::json document() const;  // doc with its buffer
  void write(const std::string& path) const;

 private:
  template <typename T>
  int add_accessor(const std::vector<T>& data, int component_type, const char* type,
                   nlohmann::json extra = nlohmann::json::object());
  std::string bin_;
};

// A quad p0 p1 p2 p3 (counter-clockwise seen from its front) as two indexed triangles,
// TEXCOORD_0 (0,1) (1,1) (1,0) (0,0) at p0..p3
GltfBuilder::Primitive quad_primitive(const float (&p)[4][3], int material);

// An axis-aligned box from lo to hi: six quads, counter-clockwise seen from outside
// (outward normals)
std::vector<GltfBuilder::Primitive> box_primitives(glm::vec3 lo, glm::vec3 hi, int material);

// A closed icosphere (flat-shaded, shared vertices, outward winding)
GltfBuilder::Primitive sphere_primitive(const glm::vec3& center, float radius, int subdivisions, int material);

}  // namespace candela::test
