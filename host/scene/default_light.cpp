#include "scene/default_light.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

namespace candela {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kPoints = 512;           // surface points the share is the median over
constexpr size_t kMaxEmitters = 4096;  // emissive triangles beyond this are subsampled by power

struct Point {
  glm::dvec3 p, n;
};

// A triangle by its mesh and its index in the mesh: 8 bytes, where its three corners as
// Points would take 144 (the points' population holds every lit triangle of the scene)
struct TriangleRef {
  uint32_t mesh = 0, triangle = 0;
};

// The corners of triangle t of `mesh` in double precision, and its cross product
void corners(const MeshDesc& mesh, size_t t, glm::dvec3* a, glm::dvec3* b, glm::dvec3* c, glm::dvec3* cross) {
  *a = mesh.positions[mesh.indices[3 * t]];
  *b = mesh.positions[mesh.indices[3 * t + 1]];
  *c = mesh.positions[mesh.indices[3 * t + 2]];
  *cross = glm::cross(*b - *a, *c - *a);
}

// An emissive triangle as a small source: its centroid, unit normal, area and radiance
// luminance (texture mean included), and whether it emits from both faces
struct Emitter {
  glm::dvec3 c, n;
  double area = 0.0, radiance = 0.0, weight = 1.0;  // weight: 1 / selection probability
  bool two_sided = false;
};

double mean_emission(const Scene& scene, const MaterialDesc& m, std::vector<double>* texture_mean) {
  double lum = dev::luminance_rgb(m.emission.x, m.emission.y, m.emission.z);
  int tex = m.texture(TEX_EMISSION).index;
  if (lum <= 0.0 || tex == NO_TEXTURE) return lum;
  double& mean = (*texture_mean)[size_t(tex)];
  if (mean < 0.0) mean = scene.textures[size_t(tex)].mean_luminance();
  return lum * mean;
}

// Triangles of non-emissive materials, with their areas (the points' population), and the
// emitters that are lights: brighter than white (radiance > 1, which glTF reaches only
// through KHR_materials_emissive_strength). Emission up to white is a glowing material
// (a screen, a label, a visor), which a glTF viewer never lets light anything.
void gather(const Scene& scene, std::vector<TriangleRef>* tris, std::vector<double>* tris_area,
            std::vector<Emitter>* em, double* emissive_area) {
  std::vector<double> texture_mean(scene.textures.size(), -1.0);
  size_t triangles = 0;
  for (const MeshDesc& mesh : scene.meshes) triangles += mesh.triangles();
  tris->reserve(triangles);  // grown by push_back, 10 M triangles would be copied over and over
  tris_area->reserve(triangles);
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    const MeshDesc& mesh = scene.meshes[i];
    const MaterialDesc& m = scene.materials.at(mesh.material);
    double peak = std::max({m.emission.x, m.emission.y, m.emission.z});
    double radiance = peak > 1.0 ? mean_emission(scene, m, &texture_mean) : 0.0;
    for (size_t t = 0; t < mesh.triangles(); ++t) {
      glm::dvec3 a, b, c, cr;
      corners(mesh, t, &a, &b, &c, &cr);
      double len = glm::length(cr);
      if (!(len > 0.0) || !std::isfinite(len)) continue;
      glm::dvec3 n = cr / len, centroid = (a + b + c) / 3.0;
      if (peak > 0.0) *emissive_area += 0.5 * len;
      if (radiance > 0.0) {
        em->push_back({centroid, n, 0.5 * len, radiance, 1.0, m.double_sided});
      } else {
        // Points are drawn later, uniformly inside the chosen triangle
        tris->push_back({uint32_t(i), uint32_t(t)});
        tris_area->push_back(0.5 * len);
      }
    }
  }
}

