// The scene a render draws, with the command line's overrides (render_scene.hpp).
#include "app/render_scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "app/options.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/renderer.hpp"
#include "scene/default_light.hpp"
#include "scene/environment.hpp"

namespace candela {
namespace {}  // namespace

void check_camera_options(const RenderArgs& a) {
  if (a.fov && !(*a.fov > 0 && *a.fov < 180)) throw Error("--fov must be between 0 and 180 degrees (exclusive)");
  if (a.aperture && !(*a.aperture >= 0 && std::isfinite(*a.aperture)))
    throw Error("--aperture must be a non-negative radius in scene units");
  if (a.focus_distance && !(*a.focus_distance > 0 && std::isfinite(*a.focus_distance)))
    throw Error("--focus-distance must be a positive distance in scene units");
  if (!a.up.empty() && glm::length(parse_vec3(a.up, "--up")) <= 0.0f)
    throw Error("--up must be a non-zero vector, e.g. 0,1,0");
  if (!a.look_from.empty()) parse_vec3(a.look_from, "--look-from");
  if (!a.look_at.empty()) parse_vec3(a.look_at, "--look-at");
}

namespace {

std::string format_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// The camera's up vector must leave a direction across the view; a lens wider than the
// scene by far only blurs it into float rounding
void check_camera_against_scene(const CameraDesc& cam, const Scene& scene) {
  glm::vec3 f = glm::normalize(cam.forward), u = cam.up;
  if (!(glm::length(glm::cross(f, u)) > 1e-4f * glm::length(u)))
    throw Error("the camera's up vector is parallel to its view direction: give --up across the view, e.g. 0,0,1");
  Bounds b = scene.bounds();
  float extent = glm::length(b.hi - b.lo);
  if (cam.aperture_radius > 1000.0f * std::max(extent, cam.focus_distance.value_or(0.0f)))
    throw Error("--aperture " + format_number(cam.aperture_radius) +
                " is more than 1000 times the scene's size: every point would be a blur");
}

// --look-from, --look-at, --up; returns the look-at point's distance when it is given
std::optional<float> aim_camera(const RenderArgs& a, CameraDesc* cam) {
  std::optional<float> look_at_distance;
  if (!a.look_from.empty()) cam->position = parse_vec3(a.look_from, "--look-from");
  if (!a.look_at.empty()) {
    glm::vec3 target = parse_vec3(a.look_at, "--look-at");
    if (glm::length(target - cam->position) <= 0) throw Error("--look-at must differ from the camera position");
    cam->forward = glm::normalize(target - cam->position);
    look_at_distance = glm::length(target - cam->position);
  }
  if (!a.up.empty()) cam->up = parse_vec3(a.up, "--up");
  return look_at_distance;
}

// --fov, --aperture, --focus-distance
void set_lens(const RenderArgs& a, std::optional<float> look_at_distance, CameraDesc* cam) {
  if (a.fov) {  // a field of view makes the camera perspective
    cam->projection = Projection::Perspective;
    cam->yfov = *a.fov * 3.14159265f / 180.0f;
  }
  if (a.aperture) {
    if (*a.aperture > 0 && cam->projection == Projection::Orthographic)
      throw Error("--aperture needs a perspective camera: the scene camera is orthographic (add --fov to replace it)");
    cam->aperture_radius = *a.aperture;
  }
  // Focus: --focus-distance, else the look-at point, else the scene camera's extras,
  // else (resolve_camera) the bounds' centre along the view axis
  if (a.focus_distance)
    cam->focus_distance = *a.focus_distance;
  else if (look_at_distance)
    cam->focus_distance = look_at_distance;
}

void apply_camera_options(const RenderArgs& a, Scene* scene) {
  check_camera_options(a);
  if (a.camera) {
    int n = int(scene->cameras.size());
    if (*a.camera < 0 || *a.camera >= n)
      throw Error("--camera " + std::to_string(*a.camera) + ": the scene has " +
                  (n == 0   ? "no camera"
                   : n == 1 ? "one camera (0)"
                            : std::to_string(n) + " cameras (0 to " + std::to_string(n - 1) + ")"));
    scene->camera = scene->cameras[size_t(*a.camera)];
  }
  bool any = !a.look_from.empty() || !a.look_at.empty() || !a.up.empty() || a.fov || a.aperture || a.focus_distance;
  if (!any) return;
  CameraDesc cam = scene->camera ? *scene->camera : framing_camera(*scene);
  std::optional<float> look_at_distance = aim_camera(a, &cam);
  set_lens(a, look_at_distance, &cam);
  check_camera_against_scene(cam, *scene);
  scene->camera = cam;
}

// --background replaces the scene's background and map; --env the map
void apply_background_options(const RenderArgs& a, Scene* scene) {
  if (!a.background.empty()) {
    scene->background = parse_vec3(a.background, "--background");
    if (scene->background.x < 0 || scene->background.y < 0 || scene->background.z < 0)
      throw Error("--background must not be negative");
    scene->environment.reset();  // the constant replaces the scene's map too
    scene->lighting_given = true;
  }
  if (!a.env.empty()) {
    scene->environment = load_environment(a.env, 1.0f, 0.0f);
    scene->lighting_given = true;
  }
}

// The built-in studio, by --default-light's rule (scene/default_light.hpp), said in one line;
// the choice, with the share of light the scene's own lights give
DefaultLightChoice add_default_light(const RenderArgs& a, Scene* scene) {
  DefaultLight mode = parse_enum(kDefaultLightNames, "--default-light", a.default_light);
  bool given = scene->lighting_given || scene->environment.has_value();
  EnvironmentDesc studio = builtin_environment();
  DefaultLightChoice c = choose_default_light(*scene, mode, given, environment_mean_luminance(studio.image));
  if (a.repeat) {  // a later frame: said for the first
    if (c.use_environment) scene->environment = std::move(studio);
  } else if (c.use_environment) {
    bool own_light = scene->has_light();
    scene->environment = std::move(studio);
    std::fprintf(stderr, "note: lighting the scene with the built-in studio environment: %s (--default-light off %s)\n",
                 c.reason.c_str(), own_light ? "leaves it out" : "keeps the scene black");
  } else if (!given && !scene->has_light()) {
    std::fprintf(stderr, "warning: the scene has no light and --default-light is off: the image will be black\n");
  } else if (mode == DefaultLight::Auto && !given) {
    std::fprintf(stderr, "note: the scene's own lights light it: %s (--default-light on adds the built-in studio)\n",
                 c.reason.c_str());
  }
  return c;
}

// Without --exposure, whether the automatic exposure applies (scene/default_light.hpp); its
// value is metered from the rendered image and said then (render_command.cpp)
void choose_exposure(const DefaultLightChoice& c, RenderArgs* a) {
  if (a->exposure) return;
  if (automatic_exposure(c)) a->auto_exposure_share = c.own_share;
}

// --env-strength, --env-rotation
void apply_environment_options(const RenderArgs& a, Scene* scene) {
  if (!scene->environment) {
    if (a.env_strength || a.env_rotation)
      std::fprintf(stderr,
                   "warning: --env-strength and --env-rotation apply to an environment map; the scene has none\n");
    return;
  }
  EnvironmentDesc& env = *scene->environment;
  if (a.env_strength) env.strength = *a.env_strength;
  if (a.env_rotation) env.rotation = *a.env_rotation;
  if (!(env.strength >= 0.0f) || !std::isfinite(env.strength))
    throw Error("--env-strength must be finite and non-negative");
  if (!std::isfinite(env.rotation)) throw Error("--env-rotation must be finite");
  if (!scene->has_light())
    std::fprintf(stderr, "warning: the scene has no light: the environment map is black; the image will be black\n");
}

// No BSDF-sampled ray can hit a point, spot or directional light
void warn_unreachable_lights(const RenderArgs& a, const Scene& scene) {
  size_t n = scene.punctual_light_count();
  if (n > 0 && parse_enum(kStrategyNames, "--strategy", a.strategy) == Strategy::Bsdf)
    std::fprintf(
        stderr,
        "warning: the scene's %zu punctual light%s contribute%s nothing under --strategy bsdf; use nee or auto\n", n,
        n == 1 ? "" : "s", n == 1 ? "s" : "");
}

}  // namespace

LoadOptions render_load_options(const RenderArgs& a) {
  LoadOptions options;
  options.allow_outside_paths = a.allow_outside_paths;
  if (!a.light_units.empty()) options.light_units = parse_enum(kLightUnitNames, "--light-units", a.light_units);
  options.variant = a.variant;
  options.animation = a.animation;
  options.anim_time = a.anim_time;
  return options;
}

Scene load_render_scene(RenderArgs* args, const GltfDocument* document) {
  RenderArgs& a = *args;
  Scene scene = document ? document->scene(a.anim_time) : load_gltf(a.scene, render_load_options(a));
  if (a.strategy.empty()) a.strategy = scene.strategy.empty() ? "auto" : scene.strategy;
  apply_background_options(a, &scene);
  apply_camera_options(a, &scene);
  if (!a.repeat)
    for (const auto& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  choose_exposure(add_default_light(a, &scene), &a);
  apply_environment_options(a, &scene);
  warn_unreachable_lights(a, scene);
  if (!scene.camera && !a.repeat) {
    size_t backdrops = 0;
    framing_bounds(scene, &backdrops);
    std::string left_out = backdrops == 0 ? std::string()
                           : backdrops == 1
                               ? " without its ground plane or backdrop (a flat mesh over 4 times the rest's size)"
                               : " without its " + std::to_string(backdrops) +
                                     " ground planes or backdrops (flat meshes over 4 times the rest's size)";
    std::fprintf(stderr,
                 "note: the scene has no camera; framing its bounds%s from an elevated three-quarter view "
                 "(--look-from and --look-at choose another)\n",
                 left_out.c_str());
  }
  return scene;
}

Shutter parse_shutter(const std::string& text) {
  size_t colon = text.find(':');
  Shutter s;
  char* end = nullptr;
  bool ok = colon != std::string::npos && colon > 0 && colon + 1 < text.size();
  if (ok) {
    std::string open = text.substr(0, colon), close = text.substr(colon + 1);
    s.open = std::strtod(open.c_str(), &end);
    ok = *end == 0;
    s.close = std::strtod(close.c_str(), &end);
    ok = ok && *end == 0 && std::isfinite(s.open) && std::isfinite(s.close) && s.open < s.close &&
         s.close - s.open <= 1000.0;
  }
  if (!ok)
    throw Error("--shutter must be OPEN:CLOSE, frames relative to the frame's time with OPEN < CLOSE (e.g. 0:0.5 "
                "or -0.25:0.25), not '" + text + "'");
  return s;
}

double shutter_middle(const RenderArgs& a, double frame_time) {
  Shutter s = parse_shutter(a.shutter);
  return frame_time + 0.5 * (s.open + s.close) / a.fps;
}

void add_motion_poses(const RenderArgs& a, const GltfDocument& document, Scene* scene) {
  Shutter shutter = parse_shutter(a.shutter);
  const int steps = a.shutter_steps;
  const size_t poses = size_t(steps) + 1;
  int w = 0, h = 0;
  resolve_image_size(a, *scene, &w, &h);
  const float aspect = float(w) / float(h);
  const CameraDesc still = resolve_camera(*scene, aspect);
  for (MeshDesc& m : scene->meshes) {
    m.motion_positions.assign(m.positions.size() * poses, glm::vec3(0.0f));
    m.motion_normals.assign(m.normals.empty() ? 0 : m.normals.size() * poses, glm::vec3(0.0f));
  }
  scene->camera_steps.clear();
  for (int s = 0; s < steps + 1; ++s) {
    double frames = shutter.open + (shutter.close - shutter.open) * double(s) / double(steps);
    Scene pose = document.scene(*a.anim_time + frames / a.fps);
    apply_camera_options(a, &pose);
    if (pose.meshes.size() != scene->meshes.size())
      throw Error("--shutter: the scene's meshes change in number across the shutter");
    for (size_t i = 0; i < pose.meshes.size(); ++i) {
      const MeshDesc& from = pose.meshes[i];
      MeshDesc& to = scene->meshes[i];
      if (from.positions.size() != to.positions.size() || from.normals.size() != to.normals.size())
        throw Error("--shutter: a mesh of the scene changes its vertex count across the shutter");
      for (size_t v = 0; v < from.positions.size(); ++v) {
        to.motion_positions[v * poses + size_t(s)] = from.positions[v];
        if (!from.normals.empty()) to.motion_normals[v * poses + size_t(s)] = from.normals[v];
      }
    }
    scene->camera_steps.push_back(pose.cameras.empty() ? still : resolve_camera(pose, aspect));
  }
  scene->motion_steps = steps;
}

void resolve_image_size(const RenderArgs& a, const Scene& scene, int* w, int* h) {
  float aspect = scene.camera ? scene.camera->aspect : 0.0f;
  *w = a.width;
  *h = a.height;
  if (*w == 0 && *h == 0) *w = 512;
  auto scaled = [](double v) { return int(std::clamp(std::round(v), 1.0, 65536.0)); };
  if (*h == 0) *h = aspect > 0 ? scaled(*w / double(aspect)) : *w;
  if (*w == 0) *w = aspect > 0 ? scaled(*h * double(aspect)) : *h;
}

}  // namespace candela
