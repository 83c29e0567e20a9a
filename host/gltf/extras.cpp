// candela's scene extras (scenes[i].extras.candela): environment map, strategy, global
// medium, constant background and the punctual lights' units; and the environment map file, read once the document is.
#include <cmath>
#include <filesystem>

#include "base/error.hpp"
#include "gltf/reader.hpp"
#include "scene/environment.hpp"

namespace candela::gltf {
namespace {

// extras.candela.environment = {"file": "sky.hdr", "strength": 1, "rotation": 0}: the
// file name (relative to the glTF file) goes to EnvironmentDesc::source; load_environment_file
// reads the image
void read_environment(ReadContext& ctx, const tinygltf::Value& env) {
  const char* what = "scene extras candela.environment";
  if (!env.IsObject() || !env.Has("file") || !env.Get("file").IsString())
    throw Error(std::string(what) + " must be an object with a \"file\" string");
  EnvironmentDesc e;
  e.source = env.Get("file").Get<std::string>();
  auto number = [&](const char* key, float fallback) {
    if (!env.Has(key)) return fallback;
    const tinygltf::Value& v = env.Get(key);
    double x = v.IsNumber() ? v.GetNumberAsDouble() : NAN;
    if (!std::isfinite(x) || std::fabs(x) > 1e30)
      throw Error(std::string(what) + "." + key + " must be a finite number");
    return float(x);
  };
  e.strength = number("strength", 1.0f);
  e.rotation = number("rotation", 0.0f);
  if (e.strength < 0.0f) throw Error(std::string(what) + ".strength must not be negative");
  ctx.scene.environment = e;
  ctx.scene.lighting_given = true;
}

void read_strategy(ReadContext& ctx, const tinygltf::Value& st) {
  if (!st.IsString() ||
      (st.Get<std::string>() != "nee" && st.Get<std::string>() != "bsdf" && st.Get<std::string>() != "auto"))
    throw Error("scene extras candela.strategy must be \"nee\", \"bsdf\" or \"auto\"");
  ctx.scene.strategy = st.Get<std::string>();
}

// The medium filling the scene
void read_global_medium(ReadContext& ctx, const tinygltf::Value& v) {
  MediumDesc m = read_medium(v, "scene extras candela.medium", ctx.folder);
  // An infinite ray through a global medium gathers emission / sigma_t: finite only where sigma_t > 0
  for (int k = 0; k < 3; ++k)
    if (m.emission[k] > 0.0f && !m.is_grid() && !(m.sigma_a[k] + m.sigma_s[k] > 0.0f))
      throw Error("scene extras candela.medium: an emitting channel needs sigma_a + sigma_s > 0 (rays reach infinity)");
  ctx.scene.global_medium = int(ctx.scene.media.size());
  ctx.scene.media.push_back(std::move(m));
}

void read_background(ReadContext& ctx, const tinygltf::Value& bg) {
  if (!bg.IsArray() || bg.ArrayLen() != 3) throw Error("scene extras candela.background must be an array of 3 numbers");
  for (int i = 0; i < 3; ++i) {
    if (!bg.Get(i).IsNumber()) throw Error("scene extras candela.background must hold numbers");
    ctx.scene.background[i] = float(bg.Get(i).GetNumberAsDouble());
    if (!(ctx.scene.background[i] >= 0.0f) || !std::isfinite(ctx.scene.background[i]))
      throw Error("scene extras candela.background must be finite and non-negative");
  }
  ctx.scene.lighting_given = true;
}

// How the punctual lights' intensities read; the command line's choice wins
void read_light_units(ReadContext& ctx, const tinygltf::Value& v) {
  std::string units = v.IsString() ? v.Get<std::string>() : "";
  if (units != "photometric" && units != "radiometric")
    throw Error("scene extras candela.light_units must be \"photometric\" or \"radiometric\"");
  if (!ctx.options.light_units)
    ctx.scene.light_units = units == "photometric" ? LightUnits::Photometric : LightUnits::Radiometric;
}

}  // namespace

void read_scene_extras(ReadContext& ctx, const tinygltf::Value& extras) {
  if (!extras.Has("candela")) return;
  const tinygltf::Value& c = extras.Get("candela");
  if (c.Has("environment")) read_environment(ctx, c.Get("environment"));
  if (c.Has("strategy")) read_strategy(ctx, c.Get("strategy"));
  if (c.Has("medium")) read_global_medium(ctx, c.Get("medium"));
  if (c.Has("background")) read_background(ctx, c.Get("background"));
  if (c.Has("light_units")) read_light_units(ctx, c.Get("light_units"));
}

// The environment map's file, beside the glTF file; none is read from memory alone
void load_environment_file(ReadContext& ctx) {
  if (!ctx.scene.environment) return;
  EnvironmentDesc& env = *ctx.scene.environment;
  if (ctx.folder.root.empty()) {
    ctx.warn.add("the environment map " + env.source + " is not loaded: the scene was read without a folder");
    ctx.scene.environment.reset();
  } else {
    std::string path = ctx.folder.resolve(env.source, "scene extras candela.environment.file");
    ctx.scene.environment = load_environment(path, env.strength, env.rotation);
  }
}

}  // namespace candela::gltf
