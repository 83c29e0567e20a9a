// The render settings, each once (settings.hpp); the help-options command that prints them.
#include "app/settings.hpp"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/options.hpp"
#include "app/render_scene.hpp"
#include "app/report.hpp"
#include "base/error.hpp"
#include "render/aov.hpp"
#include "render/denoise.hpp"
#include "render/tonemap.hpp"
#include "scene/default_light.hpp"
#include "scene/scene.hpp"

namespace candela {
namespace {

using Add = RenderSetting::Add;

// An option bound to a member of RenderArgs (or of its settings: `in_settings`), with
// the parser's checks of its value
template <typename T>
Add option(T RenderArgs::*member, std::function<void(CLI::Option*)> checks = {}) {
  return [member, checks](CLI::App* render, RenderArgs& a, const RenderSetting& s) {
    CLI::Option* o = render->add_option(s.flags, a.*member, s.help);
    if (checks) checks(o);
    return o;
  };
}
template <typename T>
Add in_settings(T RenderSettings::*member, std::function<void(CLI::Option*)> checks = {}) {
  return [member, checks](CLI::App* render, RenderArgs& a, const RenderSetting& s) {
    CLI::Option* o = render->add_option(s.flags, a.settings.*member, s.help);
    if (checks) checks(o);
    return o;
  };
}
Add flag(bool RenderArgs::*member) {
  return [member](CLI::App* render, RenderArgs& a, const RenderSetting& s) {
    return render->add_flag(s.flags, a.*member, s.help);
  };
}
std::function<void(CLI::Option*)> check(CLI::Validator v) {
  return [v](CLI::Option* o) { o->check(v); };
}

// "a|b|c": an enum's names as the docs give the option's value
template <typename E, size_t N>
std::string choices(const EnumName<E> (&table)[N]) {
  std::string s;
  for (const EnumName<E>& row : table) s += (s.empty() ? "" : "|") + std::string(row.name);
  return s;
}

// An option naming a value of an enum setting, `member` of RenderSettings: the name is
// kept in args.names[flag] (the default until given), checked and turned into the setting
// by apply, and recorded as the setting's name
template <typename E, size_t N>
RenderSetting enum_setting(const std::string& flag, const EnumName<E> (&table)[N], E RenderSettings::*member,
                           std::string help, std::string doc, std::string default_value) {
  RenderSetting s(
      flag, choices(table), std::move(help), std::move(doc), std::move(default_value),
      [](CLI::App* render, RenderArgs& a, const RenderSetting& self) {
        std::string& name = a.names[self.flags];
        name = self.default_value;
        return render->add_option(self.flags, name, self.help);
      },
      [&table, member, flag](const RenderArgs& a, RenderSettings* settings) {
        settings->*member = parse_enum(table, flag, a.names.at(flag));
      });
  s.record = [&table, member](const RenderArgs&, const RenderSettings& settings) -> SettingValue {
    return std::string(enum_name(table, settings.*member));
  };
  return s;
}

// The row's entries that only the record of a render needs: the value, unless the row has
// it (enum_setting), and where it goes
RenderSetting recorded(RenderSetting s, std::function<SettingValue(const RenderArgs&, const RenderSettings&)> record,
                       const char* metadata, const char* stats, bool must_match, const char* kernel = "") {
  if (record) s.record = record;
  s.metadata = metadata;
  s.stats = stats;
  s.must_match = must_match;
  s.kernel = kernel;
  return s;
}

constexpr bool kMustMatch = true;

uint64_t count(uint64_t v) { return v; }

std::vector<RenderSetting> make_render_settings() {
  using A = RenderArgs;
  using S = RenderSettings;
  const uint64_t kMaxIndex = 4294967295LL;
  return {
      recorded(
          {"scene", "SCENE", "Scene file (.gltf or .glb)",
           "The scene, `.gltf` or `.glb` ([scene-format.md](scene-format.md)).", "",
           option(&A::scene, [](CLI::Option* o) { o->required(); })},
          [](const A& a, const S&) -> SettingValue { return a.scene; }, "scene", nullptr, kMustMatch),
      {"-o,--output", "FILE", "Output image: .exr (linear), .png or .jpg (tone-mapped sRGB, --tonemap); repeatable",
       "Required, repeatable. `.exr`: linear float RGB with the metadata below. `.png`, `.jpg` (or `.jpeg`): 8-bit "
       "sRGB after `--exposure` and the `--tonemap` display transform.",
       "", option(&A::outputs, [](CLI::Option* o) { o->required(); })},
      // Samples, size, devices and the path tracer's settings
      {"--spp", "N", "Samples per pixel (default 64)", "Samples per pixel, 1 to 2²⁴ (default 64). Excludes `--time`.",
       "64", option(&A::spp, check(integer_in(1, 1 << 24)))},
      {"--time", "SECONDS", "Render for this many seconds instead of a sample count",
       "Render for this long instead of a fixed sample count (no launch starts after the time is up; the first "
       "always runs). Excludes `--spp`.",
       "", option(&A::time, [](CLI::Option* o) { o->check(positive_number())->excludes("--spp"); })},
      recorded(
          {"--noise-threshold", "E",
           "Adaptive sampling: after the first 16 samples, samples go only to pixels whose estimated relative "
           "error exceeds E (e.g. 0.02); --spp is then the most a pixel gets, --time the budget; the spp AOV "
           "holds the counts",
           "Adaptive sampling, E > 0 ([integrator.md](integrator.md#adaptive-sampling)): every pixel gets the first "
           "16 samples (all when `--spp` is lower), then passes go only to pixels whose estimated relative error of "
           "the mean, or a neighbour's, exceeds E, until none does, `--spp` (the most a pixel gets) is reached or "
           "`--time` is up. One device; not with `--mpi`. The `spp` AOV holds each pixel's count.",
           "", in_settings(&S::noise_threshold, check(positive_number())),
           [](const A& a, S* s) {
             if (s->noise_threshold > 0.0 && a.mpi) throw Error("--noise-threshold does not work with --mpi");
           }},
          [](const A&, const S& s) -> SettingValue {
            char text[32] = "off";
            if (s.noise_threshold > 0.0) std::snprintf(text, sizeof text, "%.6g", s.noise_threshold);
            return std::string(text);
          },
          "noise_threshold", "noise_threshold", kMustMatch, "CD_ADAPTIVE"),
      recorded(
          {"--width", "W", "Image width (default 512, or from --height and the camera aspect)", "", "512",
           option(&A::width, check(integer_in(1, 65536)))},
          [](const A&, const S& s) -> SettingValue { return count(s.width); }, nullptr, "width", false,
          "RenderParams.width"),
      recorded(
          {"--height", "H", "Image height (default from the camera aspect ratio, else the width)",
           "Image size, 1 to 65536. The default is 512 wide, with the height from the camera's aspect ratio: "
           "`aspectRatio` for a perspective camera, `xmag / ymag` for an orthographic one, square without either. "
           "Given one of them, the other follows from the same ratio.",
           "", option(&A::height, check(integer_in(1, 65536)))},
          [](const A&, const S& s) -> SettingValue { return count(s.height); }, nullptr, "height", false,
          "RenderParams.height"),
      {"--device", "SEL",
       "OpenCL device: index, P.D, cpu, gpu, intel, or a name substring (pocl, rusticl, nvidia); default first GPU, "
       "else first CPU. A comma-separated list (pocl,rusticl) or `all` renders on several devices at once",
       "`0` (an index of `candela devices`), `1.0` (platform.device), `cpu`, `gpu`, `intel` (Intel's OpenCL CPU "
       "runtime, [devices.md](devices.md#intels-opencl-cpu-runtime)), or a case-insensitive substring "
       "of the platform's name, vendor or version or of the device's name (`pocl`, `rusticl`, `llvmpipe`, "
       "`nvidia`). The default is the first GPU, else the first CPU. A comma-separated list (`pocl,rusticl`) or "
       "`all` (every listed device, once each) renders on several devices at once ([devices.md](devices.md)).",
       "", option(&A::device)},
      recorded(
          {"--seed", "S", "Random seed (default 0)",
           "Random seed (default 0). The image depends only on the seed, the spp and `--sample-offset`, never on "
           "how the samples are split into launches or devices.",
           "0", in_settings(&S::seed, check(integer_in(0, kMaxIndex)))},
          [](const A&, const S& s) -> SettingValue { return count(s.seed); }, "seed", "seed", kMustMatch,
          "RenderParams.seed"),
      recorded(
          {"--max-depth", "D", "Maximum number of bounces (default 16)",
           "Maximum number of bounces, 0 to 100000 (default 16). 0 shows only emitters seen directly; 1 adds "
           "direct lighting.",
           "16", in_settings(&S::max_depth, check(integer_in(0, 100000)))},
          [](const A&, const S& s) -> SettingValue { return count(s.max_depth); }, "max_depth", "max_depth", kMustMatch,
          "RenderParams.max_depth"),
      recorded(
          {"--strategy", choices(kStrategyNames),
           enum_names(kStrategyNames, true) + "; default: the scene's extras candela.strategy, else auto",
           "The estimator ([integrator.md](integrator.md#strategies)). Default: the scene's "
           "`scenes[i].extras.candela.strategy`, else `auto`. Punctual lights contribute only under `nee` and "
           "`auto`; `bsdf` warns once when the scene has some.",
           "auto", option(&A::strategy),
           // a bad name fails before loading; the setting waits for the scene's (complete_settings)
           [](const A& a, S*) {
             if (!a.strategy.empty()) parse_enum(kStrategyNames, "--strategy", a.strategy);
           }},
          [](const A& a, const S&) -> SettingValue { return a.strategy; }, "strategy", "strategy", kMustMatch,
          "RenderParams.strategy"),
      recorded(
          {"--light-selection", "tree|power",
           "tree|power: light selection by the light tree (estimated contribution at the shading point; "
           "default) or by power alone",
           "How a shadow ray picks its light (default `tree`): `tree` descends the light tree, weighing the "
           "emissive triangles, point and spot lights by what each can send to the shading point (directional "
           "lights and the environment keep their share by power); `power` picks every light in proportion to "
           "its power alone ([lights.md](lights.md#light-selection)).",
           "tree", option(&A::light_selection, check(CLI::IsMember({"tree", "power"})))},
          [](const A& a, const S&) -> SettingValue { return a.light_selection; }, "light_selection", "light_selection",
          kMustMatch, "CD_FEATURE_LIGHT_TREE"),
      recorded(
          {"--no-energy-compensation", "",
           "Leave out the multiple scattering of rough GGX lobes, rough glass and the clear coat (on by "
           "default: rough metal and glass keep their albedo)",
           "Leave out the multiple-scattering compensation of rough GGX lobes, rough glass and the clear coat "
           "([materials.md](materials.md#energy-compensation)), which is on by default.",
           "", flag(&A::no_energy_compensation),
           [](const A& a, S* s) { s->energy_compensation = !a.no_energy_compensation; }},
          [](const A&, const S& s) -> SettingValue { return s.energy_compensation; }, "energy_compensation",
          "energy_compensation", kMustMatch, "RenderParams.energy_compensation"),
      // The scene's lighting: background, environment map, default light
      {"--background", "R,G,B",
       "Constant background radiance R,G,B (replaces the scene's background and environment map)",
       "Constant background radiance (non-negative), replacing the scene's background and environment map. Excludes "
       "`--env`.",
       "", option(&A::background)},
      {"--env", "FILE", "Equirectangular environment map (.hdr, .exr, .png, .jpg), replacing the scene's",
       "Equirectangular environment map (`.hdr`, `.exr`, `.png`, `.jpg`: anything OpenImageIO reads), replacing the "
       "scene's ([lights.md](lights.md#environment-maps)). A missing or unreadable file is an error. Excludes "
       "`--background`.",
       "", option(&A::env, [](CLI::Option* o) { o->excludes("--background"); })},
      {"--env-strength", "S", "Environment map strength, a radiance scale (default 1, or the scene's)",
       "Radiance scale of the environment map, finite and ≥ 0 (default 1, or the scene's). Applies to the built-in "
       "studio too.",
       "1", option(&A::env_strength, check(finite_number()))},
      {"--env-rotation", "DEG",
       "Environment map rotation about +Y in degrees, counter-clockwise seen from above (default 0, or the scene's)",
       "Rotation of the map about +Y in degrees, counter-clockwise seen from above (default 0, or the scene's).", "0",
       option(&A::env_rotation, check(finite_number()))},
      {"--default-light", choices(kDefaultLightNames),
       "The built-in studio environment: " + enum_names(kDefaultLightNames, true),
       "The built-in studio environment ([lights.md](lights.md#default-lighting)): `auto` (default) adds it when the "
       "scene sets no environment or background of its own and its own lights give under 10 % of the light on its "
       "surfaces; `on` always (unless the scene sets its own); `off` never. One note on stderr says what was chosen "
       "and why.",
       "auto", option(&A::default_light),
       [](const A& a, S*) { parse_enum(kDefaultLightNames, "--default-light", a.default_light); }},
      {"--no-default-light", "", "Same as --default-light off",
       "The same as `--default-light off` (the option of earlier versions, kept).", "",
       [](CLI::App* render, A& a, const RenderSetting& s) {
         return render->add_flag_callback(
             s.flags, [&a] { a.default_light = "off"; }, s.help);
       }},
      {"--light-units", choices(kLightUnitNames),
       "KHR_lights_punctual intensities: " + enum_names(kLightUnitNames, true) +
           "; default: the scene's extras candela.light_units, else photometric",
       "How `KHR_lights_punctual` intensities read: `photometric` (candela and lux divided by 683 lm/W, the default "
       "unless the scene's extras say otherwise) or `radiometric` (one to one, for files written that way) "
       "([lights.md](lights.md#punctual-lights)).",
       "photometric", option(&A::light_units),
       [](const A& a, S*) {
         if (!a.light_units.empty()) parse_enum(kLightUnitNames, "--light-units", a.light_units);
       }},
      {"--variant", "NAME",
       "KHR_materials_variants: render the scene's material variant NAME (candela info lists them; default: the "
       "default materials)",
       "Render the scene's `KHR_materials_variants` variant NAME: each primitive its mapping names takes that "
       "variant's material ([scene-format.md](scene-format.md#gltf-support)); default: the default materials. "
       "`candela info` lists the variants; an unknown name is an error that lists them.",
       "", option(&A::variant)},
      recorded(
          {"--animation", "NAME",
           "The animation --anim-time poses, by index or name (candela info lists them; default: all of them "
           "together)",
           "The animation `--anim-time` poses, by index or name (`candela info` lists them); default: all of them "
           "together, as viewers play them ([scene-format.md](scene-format.md#gltf-support)). An unknown one is an "
           "error that lists them; it needs `--anim-time` or `--frames`.",
           "", option(&A::animation),
           [](const A& a, S*) {
             if (!a.animation.empty() && !a.anim_time && a.frames.empty())
               throw Error("--animation needs --anim-time or --frames (the moment to render)");
           }},
          [](const A& a, const S&) -> SettingValue {
            return !a.animation.empty() ? a.animation : a.anim_time ? "all" : "none";
          },
          "animation", "animation", kMustMatch),
      recorded(
          {"--anim-time", "SECONDS",
           "Pose the scene's animations at this moment, in seconds (default: the rest pose, animations ignored)",
           "Pose the scene's animations at this moment, seconds ≥ 0: node transforms, skins, morph weights, "
           "cameras and lights, as the glTF specification samples them (before the first key and after the last, "
           "the end values). Default: the rest pose, the animations ignored.",
           "", option(&A::anim_time, check(finite_number())),
           [](const A& a, S*) {
             if (a.anim_time && !(std::isfinite(*a.anim_time) && *a.anim_time >= 0.0))
               throw Error("--anim-time must be a finite number of seconds, at least 0");
           }},
          [](const A& a, const S&) -> SettingValue {
            if (!a.anim_time) return std::string("none");
            char text[32];
            std::snprintf(text, sizeof text, "%.9g", *a.anim_time);
            return std::string(text);
          },
          "anim_time", "anim_time", kMustMatch),
      {"--frames", "A:B[:STEP]",
       "Render the frames A to B (every STEP-th) of the animations, frame f at f / --fps seconds, into outputs "
       "whose run of # takes the frame number (-o fox_####.png)",
       "", "", option(&A::frames, [](CLI::Option* o) { o->excludes("--anim-time"); })},
      {"--fps", "R", "Frames per second of --frames (default 24)", "", "24", option(&A::fps, check(positive_number()))},
      {"--skip-existing", "", "With --frames: leave out the frames whose outputs all exist (to resume a sequence)",
       "A sequence: frames A, A + STEP, ... up to B, frame f posed at f / R seconds (R default 24). Every output "
       "(and `--variance`, `--stats`) needs a run of `#` in its file name for the zero-padded frame number "
       "(`-o fox_####.png`: `fox_0007.png`). The scene is read once, the kernel built once; each frame poses, "
       "compiles (BVH, lights) and renders the scene, frame f with seed S + f (S: `--seed`; frames decorrelated, "
       "a run repeatable), the first frame's automatic camera and exposure. A progress line per frame; Ctrl-C writes the frame in progress and stops; "
       "`--skip-existing` leaves out frames written whole (resuming). Under `--mpi` the ranks split the frames "
       "(rank r renders the r-th, (r + N)-th, ... of the sequence), each writing its own. Excludes `--anim-time`.",
       "", flag(&A::skip_existing)},
      recorded(
          {"--shutter", "OPEN:CLOSE",
           "Motion blur: each sample at a moment of this span of frames around the frame's time (e.g. 0:0.5 or "
           "-0.25:0.25; needs --anim-time or --frames)",
           "", "", option(&A::shutter),
           [](const A& a, S* s) {
             s->motion_steps = 0;
             if (a.shutter.empty()) return;
             parse_shutter(a.shutter);
             if (!a.anim_time && a.frames.empty())
               throw Error("--shutter needs --anim-time or --frames (the frame whose moments it blurs)");
             s->motion_steps = uint32_t(a.shutter_steps);
           }},
          [](const A& a, const S&) -> SettingValue {
            return a.shutter.empty() ? std::string("none")
                                     : a.shutter + " in " + std::to_string(a.shutter_steps) + " steps";
          },
          "shutter", "shutter", kMustMatch, "CD_MOTION_STEPS"),
      {"--shutter-steps", "K", "With --shutter: poses across the shutter less one, 1 to 64 (default 4)",
       "Motion blur ([scene-format.md](scene-format.md#motion-blur)): each camera sample takes a uniform moment "
       "in OPEN to CLOSE, in frames (1 / `--fps` seconds) relative to the frame's time (`--anim-time` or the "
       "frame of `--frames`, which it needs), OPEN < CLOSE; camera, nodes, skins and morphs move. The scene is "
       "posed at K + 1 moments evenly across the shutter, 1 ≤ K ≤ 64 (default 4), linear between them. Default: "
       "no blur.",
       "4", option(&A::shutter_steps, check(integer_in(1, 64)))},
      {"--stats", "FILE.json", "Write render statistics as JSON to this file",
       "Write render statistics ([below](#statistics---stats)).", "", option(&A::stats)},
      {"--exposure", "EV",
       "Exposure of PNG/JPEG outputs in stops (default 0, or metered from the image for a scene whose own lights "
       "are over 4x the studio's); EXR stays linear",
       "Exposure of PNG/JPEG outputs in stops, finite; EXR stays linear. Default 0, except for a scene lit by its "
       "own lights more than 4 times brighter than the studio would light it: then metered from the rendered image "
       "(its log-average luminance to middle grey), announced ([lights.md](lights.md#automatic-exposure)).",
       "0", option(&A::exposure, check(finite_number())),
       [](const A& a, S*) {
         if (a.exposure && !std::isfinite(*a.exposure)) throw Error("--exposure must be a finite number of stops");
       }},
      {"--tonemap", choices(kTonemapNames), "Display transform of PNG/JPEG outputs: " + enum_names(kTonemapNames, true),
       "Display transform of PNG/JPEG outputs ([below](#outputs)); default `neutral`.", "neutral", option(&A::tonemap),
       [](const A& a, S*) { parse_tonemap(a.tonemap); }},
      // The camera, replacing or changing the scene's (checked together: check_camera_options)
      {"--camera", "N",
       "The scene's camera to render through, by index (candela info lists them; default 0, the first)",
       "Render through the scene's camera N (0-based, in node order; default 0, the first). `candela info` lists "
       "them; an index out of range is an error.",
       "0", option(&A::camera, check(integer_in(0, 1 << 30)))},
      {"--look-from", "X,Y,Z", "Camera position X,Y,Z (overrides the scene camera)",
       "Camera position; overrides the scene camera (or replaces the automatic one).", "", option(&A::look_from)},
      {"--look-at", "X,Y,Z", "Camera target X,Y,Z", "Camera target.", "", option(&A::look_at)},
      {"--up", "X,Y,Z", "Camera up vector X,Y,Z (default 0,1,0)", "Camera up vector (default 0,1,0).", "0,1,0",
       option(&A::up)},
      {"--fov", "DEG", "Vertical field of view in degrees, 0 < FOV < 180 (makes the camera perspective)",
       "Vertical field of view, strictly between 0 and 180 degrees. Makes the camera perspective (an orthographic "
       "scene camera otherwise keeps its projection).",
       "", option(&A::fov, check(finite_number()))},
      {"--aperture", "R",
       "Thin-lens aperture radius in scene units for depth of field (default 0: pinhole; perspective cameras)",
       "Thin-lens aperture *radius* in scene units, ≥ 0 (default 0: a pinhole, or the scene camera's extras). "
       "Perspective cameras only: an error on an orthographic one ([integrator.md](integrator.md#cameras)).",
       "0", option(&A::aperture, check(finite_number()))},
      {"--focus-distance", "D",
       "Distance of the sharp plane along the view axis (default: the --look-at point, else the scene camera's "
       "extras, else the scene bounds' centre)",
       "Distance of the sharp plane along the view axis, > 0. Default: the distance to the `--look-at` point when "
       "one is given, else the scene camera's extras, else the distance from the camera to the centre of the scene's "
       "bounds along the view axis (the bounds' radius when that centre is not in front of the camera).",
       "", option(&A::focus_distance, check(finite_number()))},
      recorded(enum_setting("--filter", kPixelFilterNames, &S::filter,
                            "Pixel filter: " + enum_names(kPixelFilterNames, true),
                            "Pixel filter (default `box`); `tent` has radius 1 pixel, `gaussian` σ = 0.5 pixel "
                            "([integrator.md](integrator.md#pixel-filters)).",
                            "box"),
               nullptr, "filter", "filter", kMustMatch, "RenderParams.filter"),
      recorded(
          enum_setting("--sampler", kSamplerNames, &S::sampler, "Random numbers: " + enum_names(kSamplerNames, true),
                       "Where the random numbers come from (default `sobol`: Owen-scrambled Sobol points; "
                       "`independent`: hashed independent numbers) ([integrator.md](integrator.md#sampler)).",
                       "sobol"),
          nullptr, "sampler", "sampler", kMustMatch, "CD_SAMPLER_SOBOL"),
      {"-q,--quiet", "", "No progress or scene summary", "No progress output and no scene summary.", "",
       flag(&A::quiet)},
      {"--allow-outside-paths", "",
       "Let the scene read files outside its folder: absolute paths, .., links that lead out (by default a scene's "
       "buffers, images, maps and grids must lie inside its folder)",
       "Let the scene read files outside its folder: absolute paths, `..`, links that lead out (by default a scene's "
       "buffers, images, maps and grids must lie inside its folder; [below](#messages-and-errors)).",
       "", flag(&A::allow_outside_paths)},
      // Speed against accuracy (README)
      {"--variance", "FILE.exr",
       "Also write the variance of each pixel's mean, M2 / (n (n - 1)) per channel, to this .exr (infinite where a "
       "pixel has fewer than 2 samples)",
       "Also write the variance of each pixel's mean, M2 / (n (n − 1)) per channel from the film's Welford sums (+∞ "
       "where a pixel has fewer than 2 samples), with the image's metadata and `candela:image` = `variance_of_mean` "
       "([accuracy.md](accuracy.md#variance-images)).",
       "", option(&A::variance)},
      recorded(
          {"--aov", "LIST",
           "Also compute these AOVs, a comma list of albedo, normal, depth, alpha, spp: channels of every .exr "
           "output; -o FILE.png:NAME writes one as an image",
           "Arbitrary output variables, a comma list of `albedo`, `normal`, `depth`, `alpha`, `spp` "
           "([below](#aovs-and-a-transparent-background)): channels `albedo.R/G/B`, `normal.X/Y/Z`, `depth.Z`, `A`, "
           "`spp.Y` of every `.exr` output. `-o FILE.png:NAME` (or `.jpg`) writes one as an image, and adds it.",
           "", option(&A::aov), [](const A& a, S* s) { s->aov = aovs_need_kernel(requested_aovs(a)); }},
          [](const A& a, const S&) -> SettingValue { return aov_list_text(requested_aovs(a)); }, "aov", "aov",
          kMustMatch, "CD_AOV"),
      recorded(
          {"--transparent", "",
           "Alpha 0 where the camera sees the environment (fractionally through smooth glass and alpha blending); "
           "PNG outputs RGBA, EXR ones with A; the environment still lights the scene",
           "A transparent background ([below](#aovs-and-a-transparent-background)): the environment that camera "
           "paths see directly or through smooth glass and blended alpha is left out of the image, and alpha says "
           "how much of it was; it still lights the scene. PNG outputs are RGBA, EXR ones have `A`.",
           "", flag(&A::transparent), [](const A& a, S* s) { s->transparent = a.transparent; }},
          [](const A& a, const S&) -> SettingValue { return a.transparent; }, "transparent", "transparent",
          kMustMatch, "CD_TRANSPARENT"),
      recorded(
          {"--denoise", "[=fast|balanced|high]",
           "Denoise the image with Open Image Denoise (scripts/setup.sh installs it), guided by the albedo and "
           "normal AOVs; QUALITY fast, balanced (the default) or high; EXR outputs keep the unbiased image as "
           "noisy.R/G/B",
           "Denoise with Intel Open Image Denoise's `RT` filter ([below](#denoising)) at this quality (`--denoise` "
           "alone: `balanced`), guided by the albedo and normal AOVs (which it adds), each filtered first (`cleanAux`); "
           "interrupted renders too. PNG/JPEG outputs show the denoised image; EXR ones hold it as RGB and the "
           "unbiased estimate as `noisy.R/G/B`, which `merge` and `compare` read.",
           "",
           [](CLI::App* render, RenderArgs& a, const RenderSetting& s) {
             CLI::Option* o = render->add_flag(s.flags, a.denoise, s.help);  // bare: "true", taken as balanced
             o->transform([](std::string v) { return v == "true" ? std::string("balanced") : v; }, "", "");
             return o->option_text("[=QUALITY]");
           },
           [](const A& a, S*) {
             if (!a.denoise.empty()) parse_enum(kDenoiseQualityNames, "--denoise", a.denoise);
           }},
          [](const A& a, const S&) -> SettingValue { return a.denoise.empty() ? "off" : a.denoise; }, "denoise",
          "denoise", false),
      recorded(
          {"--generic", "",
           "Build the generic kernel with every scene feature compiled in, instead of the one specialized to "
           "the scene (to measure what specialization gains)",
           "Build the generic kernel, with every scene feature compiled in, instead of the one specialized to "
           "the scene ([architecture.md](architecture.md#kernel-specialization)).",
           "", flag(&A::generic)},
          [](const A& a, const S&) -> SettingValue { return a.generic; }, nullptr, "generic_kernel", false,
          "CD_FEATURE_*"),
      // Several devices and machines (README); --device takes a list
      recorded(
          {"--sample-offset", "K",
           "First sample index (default 0): renders indices [K, K+spp), a shard for `candela merge`; stored as "
           "candela:sample_offset",
           "First sample index (default 0): renders the sample indices [K, K + spp) of every pixel, a shard "
           "that `candela merge` combines with others "
           "([devices.md](devices.md#several-machines-shards-and-candela-merge)).",
           "0", option(&A::sample_offset, check(integer_in(0, kMaxIndex)))},
          [](const A& a, const S&) -> SettingValue { return count(a.sample_offset); }, "sample_offset", "sample_offset",
          false),
      {"--mpi", "",
       "Spread --spp over the ranks of an MPI job (mpirun -np N candela render ... --mpi): each rank renders a block "
       "of the sample indices, rank 0 merges and writes (needs -DCANDELA_MPI=ON)",
       "Run under `mpirun -np N`: each rank renders a block of the `--spp` sample indices, rank 0 merges the films "
       "and writes the outputs; with `--frames` the ranks split the frames instead. Needs a build with "
       "`-DCANDELA_MPI=ON` ([devices.md](devices.md#mpi)).",
       "", flag(&A::mpi)},
  };
}

// "`--filter box\|tent\|gaussian`", "`-o, --output FILE`", "`SCENE`"
std::string docs_name(const RenderSetting& s) {
  std::string name = s.flags[0] == '-' ? s.flags : "";
  for (size_t at = name.find(','); at != std::string::npos; at = name.find(',', at + 2)) name.replace(at, 1, ", ");
  std::string value;
  for (char c : s.value_name) value += c == '|' ? std::string("\\|") : std::string(1, c);
  return "`" + name + (name.empty() || value.empty() || value[0] == '[' ? "" : " ") + value + "`";
}

std::string options_markdown() {
  std::string out = "| option | meaning |\n|---|---|\n", names;
  for (const RenderSetting& s : render_settings()) {
    names += (names.empty() ? "" : ", ") + docs_name(s);
    if (s.doc.empty()) continue;
    out += "| " + names + " | " + s.doc + " |\n";
    names.clear();
  }
  return out;
}

std::string record_markdown() {
  std::string out = "| option | image metadata | `--stats` key | `merge` requires a match |\n|---|---|---|---|\n";
  auto code = [](const std::string& text) { return text.empty() ? text : "`" + text + "`"; };
  for (const RenderSetting& s : render_settings()) {
    if (!s.record) continue;
    std::string name = s.flags[0] == '-' ? s.flags.substr(s.flags.rfind(',') + 1) : s.value_name;
    out += "| " + code(name) + " | " + code(s.metadata ? "candela:" + std::string(s.metadata) : "") + " | " +
           code(s.stats ? s.stats : "") + " | " + (s.must_match ? "yes" : "") + " |\n";
  }
  return out;
}

nlohmann::json settings_json() {
  nlohmann::json options = nlohmann::json::array();
  for (const RenderSetting& s : render_settings()) {
    nlohmann::json o = {{"flags", s.flags},
                        {"value_name", s.value_name},
                        {"help", s.help},
                        {"doc", s.doc},
                        {"default", s.default_value},
                        {"recorded", bool(s.record)},
                        {"must_match", s.must_match},
                        {"kernel", s.kernel}};
    o["metadata"] = s.metadata ? nlohmann::json(s.metadata) : nlohmann::json();
    o["stats"] = s.stats ? nlohmann::json(s.stats) : nlohmann::json();
    options.push_back(o);
  }
  nlohmann::json results = nlohmann::json::array();
  for (const RecordKey& k : result_keys())
    results.push_back({{"key", k.key},
                       {"metadata", k.metadata},
                       {"stats", k.stats},
                       {"must_match", k.must_match},
                       {"always", k.always}});
  return {{"options", options}, {"results", results}, {"must_match", must_match_keys()}};
}

}  // namespace

const std::vector<RenderSetting>& render_settings() {
  static const std::vector<RenderSetting> table = make_render_settings();
  return table;
}

void add_render_settings(CLI::App* render, RenderArgs* args) {
  for (const RenderSetting& s : render_settings()) s.add(render, *args, s);
}

void apply_render_settings(const RenderArgs& args, RenderSettings* settings) {
  for (const RenderSetting& s : render_settings())
    if (s.apply) s.apply(args, settings);
}

std::string settings_markdown(const std::string& table) {
  if (table == "options") return options_markdown();
  if (table == "record") return record_markdown();
  throw Error("--markdown takes options or record, not '" + table + "'");
}

CLI::App* add_help_options_command(CLI::App* app, HelpOptionsArgs* args) {
  auto* cmd = app->add_subcommand("help-options", "The render options as docs/cli.md tables or JSON");
  cmd->group("");  // hidden: for the docs and their test
  auto* markdown = cmd->add_option("--markdown", args->markdown, "options|record: one of docs/cli.md's tables");
  cmd->add_flag("--json", args->json, "Every option and recorded key as JSON")->excludes(markdown);
  return cmd;
}

int run_help_options(const HelpOptionsArgs& args) {
  if (args.json)
    std::printf("%s\n", settings_json().dump(2).c_str());
  else
    std::printf("%s", settings_markdown(args.markdown.empty() ? "options" : args.markdown).c_str());
  return 0;
}

}  // namespace candela
