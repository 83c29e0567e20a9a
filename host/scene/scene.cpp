#include "scene/scene.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "base/error.hpp"

namespace candela {

namespace {

bool nonzero(float v) { return v != 0.0f; }
bool nonzero(const glm::vec3& v) { return v != glm::vec3(0.0f); }

enum class GltfRole { LOBE, MODIFIER, PLAIN };

}  // namespace

uint32_t MaterialDesc::kernel_type() const {
  bool lambertian = true;
#define CD_LOBE_ZERO(_, name, n, value, lo, hi, ext, key, slot, load, feature, role) \
  lambertian = lambertian && !(GltfRole::role == GltfRole::LOBE && nonzero(name));
  GLTF_PARAMS(CD_LOBE_ZERO)
#undef CD_LOBE_ZERO
  return unlit || (type == MATERIAL_GLTF && lambertian) ? MATERIAL_DIFFUSE : type;
}

bool MaterialDesc::needs(const char* macro) const {
  std::string want = macro;
  if (kernel_type() == MATERIAL_CONDUCTOR) return want == "CD_FEATURE_ANISOTROPY" && anisotropy_strength > 0.0f;
  if (kernel_type() != MATERIAL_GLTF) return false;
  bool needed = false;
#define CD_PARAM_NEEDS(_, name, n, value, lo, hi, ext, key, slot, load, feature, role) \
  needed = needed || (GltfRole::role != GltfRole::PLAIN && want == #feature && nonzero(name));
  GLTF_PARAMS(CD_PARAM_NEEDS)
#undef CD_PARAM_NEEDS
  return needed;
}

bool MaterialDesc::alpha_tested() const {
  bool textured = texture(TEX_BASE_COLOR).index != NO_TEXTURE;
  if (alpha_mode == AlphaMode::Mask) return textured || base_color.a < alpha_cutoff;
  if (alpha_mode == AlphaMode::Blend) return textured || base_color.a < 1.0f;
  return false;
}

double TextureDesc::mean_luminance() const {
  size_t n = texels();
  if (n == 0) return 0.0;
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    float c[3];
    for (int k = 0; k < 3; ++k) {
      if (!rgbaf.empty()) {
        c[k] = rgbaf[4 * i + k];
      } else {
        float v = rgba8[4 * i + k] / 255.0f;
        c[k] = srgb ? dev::srgb_to_linear(v) : v;
      }
    }
    sum += dev::luminance_rgb(c[0], c[1], c[2]);
  }
  return sum / double(n);
}

size_t Scene::triangles() const {
  size_t n = 0;
  for (const auto& m : meshes) n += m.triangles();
  return n;
}

Bounds Scene::bounds() const {
  Bounds b;
  for (const auto& m : meshes)
    for (const auto& p : m.positions) b.grow(p);
  return b;
}

namespace {

// The feature that compiles material type `type` in (its CD_MATERIALS entry); nullptr: always in
bool SceneFeatures::*material_feature(uint32_t type) {
#define CD_MATERIAL_FEATURE(id, name, feature) \
  if (type == id) return SceneFeatures::flag(#feature);
  CD_MATERIALS(CD_MATERIAL_FEATURE)
#undef CD_MATERIAL_FEATURE
  return nullptr;
}

}  // namespace

SceneFeatures Scene::features() const {
  SceneFeatures f;
  for (const auto& m : materials)
    for (const auto& t : m.textures) f.textures |= t.index != NO_TEXTURE;
  for (const auto& m : meshes) {
    f.uvs |= !m.uv0.empty() || !m.uv1.empty();
    f.tangents |= !m.tangents.empty();
    for (const auto& c : m.colors) f.vertex_colors |= c != glm::vec3(1.0f);
    f.alpha |= materials.at(m.material).alpha_tested();
    f.media |= materials.at(m.material).medium >= 0;
    // The features of GLTF_PARAMS a mesh's material needs
    for (const char* macro : dev::kSceneFeatureMacros)
      if (materials.at(m.material).needs(macro)) f.*SceneFeatures::flag(macro) = true;
    f.unlit |= materials.at(m.material).unlit;
    // The feature of the BSDF each mesh's material is shaded with (CD_MATERIALS; the
    // loader's default material may go unused)
    if (bool SceneFeatures::*flag = material_feature(materials.at(m.material).kernel_type())) f.*flag = true;
  }
  f.media |= global_medium >= 0;
  for (const auto& m : media) f.nanovdb |= f.media && m.is_nanovdb();
  // The lights compile_lights makes: emitting punctual lights; the map, else a background
  f.punctual = punctual_light_count() > 0;
  f.environment = environment.has_value() || dev::luminance_rgb(background.x, background.y, background.z) > 0.0f;
  return f;
}

size_t Scene::punctual_light_count() const {
  size_t n = 0;
  for (const PunctualLightDesc& l : punctual_lights)
    n += dev::luminance_rgb(l.color.x, l.color.y, l.color.z) * l.intensity > 0.0f;
  return n;
}

bool Scene::has_light() const {
  if (environment) {
    if (environment->strength > 0.0f && environment->image.mean_luminance() > 0.0) return true;
  } else if (background.x > 0.0f || background.y > 0.0f || background.z > 0.0f) {
    return true;
  }
  if (punctual_light_count() > 0) return true;
  for (const auto& mesh : meshes) {
    const MaterialDesc& m = materials.at(mesh.material);
    bool factor = m.emission.x > 0.0f || m.emission.y > 0.0f || m.emission.z > 0.0f;
    int tex = m.texture(TEX_EMISSION).index;
    if (factor && (tex == NO_TEXTURE || textures.at(size_t(tex)).mean_luminance() > 0.0)) return true;
  }
  return false;
}

glm::vec3 triangle_normal_area(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, double* area) {
  glm::dvec3 n = glm::cross(glm::dvec3(b) - glm::dvec3(a), glm::dvec3(c) - glm::dvec3(a));
  double len = glm::length(n);
  *area = 0.5 * len;
  return len > 0.0 ? glm::vec3(n / len) : glm::vec3(0.0f);
}

namespace {

float largest_extent(const Bounds& b) {
  glm::vec3 e = b.hi - b.lo;
  return b.empty() ? 0.0f : std::max({e.x, e.y, e.z});
}

// A mesh that is nearly flat (its bounds' smallest side under 1 % of its largest)
bool is_planar(const Bounds& b) {
  glm::vec3 e = b.hi - b.lo;
  return !b.empty() && std::min({e.x, e.y, e.z}) <= 0.01f * largest_extent(b);
}

}  // namespace

Bounds framing_bounds(const Scene& scene, size_t* backdrops) {
  const float kBackdrop = 4.0f;
  std::vector<Bounds> mesh_bounds(scene.meshes.size());
  Bounds solid, framed;
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    for (const auto& p : scene.meshes[i].positions) mesh_bounds[i].grow(p);
    if (!is_planar(mesh_bounds[i])) solid.grow(mesh_bounds[i]);
  }
  // Beneath or behind the solids: across its plane it spans their bounds
  auto spans_solids = [&](const Bounds& b) {
    glm::vec3 e = b.hi - b.lo;
    int flat = e.x <= e.y && e.x <= e.z ? 0 : e.y <= e.z ? 1 : 2;
    for (int a = 0; a < 3; ++a)
      if (a != flat && (b.lo[a] > solid.lo[a] || b.hi[a] < solid.hi[a])) return false;
    return true;
  };
  size_t skipped = 0;
  for (const Bounds& b : mesh_bounds) {
    if (b.empty()) continue;
    bool backdrop =
        !solid.empty() && is_planar(b) && largest_extent(b) > kBackdrop * largest_extent(solid) && spans_solids(b);
    skipped += backdrop;
    if (!backdrop) framed.grow(b);
  }
  if (backdrops) *backdrops = skipped;
  return framed;
}

CameraDesc framing_camera(const Scene& scene, float aspect) {
  const float kDegree = 3.14159265f / 180.0f, kMargin = 0.95f;
  Bounds b = framing_bounds(scene);
  CameraDesc cam;
  if (b.empty()) return cam;
  glm::vec3 extent = b.hi - b.lo, centre = b.center();
  bool flat = extent.y < 0.15f * std::max(extent.x, extent.z);
  float azimuth = 30.0f * kDegree, elevation = (flat ? 50.0f : 20.0f) * kDegree;
  glm::vec3 back(std::sin(azimuth) * std::cos(elevation), std::sin(elevation), std::cos(azimuth) * std::cos(elevation));
  cam.forward = -back;
  glm::vec3 right = glm::normalize(glm::cross(cam.forward, cam.up)), up = glm::cross(right, cam.forward);
  // The distance along `back` at which every corner projects inside the frame
  float tan_y = std::tan(0.5f * cam.yfov) * kMargin, tan_x = tan_y * (aspect > 0.0f ? aspect : 1.0f);
  float dist = 0.0f, nearest = 0.0f;
  for (int i = 0; i < 8; ++i) {
    glm::vec3 q = glm::vec3(i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z) - centre;
    float along = glm::dot(q, back);
    dist = std::max({dist, along + std::fabs(glm::dot(q, right)) / tan_x, along + std::fabs(glm::dot(q, up)) / tan_y});
    nearest = std::max(nearest, along);
  }
  dist = std::max({dist, 1.05f * nearest, 1e-3f});
  cam.position = centre + dist * back;
  return cam;
}

CameraDesc resolve_camera(const Scene& scene, float aspect) {
  CameraDesc cam = scene.camera ? *scene.camera : framing_camera(scene, aspect);
  if (!(cam.aperture_radius >= 0.0f) || !std::isfinite(cam.aperture_radius))
    throw Error("the camera's aperture radius must be finite and non-negative");
  if (cam.aperture_radius > 0.0f && cam.projection == Projection::Orthographic)
    throw Error("an orthographic camera has no lens: depth of field (an aperture) needs a perspective camera");
  if (!cam.focus_distance) {
    Bounds b = framing_bounds(scene);
    float along = b.empty() ? 0.0f : glm::dot(b.center() - cam.position, glm::normalize(cam.forward));
    cam.focus_distance = along > 0.0f ? along : std::max(b.empty() ? 1.0f : b.radius(), 1e-3f);
  }
  if (!(*cam.focus_distance > 0.0f) || !std::isfinite(*cam.focus_distance))
    throw Error("the camera's focus distance must be finite and positive");
  return cam;
}

}  // namespace candela
