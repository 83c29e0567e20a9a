// `candela render`: its options, and the render from the scene file to the written images.
#include "app/render_command.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <memory>

#include "app/mpi_render.hpp"
#include "app/options.hpp"
#include "app/progress.hpp"
#include "app/render_devices.hpp"
#include "app/render_scene.hpp"
#include "app/report.hpp"
#include "compile/camera.hpp"
#include "compile/scene_compiler.hpp"
#include "render/image_stats.hpp"
#include "render/tonemap.hpp"
#include "scene/default_light.hpp"

namespace candela {
namespace {

std::atomic<bool> g_interrupted{false};

void on_sigint(int) {
  if (g_interrupted.exchange(true)) std::_Exit(130);  // second Ctrl-C: leave at once
}

// Speed against accuracy (README): --variance and --generic
void add_accuracy_render_options(CLI::App* render, RenderArgs* a) {
  render->add_option("--variance", a->variance,
                     "Also write the variance of each pixel's mean, M2 / (n (n - 1)) per channel, to this .exr "
                     "(infinite where a pixel has fewer than 2 samples)");
  render->add_flag("--generic", a->generic,
                   "Build the generic kernel with every scene feature compiled in, instead of the one specialized "
                   "to the scene (to measure what specialization gains)");
}

// Several devices and machines (README): --sample-offset and --mpi; --device takes a list
void add_distributed_render_options(CLI::App* render, RenderArgs* a) {
  render->add_option("--sample-offset", a->sample_offset,
                     "First sample index (default 0): renders indices [K, K+spp), a shard for `candela merge`; "
                     "stored as candela:sample_offset");
  render->add_flag("--mpi", a->mpi,
                   "Spread --spp over the ranks of an MPI job (mpirun -np N candela render ... --mpi): each rank "
                   "renders a block of the sample indices, rank 0 merges and writes (needs -DCANDELA_MPI=ON)");
}

// The scene's lighting: background, environment map, default light
void add_lighting_render_options(CLI::App* render, RenderArgs& a) {
  auto* background_opt =
      render->add_option("--background", a.background,
                         "Constant background radiance R,G,B (replaces the scene's background and environment map)");
  render->add_option("--env", a.env, "Equirectangular environment map (.hdr, .exr, .png, .jpg), replacing the scene's")
      ->excludes(background_opt);
  render->add_option("--env-strength", a.env_strength,
                     "Environment map strength, a radiance scale (default 1, or the scene's)");
  render->add_option(
      "--env-rotation", a.env_rotation,
      "Environment map rotation about +Y in degrees, counter-clockwise seen from above (default 0, or the scene's)");
  render->add_option("--default-light", a.default_light,
                     "The built-in studio environment: " + enum_names(kDefaultLightNames, true));
  render->add_flag_callback(
      "--no-default-light", [&a] { a.default_light = "off"; }, "Same as --default-light off");
  render->add_option("--light-units", a.light_units,
                     "KHR_lights_punctual intensities: " + enum_names(kLightUnitNames, true) +
                         "; default: the scene's extras candela.light_units, else photometric");
  render->add_option("--variant", a.variant,
                     "KHR_materials_variants: render the scene's material variant NAME (candela info lists them; "
                     "default: the default materials)");
}

// The camera, replacing or changing the scene's
void add_camera_render_options(CLI::App* render, RenderArgs& a) {
  render->add_option("--camera", a.camera,
                     "The scene's camera to render through, by index (candela info lists them; "
                     "default 0, the first)");
  render->add_option("--look-from", a.look_from, "Camera position X,Y,Z (overrides the scene camera)");
  render->add_option("--look-at", a.look_at, "Camera target X,Y,Z");
  render->add_option("--up", a.up, "Camera up vector X,Y,Z (default 0,1,0)");
  render->add_option("--fov", a.fov, "Vertical field of view in degrees, 0 < FOV < 180 (makes the camera perspective)");
  render->add_option(
      "--aperture", a.aperture,
      "Thin-lens aperture radius in scene units for depth of field (default 0: pinhole; perspective cameras)");
  render->add_option("--focus-distance", a.focus_distance,
                     "Distance of the sharp plane along the view axis (default: the --look-at point, else the scene "
                     "camera's extras, else the scene bounds' centre)");
}

// Samples, size, devices and the path tracer's settings
void add_sampling_render_options(CLI::App* render, RenderArgs& a) {
  auto* spp_opt = render->add_option("--spp", a.spp, "Samples per pixel (default 64)")->check(CLI::Range(1u, 1u << 24));
  render->add_option("--time", a.time, "Render for this many seconds instead of a sample count")
      ->check(CLI::PositiveNumber)
      ->excludes(spp_opt);
  render->add_option("--width", a.width, "Image width (default 512, or from --height and the camera aspect)")
      ->check(CLI::Range(1, 65536));
  render->add_option("--height", a.height, "Image height (default from the camera aspect ratio, else the width)")
      ->check(CLI::Range(1, 65536));
  render->add_option(
      "--device", a.device,
      "OpenCL device: index, P.D, cpu, gpu, or a name substring (pocl, rusticl, nvidia); default first GPU, else first "
      "CPU. A comma-separated list (pocl,rusticl) or `all` renders on several devices at once");
  render->add_option("--seed", a.seed, "Random seed (default 0)");
  render->add_option("--max-depth", a.max_depth, "Maximum number of bounces (default 16)")
      ->check(CLI::Range(0u, 100000u));
  render->add_option("--strategy", a.strategy,
                     enum_names(kStrategyNames, true) + "; default: the scene's extras candela.strategy, else auto");
  render->add_flag(
      "--no-energy-compensation", a.no_energy_compensation,
      "Leave out the multiple scattering of rough GGX lobes (on by default: rough metal keeps its albedo)");
}

void check_variance_path(const RenderArgs& a) {
  if (a.variance.empty()) return;
  std::string ext = lowercase(a.variance.size() >= 4 ? a.variance.substr(a.variance.size() - 4) : "");
  if (ext != ".exr")
    throw Error("--variance must name an .exr file (the variance is linear float data): " + a.variance);
}

void check_sample_offset(const RenderArgs& a, uint32_t spp) {
  if (spp > 0 && uint64_t(a.sample_offset) + spp > (uint64_t(1) << 32))
    throw Error("--sample-offset + --spp must not pass 2^32 sample indices");
}

// What can be checked before the scene loads: option names and output paths
RenderSettings check_render_args(const RenderArgs& a) {
  RenderSettings settings;
  if (!a.strategy.empty()) parse_enum(kStrategyNames, "--strategy", a.strategy);  // fails before loading
  settings.filter = parse_enum(kPixelFilterNames, "--filter", a.filter);
  settings.sampler = parse_enum(kSamplerNames, "--sampler", a.sampler);
  parse_tonemap(a.tonemap);  // a bad name fails before loading
  parse_enum(kDefaultLightNames, "--default-light", a.default_light);
  if (!a.light_units.empty()) parse_enum(kLightUnitNames, "--light-units", a.light_units);
  if (!std::isfinite(a.exposure)) throw Error("--exposure must be a finite number of stops");
  if (a.outputs.empty()) throw Error("no output file: pass -o OUT.exr or -o OUT.png");
  for (const auto& out : a.outputs) check_output_path(out);
  check_variance_path(a);
  return settings;
}

// The settings that need the loaded scene: its strategy and the camera's aspect ratio
void complete_settings(const RenderArgs& a, const Scene& scene, RenderSettings* settings) {
  settings->strategy = parse_enum(kStrategyNames, "--strategy", a.strategy);
  resolve_image_size(a, scene, &settings->width, &settings->height);
  settings->seed = a.seed;
  settings->max_depth = a.max_depth;
  settings->energy_compensation = !a.no_energy_compensation;
}

// The renderer of the scene through its camera, on the devices. Host memory: the loaded
// scene's arrays go once compiled, the compiled scene's as the devices take their copies
// (README, Performance: Memory). --generic: every kernel feature on (and the vertex arrays
// those features read).
Renderer make_renderer(const RenderArgs& a, Scene* scene, const RenderSettings& settings,
                       const std::vector<DeviceEntry>& devices) {
  auto compiled =
      std::make_shared<CompiledScene>(a.generic ? compile_scene(*scene, SceneFeatures::all()) : compile_scene(*scene));
  dev::Camera camera = compile_camera(*scene, settings.width, settings.height);
  *scene = Scene();
  return Renderer(devices, std::move(compiled), camera, settings, true);
}

// The render with its progress bar; Ctrl-C stops it between launches
RenderResult render_with_progress(Renderer& renderer, const RenderArgs& a, const RenderSettings& settings,
                                  uint32_t first_sample, uint32_t spp) {
  std::signal(SIGINT, on_sigint);
  ProgressBar bar(!a.quiet, double(settings.width) * settings.height);
  bar.show_device_shares(renderer.worker_count() > 1);
  RenderResult r = renderer.render(
      first_sample, spp, a.time, [&](const RenderProgress& p) { bar.update(p); }, [] { return g_interrupted.load(); });
  bar.finish();
  std::signal(SIGINT, SIG_DFL);
  return r;
}

// The images (and the variance image), each with the report as metadata
void write_outputs(const RenderArgs& a, const Film& film, const RenderReport& report) {
  std::map<std::string, std::string> meta = image_metadata(report);
  for (const auto& out : a.outputs) {
    write_image(out, film, meta, {a.exposure, parse_tonemap(a.tonemap)});
    std::printf("wrote %s\n", out.c_str());
  }
  if (a.variance.empty()) return;
  write_variance_image(a.variance, film, meta);
  std::printf("wrote %s\n", a.variance.c_str());
}

void print_result(const RenderReport& report, bool partial_pass) {
  std::printf("%u spp in %.2fs: %.3f Msamples/s on %s%s\n", report.spp, report.seconds,
              report.samples_per_second * 1e-6, report.device.c_str(), report.interrupted ? " (interrupted)" : "");
  print_device_shares(report.devices);
  if (partial_pass)
    std::fprintf(stderr, "note: stopped inside a pass; some pixels hold more than %u samples\n", report.spp);
  if (report.dropped_samples)
    std::fprintf(stderr, "warning: %llu non-finite samples were dropped\n", (unsigned long long)report.dropped_samples);
}

}  // namespace

CLI::App* add_render_command(CLI::App* app, RenderArgs* args) {
  RenderArgs& a = *args;
  auto* render = app->add_subcommand("render", "Render a glTF scene");
  render->add_option("scene", a.scene, "Scene file (.gltf or .glb)")->required();
  render
      ->add_option("-o,--output", a.outputs,
                   "Output image: .exr (linear), .png or .jpg (tone-mapped sRGB, --tonemap); repeatable")
      ->required();
  add_sampling_render_options(render, a);
  add_lighting_render_options(render, a);
  render->add_option("--stats", a.stats, "Write render statistics as JSON to this file");
  render->add_option("--exposure", a.exposure, "Exposure of PNG/JPEG outputs in stops (default 0); EXR stays linear");
  render->add_option("--tonemap", a.tonemap,
                     "Display transform of PNG/JPEG outputs: " + enum_names(kTonemapNames, true));
  add_camera_render_options(render, a);
  render->add_option("--filter", a.filter, "Pixel filter: " + enum_names(kPixelFilterNames, true));
  render->add_option("--sampler", a.sampler, "Random numbers: " + enum_names(kSamplerNames, true));
  render->add_flag("-q,--quiet", a.quiet, "No progress or scene summary");
  add_accuracy_render_options(render, &a);
  add_distributed_render_options(render, &a);
  return render;
}

int run_render(RenderArgs a) {
  RenderSettings settings = check_render_args(a);
  Scene scene = load_render_scene(&a);
  complete_settings(a, scene, &settings);
  uint32_t spp = a.time > 0 ? 0 : (a.spp ? a.spp : 64);
  check_sample_offset(a, spp);
  uint32_t first_sample = mpi_shard(&a, &spp);
  std::vector<DeviceEntry> devices = select_render_devices(a.device);
  if (!a.quiet && devices.size() == 1) std::fprintf(stderr, "device: %s\n", joined_descriptions(devices).c_str());
  Renderer renderer = make_renderer(a, &scene, settings, devices);
  if (!a.quiet) print_render_summary(renderer, devices);
  RenderResult r = render_with_progress(renderer, a, settings, first_sample, spp);
  if (!mpi_combine(&r)) return 0;
  if (r.spp == 0) throw Error("interrupted before any sample was rendered; nothing written");
  RenderReport report = make_render_report(a, settings, renderer, r, devices);
  write_outputs(a, r.film, report);
  print_result(report, r.partial_pass);
  if (!a.stats.empty()) write_stats(report, a.stats);
  return r.interrupted ? 130 : 0;
}

int run_render_command(const RenderArgs& args) {
  return args.mpi ? run_render_under_mpi(args, run_render) : run_render(args);
}

}  // namespace candela
