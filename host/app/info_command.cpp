// `candela info SCENE`: what a scene holds, as candela reads it: size, extensions, animations,
// cameras, lights, materials, and the warnings of what it leaves out.
#include <cstdio>
#include <string>

#include "app/commands.hpp"
#include "app/options.hpp"
#include "compile/scene_compiler.hpp"
#include "gltf/gltf_loader.hpp"
#include "scene/default_light.hpp"
#include "scene/environment.hpp"

namespace candela {
namespace {

std::string vec(const glm::vec3& v) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.4g, %.4g, %.4g)", v.x, v.y, v.z);
  return text;
}

std::string quoted_or(const std::string& name, const std::string& fallback) {
  return name.empty() ? fallback : "'" + name + "'";
}

void print_geometry(const Scene& s) {
  size_t vertices = 0;
  for (const MeshDesc& m : s.meshes) vertices += m.positions.size();
  Bounds b = s.bounds();
  std::printf("geometry: %zu triangles, %zu vertices in %zu primitives; bounds %s to %s\n", s.triangles(), vertices,
              s.meshes.size(), vec(b.lo).c_str(), vec(b.hi).c_str());
}

void print_extensions(const Scene& s) {
  std::printf("extensions used:%s\n", s.extensions_used.empty() ? " none" : "");
  for (const std::string& e : s.extensions_used)
    std::printf("  %s%s\n", e.c_str(), supported_gltf_extension(e) ? "" : "  (not supported: ignored)");
}

void print_variants(const Scene& s) {
  if (s.variants.empty()) return;
  std::printf("material variants (KHR_materials_variants; render --variant NAME): %zu\n", s.variants.size());
  for (const std::string& v : s.variants) std::printf("  '%s'\n", v.c_str());
}

void print_animations(const Scene& s) {
  if (s.animations.empty()) return;
  std::printf(
      "animations: %zu (render --anim-time T poses all of them together at T seconds; --animation N|NAME "
      "one)\n",
      s.animations.size());
  for (size_t i = 0; i < s.animations.size(); ++i) {
    const AnimationDesc& a = s.animations[i];
    std::printf("  %zu: %s, %.4g to %.4g s, %zu channel%s: %s\n", i, quoted_or(a.name, "(unnamed)").c_str(), a.start,
                a.end, a.channels, a.channels == 1 ? "" : "s", a.targets.empty() ? "none" : a.targets.c_str());
  }
}

void print_cameras(const Scene& s) {
  std::printf("cameras: %zu%s\n", s.cameras.size(),
              s.cameras.empty() ? " (render frames the bounds from an elevated three-quarter view)" : "");
  for (size_t i = 0; i < s.cameras.size(); ++i) {
    const CameraDesc& c = s.cameras[i];
    std::string lens = c.projection == Projection::Perspective
                           ? "perspective, yfov " + std::to_string(int(c.yfov * 180.0f / 3.14159265f + 0.5f)) + " deg"
                           : "orthographic, half-height " + std::to_string(c.ymag).substr(0, 6);
    std::printf("  %zu: %s %s at %s looking %s%s\n", i, quoted_or(c.name, "camera").c_str(), lens.c_str(),
                vec(c.position).c_str(), vec(c.forward).c_str(), i == 0 ? "  (the default; render --camera N)" : "");
  }
}

// A type's name from its list (dev::material_type_name, light_type_name), "?" for none
const char* or_unknown(const char* name) { return name ? name : "?"; }

void print_lights(const Scene& s) {
  std::printf("punctual lights: %zu (intensities read as %s)\n", s.punctual_lights.size(),
              enum_name(kLightUnitNames, s.light_units));
  for (const PunctualLightDesc& l : s.punctual_lights)
    std::printf("  %s, colour %s x %.4g %s, at %s\n", or_unknown(dev::light_type_name(punctual_light(l).type)),
                vec(l.color).c_str(), l.intensity, l.type == PunctualType::Directional ? "W/m^2" : "W/sr",
                vec(l.position).c_str());
  size_t emissive = 0, triangles = 0;
  for (const MeshDesc& m : s.meshes) {
    const glm::vec3& e = s.materials.at(m.material).emission;
    if (e.x > 0.0f || e.y > 0.0f || e.z > 0.0f) {
      ++emissive;
      triangles += m.triangles();
    }
  }
  std::printf("emissive primitives: %zu (%zu triangles)\n", emissive, triangles);
  if (s.environment)
    std::printf("environment: %s, strength %.4g, rotation %.4g deg\n", s.environment->source.c_str(),
                s.environment->strength, s.environment->rotation);
  else
    std::printf("background: %s\n", vec(s.background).c_str());
  EnvironmentDesc studio = builtin_environment();
  DefaultLightChoice c = choose_default_light(s, DefaultLight::Auto, s.lighting_given || s.environment.has_value(),
                                              environment_mean_luminance(studio.image));
  std::printf("default light (render --default-light auto): %s: %s\n",
              c.use_environment ? "the built-in studio" : "none", c.reason.c_str());
}

