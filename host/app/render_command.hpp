// `candela render SCENE -o OUT ...`: the values of its options (settings.hpp defines each
// option) and the render they ask for.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "render/renderer.hpp"

namespace candela {

struct RenderArgs {
  std::string scene;
  std::vector<std::string> outputs;
  uint32_t spp = 0;
  double time = 0.0;
  int width = 0, height = 0;
  std::string device;
  std::string strategy;                  // empty: the scene's (extras candela.strategy), else auto
  std::string light_selection = "tree";  // --light-selection tree|power
  bool no_energy_compensation = false;
  std::string background;
  std::string env;
  std::optional<float> env_strength, env_rotation;
  std::string default_light = "auto";  // --default-light auto|on|off (--no-default-light: off)
  std::string light_units;             // --light-units photometric|radiometric; empty: the scene's
  std::string variant;                 // --variant NAME: a KHR_materials_variants variant; empty: the default
  std::string animation;               // --animation N|NAME: the animation posed; empty: all of them
  std::optional<double> anim_time;     // --anim-time SECONDS: the moment posed; unset: the rest pose
  std::string frames;                  // --frames A:B[:STEP]: a sequence, frame f at f / fps seconds
  double fps = 24.0;                   // --fps R
  bool skip_existing = false;          // --skip-existing: frames whose outputs all exist are not rendered
  std::string shutter;                 // --shutter OPEN:CLOSE: motion blur over that span of frames; empty: none
  int shutter_steps = 4;               // --shutter-steps K: poses across the shutter less one
  bool repeat = false;                 // a later frame of a sequence: the scene's notes were said for the first
  bool share_exposure = false;         // a rank's first frame of a sequence under --mpi: the ranks agree on
  size_t frame_position = 0;           // the exposure of the sequence's earliest (mpi_sequence_exposure)
  std::string stats;
  std::optional<float> exposure;  // --exposure EV; unset: 0, or the automatic exposure (render_scene.cpp)
  // Set where the automatic exposure applies (the scene's own lights' share of the studio's
  // light): PNG/JPEG outputs are exposed from the rendered image (render_command.cpp)
  std::optional<double> auto_exposure_share;
  std::string tonemap = "neutral";
  std::optional<int> camera;  // --camera N: the scene's camera N (default its first)
  std::string look_from, look_at, up;
  std::optional<float> fov;  // degrees
  std::optional<float> aperture, focus_distance;
  bool quiet = false;
  std::string variance;              // --variance: variance-of-the-mean image (render/image_stats.hpp)
  std::string aov;                   // --aov LIST (render/aov.hpp); outputs FILE.png:NAME add theirs
  bool transparent = false;          // --transparent: alpha 0 where the camera sees the environment
  std::string denoise;               // --denoise[=QUALITY] (render/denoise.hpp); empty: off
  bool generic = false;              // --generic: the kernel with every scene feature compiled in
  uint32_t sample_offset = 0;        // --sample-offset: first sample index (shards, candela merge)
  bool mpi = false;                  // --mpi: spread the samples over the ranks of an MPI job
  bool allow_outside_paths = false;  // --allow-outside-paths: scene files outside its folder
  // The renderer's settings that options give as they are (--seed, --max-depth); the
  // others follow from the options above and `names` (check_render_args, complete_settings)
  RenderSettings settings;
  // The names given to the options of enum settings, by flag ("--filter": "box"); each
  // option's apply sets its setting from its name (settings.cpp: enum_setting)
  std::map<std::string, std::string> names;
};

CLI::App* add_render_command(CLI::App* app, RenderArgs* args);

// The steps of a render that `candela view` shares (view.hpp):
// the settings the options give, checked as far as they can be before the scene loads
// (without the outputs' checks), with the kernel-build notes on stderr unless --quiet
RenderSettings prepare_render_settings(const RenderArgs& args);
// The settings that need the loaded scene: its strategy and the camera's aspect ratio
struct Scene;
void complete_settings(const RenderArgs& args, const Scene& scene, RenderSettings* settings);
// The renderer of the scene through its camera, on the devices. Host memory: the loaded
// scene's arrays go once compiled (`scene` is left empty), the compiled scene's as the
// devices take their copies (README, Performance: Memory). --generic: every kernel feature
// on (and the vertex arrays those features read).
Renderer make_renderer(const RenderArgs& args, Scene* scene, const RenderSettings& settings,
                       const std::vector<DeviceEntry>& devices, KernelPrebuild& prebuild);

// The AOVs a render computes: --aov's, those that outputs FILE.png:NAME name (render/aov.hpp),
// and with --denoise its guides, albedo and normal
uint32_t requested_aovs(const RenderArgs& args);

// Renders, writes the outputs and returns the exit code (130: interrupted)
int run_render(RenderArgs args);

// run_render, under an MPI session with --mpi (app/mpi_render.hpp)
int run_render_command(const RenderArgs& args);

}  // namespace candela
