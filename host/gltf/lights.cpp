// KHR_lights_punctual: point, spot and directional lights, checked against the extension
// and placed at their nodes.
#include <cmath>

#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

PunctualType light_type(const tinygltf::Light& gl, const std::string& what) {
  if (gl.type == "point") return PunctualType::Point;
  if (gl.type == "spot") return PunctualType::Spot;
  if (gl.type == "directional") return PunctualType::Directional;
  throw Error(what + " has type '" + gl.type + "'; it must be point, spot or directional");
}

void read_color(const tinygltf::Light& gl, const std::string& what, Warnings* warn, PunctualLightDesc* l) {
  if (gl.color.empty()) return;
  if (gl.color.size() != 3) throw Error(what + ": color must hold 3 numbers");
  for (int c = 0; c < 3; ++c) {
    l->color[c] = float(gl.color[size_t(c)]);
    if (!(l->color[c] >= 0.0f && std::isfinite(l->color[c])))
      throw Error(what + ": color must be finite and non-negative");
  }
  if (l->color.x > 1.0f || l->color.y > 1.0f || l->color.z > 1.0f)
    warn->add(what + ": color components above 1 are outside the extension's range; used as given");
}

void read_spot_cone(const tinygltf::Light& gl, const std::string& what, PunctualLightDesc* l) {
  l->inner_cone = float(gl.spot.innerConeAngle);
  l->outer_cone = float(gl.spot.outerConeAngle);
  const double half_pi = 1.57079632679489662;
  if (!(gl.spot.innerConeAngle >= 0.0 && gl.spot.innerConeAngle < gl.spot.outerConeAngle &&
        gl.spot.outerConeAngle <= half_pi + 1e-9))
    throw Error(what + ": spot cone angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2");
}

// A light's own properties, checked against what the extension says they must be (an
// Error) or should be (a warning); read_node_light places it
PunctualLightDesc read_punctual_light(const tinygltf::Light& gl, size_t index, LightUnits units, Warnings* warn) {
  const std::string what = "KHR_lights_punctual light " + std::to_string(index);
  PunctualLightDesc l;
  l.type = light_type(gl, what);
  read_color(gl, what, warn, &l);
  if (!(gl.intensity >= 0.0 && std::isfinite(gl.intensity)))
    throw Error(what + ": intensity must be finite and non-negative");
  // candela and lux to W/sr and W/m^2 (in double: a file written as radiometric x 683 reads back exactly)
  l.intensity = float(units == LightUnits::Photometric ? gl.intensity / kLumensPerWatt : gl.intensity);
  // tinygltf reads an absent range as 0: both mean infinite
  l.range = float(gl.range);
  if (!(l.range >= 0.0f && std::isfinite(l.range))) throw Error(what + ": range must be greater than 0");
  if (l.type == PunctualType::Directional && l.range > 0.0f) {
    warn->add(what + ": range applies only to point and spot lights; it is ignored on a directional light");
    l.range = 0.0f;
  }
  if (l.type == PunctualType::Spot) read_spot_cone(gl, what, &l);
  return l;
}

}  // namespace

// The node's light at the node's world origin, pointing along its world -Z axis
void read_node_light(ReadContext& ctx, int node_index, const tinygltf::Value& ext, const glm::mat4& world) {
  const std::string where = "glTF node " + std::to_string(node_index);
  if (!ext.IsObject() || !ext.Has("light") || !ext.Get("light").IsNumber())
    throw Error(where + ": KHR_lights_punctual has no light index");
  double index = ext.Get("light").GetNumberAsDouble();
  if (!(index >= 0.0 && index < double(ctx.model.lights.size()) && index == std::floor(index)))
    throw Error(where + " refers to a missing KHR_lights_punctual light");
  PunctualLightDesc l =
      read_punctual_light(ctx.model.lights[size_t(index)], size_t(index), ctx.scene.light_units, &ctx.warn);
  l.position = glm::vec3(world * glm::vec4(0, 0, 0, 1));
  if (!(std::isfinite(l.position.x) && std::isfinite(l.position.y) && std::isfinite(l.position.z)))
    throw Error(where + ": the light's position is not finite");
  if (l.type != PunctualType::Point) {
    glm::vec3 dir = glm::vec3(world * glm::vec4(0, 0, -1, 0));
    float len = glm::length(dir);
    if (!(len > 0.0f && std::isfinite(len)))
      throw Error(where + ": the light has no direction (its node transform is degenerate or not finite)");
    l.direction = dir / len;
  }
  ctx.scene.punctual_lights.push_back(l);
}

}  // namespace candela::gltf