// At most kMaxEmitters emitters, drawn by power with replacement and weighted so that the sum
// over them estimates the sum over all
std::vector<Emitter> subsample(std::vector<Emitter> all, std::mt19937_64* rng) {
  if (all.size() <= kMaxEmitters) return all;
  std::vector<double> power(all.size());
  for (size_t i = 0; i < all.size(); ++i) power[i] = all[i].radiance * all[i].area;
  std::discrete_distribution<size_t> pick(power.begin(), power.end());
  double total = 0.0;
  for (double p : power) total += p;
  std::vector<Emitter> out;
  for (size_t k = 0; k < kMaxEmitters; ++k) {
    size_t i = pick(*rng);
    Emitter e = all[i];
    e.weight = total / (power[i] * double(kMaxEmitters));
    out.push_back(e);
  }
  return out;
}

// Irradiance at p on its brighter side (n or -n) from the emitters and punctual lights,
// unoccluded; a source closer than its own size contributes at most pi x its radiance
double irradiance(const Point& q, const std::vector<Emitter>& emitters, const Scene& scene) {
  double front = 0.0, back = 0.0;
  auto add = [&](double e, double cos_p) { (cos_p > 0.0 ? front : back) += e * std::fabs(cos_p); };
  for (const Emitter& e : emitters) {
    glm::dvec3 d = e.c - q.p;
    double r2 = glm::dot(d, d);
    if (!(r2 > 0.0)) continue;
    glm::dvec3 w = d / std::sqrt(r2);
    double cos_e = -glm::dot(w, e.n);  // > 0: q is in front of the emitting face
    if (e.two_sided) cos_e = std::fabs(cos_e);
    if (cos_e <= 0.0) continue;
    double solid_angle = std::min(e.area * cos_e / r2, 2.0 * kPi);
    add(e.weight * e.radiance * solid_angle, glm::dot(w, q.n));
  }
  for (const PunctualLightDesc& l : scene.punctual_lights) {
    double power = dev::luminance_rgb(l.color.x, l.color.y, l.color.z) * l.intensity;
    if (!(power > 0.0)) continue;
    if (l.type == PunctualType::Directional) {
      add(power, -glm::dot(glm::dvec3(l.direction), q.n));
      continue;
    }
    glm::dvec3 d = glm::dvec3(l.position) - q.p;
    double r2 = glm::dot(d, d);
    if (!(r2 > 0.0)) continue;
    glm::dvec3 w = d / std::sqrt(r2);
    double scale = 1.0;
    if (l.range > 0.0f) scale = std::clamp(1.0 - std::pow(std::sqrt(r2) / l.range, 4.0), 0.0, 1.0);
    if (l.type == PunctualType::Spot) {  // the kernel's cone profile, with its parameters
      dev::SpotCone cone = dev::spot_cone(double(l.inner_cone), double(l.outer_cone));
      scale *= dev::spot_profile(float(-glm::dot(w, glm::dvec3(l.direction))), cone.scale, cone.offset);
    }
    add(power * scale / r2, glm::dot(w, q.n));
  }
  return std::max(front, back);
}

}  // namespace

OwnLight own_light_share(const Scene& scene, double environment_radiance) {
  std::vector<TriangleRef> tris;
  std::vector<double> areas;
  std::vector<Emitter> emitters;
  double emissive_area = 0.0;
  gather(scene, &tris, &areas, &emitters, &emissive_area);
  double lit_area = 0.0;
  for (double a : areas) lit_area += a;
  OwnLight own;
  own.lights = !emitters.empty() || scene.punctual_light_count() > 0;
  // Mostly emitters: the asset is its glowing parts, with little for them to light
  own.mostly_emissive = !(lit_area > emissive_area);
  if (!own.lights || own.mostly_emissive) return own;
  std::mt19937_64 rng(0x63616e64656c61ull);  // fixed: the same scene gives the same answer
  emitters = subsample(std::move(emitters), &rng);
  std::discrete_distribution<size_t> pick(areas.begin(), areas.end());
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  double e_env = kPi * environment_radiance;
  std::vector<double> share;
  for (int k = 0; k < kPoints; ++k) {
    size_t t = pick(rng);
    double su = std::sqrt(u01(rng)), v = u01(rng);
    glm::dvec3 a, b, c, cr;
    corners(scene.meshes[tris[t].mesh], tris[t].triangle, &a, &b, &c, &cr);
    Point q{(1.0 - su) * a + su * (1.0 - v) * b + su * v * c, cr / glm::length(cr)};
    q.p += 1e-4 * q.n * std::max(1.0, glm::length(q.p));  // off the surface, as a ray would start
    share.push_back(irradiance(q, emitters, scene) / e_env);
  }
  std::nth_element(share.begin(), share.begin() + kPoints / 2, share.end());
  own.share = share[kPoints / 2];
  return own;
}

