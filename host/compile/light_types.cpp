#include "compile/light_types.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "base/error.hpp"

namespace candela {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Each light type's power (light_power) and bounds in the light tree (light_bounds), in
// CD_LIGHTS order

// Diffuse emitter: power = pi * L * A per emitting side. Bounds: L A per emitting side
// about the front normal, or both ways when double-sided
double light_power_triangle(const dev::Light& light, const dev::SceneBuffers& buffers, double emission_scale, double) {
  const dev::Material& m = buffers.materials[buffers.prims[light.index].material];
  double lum = dev::luminance_rgb(m.emission[0], m.emission[1], m.emission[2]) * emission_scale;
  return kPi * lum * light.params.triangle.area * ((m.flags & MATERIAL_DOUBLE_SIDED) ? 2.0 : 1.0);
}

bool light_bounds_triangle(const dev::Light& l, const dev::SceneBuffers& b, double power, LightBounds* lb) {
  const dev::Prim& p = b.prims[l.index];
  glm::dvec3 v[3];
  for (int k = 0; k < 3; ++k) {
    glm::vec3 f(b.positions[3 * size_t(p.v[k])], b.positions[3 * size_t(p.v[k]) + 1],
                b.positions[3 * size_t(p.v[k]) + 2]);
    lb->lo = glm::min(lb->lo, f);
    lb->hi = glm::max(lb->hi, f);
    v[k] = glm::dvec3(f);
  }
  glm::dvec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
  double nl = glm::length(n);
  lb->axis = nl > 0.0 ? n / nl : glm::dvec3(0, 0, 1);
  bool two_sided = (b.materials[p.material].flags & MATERIAL_DOUBLE_SIDED) != 0u;
  lb->theta_o = two_sided || !(nl > 0.0) ? kPi : 0.0;
  lb->theta_e = 0.5 * kPi;
  lb->intensity = power / (kPi * (two_sided ? 2.0 : 1.0));
  return true;
}

// A constant environment's power through the scene's bounding sphere; a map's with its
// mean radiance luminance, passed as emission_scale. At infinity: not in the tree
double light_power_environment(const dev::Light& light, const dev::SceneBuffers&, double emission_scale,
                               double scene_radius) {
  bool map = int(light.params.environment.map) != NO_TEXTURE;
  double lum = map ? emission_scale : dev::luminance_rgb(light.radiance[0], light.radiance[1], light.radiance[2]);
  return 4.0 * kPi * kPi * scene_radius * scene_radius * lum;
}

bool light_bounds_environment(const dev::Light&, const dev::SceneBuffers&, double, LightBounds*) { return false; }

// Radiant intensity I over the sphere. A finite range is left out: the power is then an
// upper bound, which only costs variance. Bounds: I in all directions
double light_power_point(const dev::Light& light, const dev::SceneBuffers&, double, double) {
  double lum = dev::luminance_rgb(light.radiance[0], light.radiance[1], light.radiance[2]);
  return lum * (4.0 * kPi);
}

// A punctual light at `position` of intensity I, emitting within theta_e of its axis
void punctual_bounds(const dev::Light& l, const float position[3], LightBounds* lb) {
  glm::vec3 pos(position[0], position[1], position[2]);
  lb->lo = lb->hi = pos;
  lb->intensity = dev::luminance_rgb(l.radiance[0], l.radiance[1], l.radiance[2]);
}

bool light_bounds_point(const dev::Light& l, const dev::SceneBuffers&, double, LightBounds* lb) {
  punctual_bounds(l, l.params.point.position, lb);
  lb->theta_o = kPi;
  lb->theta_e = 0.5 * kPi;
  return true;
}

// Solid-angle integral of the spot profile clamp(c * scale + offset, 0, 1)^2 over the
// sphere, c = cos(angle to the axis): with s = 1 / scale and c0 = -offset / scale (the
// outer cosine), t = (c - c0) / s rises from 0 at c0 to 1 at c0 + s and stays 1 up to c = 1
double spot_solid_angle(double scale, double offset) {
  double s = 1.0 / scale, c0 = -offset / scale;
  double t_max = std::min(1.0, (1.0 - c0) / s);
  return 2.0 * kPi * (s * t_max * t_max * t_max / 3.0 + std::max(0.0, 1.0 - c0 - s));
}

// Radiant intensity I over the spot's profile. Bounds: I about the axis out to the outer
// cone angle
double light_power_spot(const dev::Light& light, const dev::SceneBuffers&, double, double) {
  double lum = dev::luminance_rgb(light.radiance[0], light.radiance[1], light.radiance[2]);
  return lum * spot_solid_angle(light.params.spot.cone_scale, light.params.spot.cone_offset);
}

bool light_bounds_spot(const dev::Light& l, const dev::SceneBuffers&, double, LightBounds* lb) {
  const dev::SpotLight& s = l.params.spot;
  punctual_bounds(l, s.position, lb);
  lb->axis = glm::normalize(glm::dvec3(s.axis[0], s.axis[1], s.axis[2]));
  lb->theta_o = 0.0;
  lb->theta_e = std::acos(std::clamp(-double(s.cone_offset) / double(s.cone_scale), -1.0, 1.0));
  return true;
}

// Irradiance E through the disc the scene's bounding sphere shows the light. At infinity:
// not in the tree
double light_power_directional(const dev::Light& light, const dev::SceneBuffers&, double, double scene_radius) {
  return kPi * scene_radius * scene_radius *
         dev::luminance_rgb(light.radiance[0], light.radiance[1], light.radiance[2]);
}

bool light_bounds_directional(const dev::Light&, const dev::SceneBuffers&, double, LightBounds*) { return false; }

}  // namespace

double light_power(const dev::Light& light, const dev::SceneBuffers& buffers, double emission_scale,
                   double scene_radius) {
#define CD_LIGHT_POWER(id, name, feature) \
  if (light.type == id) return light_power_##name(light, buffers, emission_scale, scene_radius);
  CD_LIGHTS(CD_LIGHT_POWER)
#undef CD_LIGHT_POWER
  throw Error("light_power: unknown light type " + std::to_string(light.type));
}

bool light_bounds(const dev::Light& light, const dev::SceneBuffers& buffers, double power, LightBounds* bounds) {
  *bounds = LightBounds();
  bool member = false, known = false;
#define CD_LIGHT_BOUNDS(id, name, feature)                       \
  if (light.type == id) {                                        \
    member = light_bounds_##name(light, buffers, power, bounds); \
    known = true;                                                \
  }
  CD_LIGHTS(CD_LIGHT_BOUNDS)
#undef CD_LIGHT_BOUNDS
  if (!known) throw Error("light_bounds: unknown light type " + std::to_string(light.type));
  if (!member) return false;
  bounds->intensity = std::max(bounds->intensity, 1e-30);
  return true;
}

}  // namespace candela