void print_materials(const Scene& s) {
#define CD_SLOT_NAME(slot, name, ...) name,
  const char* kSlots[TEX_SLOTS] = {GLTF_TEXTURES(CD_SLOT_NAME)};
#undef CD_SLOT_NAME
  size_t n = s.materials.size() - 1;  // the last is the glTF default material
  std::printf("materials: %zu\n", n);
  for (size_t i = 0; i < n; ++i) {
    const MaterialDesc& m = s.materials[i];
    std::string textures;
    for (int k = 0; k < TEX_SLOTS; ++k)
      if (m.texture(k).index != NO_TEXTURE) textures += std::string(textures.empty() ? "" : ", ") + kSlots[k];
    char dispersion[48] = "", diffuse_roughness[48] = "";
    if (m.needs("CD_FEATURE_DISPERSION"))
      std::snprintf(dispersion, sizeof dispersion, ", dispersion %.3g", m.dispersion);
    if (m.needs("CD_FEATURE_DIFFUSE_ROUGHNESS"))
      std::snprintf(diffuse_roughness, sizeof diffuse_roughness, ", diffuse roughness %.3g", m.diffuse_roughness);
    std::printf("  %zu: %s %s material, metallic %.3g, roughness %.3g%s%s%s%s%s%s%s\n", i,
                quoted_or(m.name, "(unnamed)").c_str(), or_unknown(dev::material_type_name(m.type)), m.metallic,
                m.roughness, m.transmission > 0.0f ? ", transmissive" : "", m.clearcoat > 0.0f ? ", clearcoat" : "",
                m.diffuse_transmission > 0.0f ? ", diffuse transmission" : "", dispersion,
                m.iridescence > 0.0f ? ", iridescence" : "", diffuse_roughness,
                textures.empty() ? "" : ("; textures: " + textures).c_str());
  }
}

}  // namespace

CLI::App* add_info_command(CLI::App* app, InfoArgs* args) {
  CLI::App* info = app->add_subcommand("info",
                                       "Print what a glTF scene holds as candela reads it: geometry, "
                                       "extensions, cameras, lights, materials and warnings");
  info->add_option("scene", args->scene, "Scene file (.gltf or .glb)")->required();
  info->add_flag("--allow-outside-paths", args->allow_outside_paths,
                 "Let the scene read files outside its folder (absolute paths, .., links out)");
  info->add_option("--anim-time", args->anim_time,
                   "The scene posed by its animations at this moment in seconds, as render --anim-time poses it")
      ->check(finite_number());
  info->add_option("--animation", args->animation, "The animation --anim-time poses, by index or name (default: all)")
      ->needs("--anim-time");
  return info;
}

int run_info_command(const InfoArgs& args) {
  LoadOptions options;
  options.allow_outside_paths = args.allow_outside_paths;
  options.anim_time = args.anim_time;
  options.animation = args.animation;
  Scene s = load_gltf(args.scene, options);
  std::printf("scene: %s\n", args.scene.c_str());
  if (args.anim_time)
    std::printf("posed at %.6g s by %s\n", *args.anim_time,
                args.animation.empty() ? "all its animations" : ("animation " + args.animation).c_str());
  print_geometry(s);
  print_extensions(s);
  print_variants(s);
  print_animations(s);
  print_cameras(s);
  print_lights(s);
  print_materials(s);
  std::printf("warnings: %zu\n", s.warnings.size());
  for (const std::string& w : s.warnings) std::printf("  %s\n", w.c_str());
  return 0;
}

}  // namespace candela