DefaultLightChoice choose_default_light(const Scene& scene, DefaultLight mode, bool environment_given,
                                        double environment_radiance) {
  DefaultLightChoice c;
  if (environment_given) {
    c.reason = "the scene's own environment or background lights it";
    return c;
  }
  if (mode == DefaultLight::Off) {
    c.reason = "--default-light off";
    return c;
  }
  if (mode == DefaultLight::On) {
    c.use_environment = true;
    c.reason = "--default-light on";
    return c;
  }
  if (!scene.has_light()) {
    c.use_environment = true;
    c.reason = "the scene has no light";
    return c;
  }
  OwnLight own = own_light_share(scene, environment_radiance);
  c.own_share = own.share;
  c.use_environment = c.own_share < kOwnLightShareThreshold;
  if (!own.lights) {
    c.reason = "its only emitters glow (no brighter than white): they are materials, not lights";
  } else if (own.mostly_emissive) {
    c.reason = "its emitters are most of its surface, with little for them to light";
  } else {
    char text[160];
    std::snprintf(text, sizeof text, "its own lights give %.2g%% of the light the studio would on its surfaces",
                  100.0 * c.own_share);
    c.reason = text;
  }
  return c;
}

std::optional<float> automatic_exposure(const DefaultLightChoice& c) {
  if (c.use_environment || !(c.own_share > kAutoExposureShare) || !std::isfinite(c.own_share)) return std::nullopt;
  return float(std::round(-10.0 * std::log2(c.own_share)) / 10.0);
}

std::optional<float> image_exposure(const std::vector<float>& luminance, int width, int height) {
  if (width <= 0 || height <= 0 || luminance.size() < size_t(width) * size_t(height)) return std::nullopt;
  int side = std::max(1, (std::min(width, height) + kMeterZones - 1) / kMeterZones);
  std::vector<double> zones;
  for (int by = 0; by < height; by += side)
    for (int bx = 0; bx < width; bx += side) {
      double sum = 0.0;
      size_t n = 0;
      for (int y = by; y < std::min(by + side, height); ++y)
        for (int x = bx; x < std::min(bx + side, width); ++x) {
          float l = luminance[size_t(y) * size_t(width) + size_t(x)];
          if (!std::isfinite(l)) continue;
          sum += std::max(double(l), 0.0);
          ++n;
        }
      if (n > 0 && sum > 0.0) zones.push_back(sum / double(n));
    }
  if (zones.empty()) return std::nullopt;
  std::vector<double> sorted = zones;
  size_t k = std::min(sorted.size() - 1, size_t(0.99 * double(sorted.size())));
  std::nth_element(sorted.begin(), sorted.begin() + std::ptrdiff_t(k), sorted.end());
  double floor = 1e-3 * sorted[k], sum = 0.0;
  size_t n = 0;
  for (double z : zones)
    if (z >= floor) {
      sum += std::log(z);
      ++n;
    }
  double stops = std::log2(kMiddleGrey) - sum / double(n) / std::log(2.0);
  stops = std::clamp(stops, -kImageExposureRange, kImageExposureRange);
  return float(std::round(10.0 * stops) / 10.0) + 0.0f;  // + 0: no -0.0
}

}  // namespace candela
