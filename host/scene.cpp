#include "scene.hpp"

#include <cmath>

namespace candela {

std::string SceneFeatures::build_options() const {
  return std::string("-DCD_FEATURE_TEXTURES=") + (textures ? "1" : "0") +
         " -DCD_FEATURE_VERTEX_COLORS=" + (vertex_colors ? "1" : "0");
}

Bounds Scene::bounds() const {
  Bounds b;
  for (const auto& t : triangles)
    for (const auto& p : t.p) b.grow(p);
  return b;
}

std::vector<double> Scene::emission_texture_means() const {
  std::vector<bool> emissive(textures.size(), false);
  for (const auto& m : materials)
    if (m.emission_texture != NO_TEXTURE) emissive[size_t(m.emission_texture)] = true;
  std::vector<double> means;
  auto decode = [](uint8_t v, bool srgb) {
    double c = v / 255.0;
    return srgb ? (c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4)) : c;
  };
  for (size_t k = 0; k < textures.size(); ++k) {
    const dev::TextureInfo& t = textures[k];
    if (!emissive[k]) {
      means.push_back(0.0);
      continue;
    }
    bool srgb = t.flags & TEXTURE_SRGB;
    size_t n = size_t(t.width) * t.height;
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const uint8_t* c = &texels[4 * (size_t(t.offset) + i)];
      sum += 0.2126 * decode(c[0], srgb) + 0.7152 * decode(c[1], srgb) + 0.0722 * decode(c[2], srgb);
    }
    means.push_back(n ? sum / n : 0.0);
  }
  return means;
}

SceneFeatures Scene::features() const {
  SceneFeatures f;
  f.vertex_colors = has_vertex_colors;
  for (const auto& m : materials)
    f.textures |= m.base_color_texture != NO_TEXTURE || m.emission_texture != NO_TEXTURE;
  return f;
}

bool Scene::has_emission() const {
  std::vector<double> means = emission_texture_means();
  for (const auto& m : materials) {
    bool factor = m.emission[0] > 0.0f || m.emission[1] > 0.0f || m.emission[2] > 0.0f;
    if (factor && (m.emission_texture == NO_TEXTURE || means[size_t(m.emission_texture)] > 0.0))
      return true;
  }
  return false;
}

CameraDesc resolve_camera(const Scene& scene) {
  if (scene.camera) return *scene.camera;
  // Look at the bounds from +z, far enough to see the whole bounding sphere
  Bounds b = scene.bounds();
  CameraDesc cam;
  float r = std::max(b.radius(), 1e-3f);
  float dist = r / std::sin(0.5f * cam.yfov) * 1.05f;
  cam.position = b.center() + glm::vec3(0.0f, 0.0f, dist);
  cam.forward = glm::vec3(0.0f, 0.0f, -1.0f);
  return cam;
}

dev::Camera make_device_camera(const CameraDesc& cam, int width, int height) {
  glm::vec3 f = glm::normalize(cam.forward);
  glm::vec3 r = glm::cross(f, cam.up);
  if (!(glm::length(r) > 1e-6f)) {
    // Up is parallel to the view: use the world axis least aligned with it
    glm::vec3 a = glm::abs(f);
    glm::vec3 axis = a.x <= a.y && a.x <= a.z ? glm::vec3(1, 0, 0)
                     : a.y <= a.z            ? glm::vec3(0, 1, 0)
                                             : glm::vec3(0, 0, 1);
    r = glm::cross(f, axis);
  }
  r = glm::normalize(r);
  glm::vec3 u = glm::cross(r, f);
  float tan_y = std::tan(0.5f * cam.yfov);
  float tan_x = tan_y * float(width) / float(height);
  dev::Camera c{};
  for (int i = 0; i < 3; ++i) {
    c.origin[i] = cam.position[i];
    c.forward[i] = f[i];
    c.right[i] = r[i] * tan_x;
    c.up[i] = u[i] * tan_y;
  }
  return c;
}

}  // namespace candela
