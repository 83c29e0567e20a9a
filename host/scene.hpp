// Host-side scene: what the glTF loader produces and the renderer uploads.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "device_types.hpp"

namespace candela {

struct SceneTriangle {
  glm::vec3 p[3];
  glm::vec3 n[3];  // zero: use the flat geometric normal
  glm::vec2 uv[3];
  glm::vec3 color[3] = {glm::vec3(1.0f), glm::vec3(1.0f), glm::vec3(1.0f)};  // COLOR_0
  uint32_t material = 0;
};

struct CameraDesc {
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float yfov = 0.7853982f;  // radians
  float aspect = 0.0f;  // width / height; 0 = not given
};

struct Bounds {
  glm::vec3 lo{1e30f}, hi{-1e30f};
  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Bounds& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x; }
  glm::vec3 center() const { return 0.5f * (lo + hi); }
  float radius() const { return 0.5f * glm::length(hi - lo); }
};

// Coarse scene features that select kernel code at build time (part of the cache key)
struct SceneFeatures {
  bool textures = false;
  bool vertex_colors = false;
  std::string build_options() const;
};

struct Scene {
  std::vector<SceneTriangle> triangles;
  std::vector<dev::Material> materials;
  std::vector<dev::TextureInfo> textures;
  std::vector<uint8_t> texels;  // RGBA8, 4 bytes per texel (TextureInfo::flags: encoding)
  bool has_vertex_colors = false;  // some triangle's colors are not white
  std::optional<CameraDesc> camera;
  glm::vec3 background{0.0f};
  std::vector<std::string> warnings;  // each unsupported feature named once

  Bounds bounds() const;
  // Mean luminance (sRGB decoded where flagged) of each texture used as an emissive
  // texture; 0 for the others, which are not read
  std::vector<double> emission_texture_means() const;
  SceneFeatures features() const;
  bool has_emission() const;
};

// Camera for an image of width x height: the scene's, else one framing the bounds
CameraDesc resolve_camera(const Scene& scene);
dev::Camera make_device_camera(const CameraDesc& cam, int width, int height);

}  // namespace candela
