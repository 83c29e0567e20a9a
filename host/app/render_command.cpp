// `candela render`: its options, and the render from the scene file to the written images.
#include "app/render_command.hpp"

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>

#include "app/mpi_render.hpp"
#include "app/options.hpp"
#include "app/progress.hpp"
#include "app/render_devices.hpp"
#include "app/render_scene.hpp"
#include "app/report.hpp"
#include "app/sequence.hpp"
#include "app/settings.hpp"
#include "base/atomic_file.hpp"
#include "base/file_access.hpp"
#include "compile/camera.hpp"
#include "compile/light_tree.hpp"
#include "compile/scene_compiler.hpp"
#include "gltf/gltf_loader.hpp"
#include "render/aov.hpp"
#include "render/denoise.hpp"
#include "render/image_stats.hpp"
#include "render/tonemap.hpp"
#include "scene/default_light.hpp"

namespace candela {
namespace {

// SIGINT and SIGTERM. Before the render starts (loading, kernel build) nothing is lost
// by leaving at once; during the render the first one stops it between launches and its
// samples are written; while writing, every one waits for the write. Exit status 128 +
// the first signal's number.
enum Phase : int { kPreparing, kRendering, kWriting };
std::atomic<int> g_phase{kPreparing};
std::atomic<int> g_signal{0};

void on_signal(int sig) {
  int none = 0;
  g_signal.compare_exchange_strong(none, sig);
  if (g_phase.load() == kPreparing) {
    const char msg[] = "candela: interrupted before rendering; nothing written\n";
    ssize_t ignored = write(2, msg, sizeof msg - 1);
    (void)ignored;
    std::_Exit(128 + sig);
  }
}

// Tests send each signal at each phase through CANDELA_RAISE_AT=PHASE:SIGNAL (once), PHASE
// one of loading, kernel-build, first-pass (inside it), later-pass (after a whole range),
// mid-pass (inside a later range), writing; SIGNAL INT or TERM
void raise_if_asked(const char* phase) {
  static bool raised = false;
  const char* at = std::getenv("CANDELA_RAISE_AT");
  if (!at || raised) return;
  std::string text = at;
  size_t colon = text.find(':');
  if (colon == std::string::npos || text.substr(0, colon) != phase) return;
  std::string name = text.substr(colon + 1);
  raised = true;
  if (name == "INT") std::raise(SIGINT);
  if (name == "TERM") std::raise(SIGTERM);
}

void catch_signals() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

void enter_phase(Phase phase) { g_phase.store(phase); }
bool signalled() { return g_signal.load() != 0; }

void check_variance_path(const RenderArgs& a) {
  if (a.variance.empty()) return;
  std::string ext = lowercase(a.variance.size() >= 4 ? a.variance.substr(a.variance.size() - 4) : "");
  if (ext != ".exr")
    throw Error("--variance must name an .exr file (the variance is linear float data): " + a.variance);
  check_writable_path(a.variance);
}

void check_sample_offset(const RenderArgs& a, uint32_t spp) {
  if (spp > 0 && uint64_t(a.sample_offset) + spp > (uint64_t(1) << 32))
    throw Error("--sample-offset + --spp must not pass 2^32 sample indices");
}

// No two outputs, and no output and input, name the same file
void check_distinct_paths(const RenderArgs& a) {
  namespace fs = std::filesystem;
  auto key = [](const std::string& path) {
    std::error_code ec;
    fs::path p = fs::weakly_canonical(fs::absolute(path), ec);
    return ec ? fs::absolute(path).lexically_normal().string() : p.string();
  };
  std::vector<std::pair<std::string, std::string>> outputs;  // (key, option and path)
  for (const auto& out : a.outputs) outputs.push_back({key(parse_output(out).path), "-o " + out});
  if (!a.variance.empty()) outputs.push_back({key(a.variance), "--variance " + a.variance});
  if (!a.stats.empty()) outputs.push_back({key(a.stats), "--stats " + a.stats});
  for (size_t i = 0; i < outputs.size(); ++i)
    for (size_t j = i + 1; j < outputs.size(); ++j)
      if (outputs[i].first == outputs[j].first)
        throw Error(outputs[i].second + " and " + outputs[j].second + " name the same file");
  std::vector<std::pair<std::string, std::string>> inputs = {{a.scene, "the scene"}};
  if (!a.env.empty()) inputs.push_back({a.env, "--env"});
  for (const auto& [path, what] : inputs)
    for (const auto& out : outputs)
      if (out.first == key(path)) throw Error(out.second + " would overwrite " + what + " (" + path + ")");
}

void check_stats_path(const RenderArgs& a) {
  if (!a.stats.empty()) check_writable_path(a.stats);
}

// --frames: every file written takes the frame number from a run of '#'
void check_sequence_args(const RenderArgs& a) {
  if (a.frames.empty()) {
    if (a.skip_existing) throw Error("--skip-existing applies to a sequence (--frames)");
    return;
  }
  parse_frames(a.frames);
  std::vector<std::pair<std::string, std::string>> files;
  for (const auto& out : a.outputs) files.push_back({"-o", out});
  if (!a.variance.empty()) files.push_back({"--variance", a.variance});
  if (!a.stats.empty()) files.push_back({"--stats", a.stats});
  for (const auto& [option, path] : files)
    if (!has_frame_pattern(path))
      throw Error("--frames writes one file a frame: " + option + " " + path +
                  " needs a run of # in its name for the frame number (fox_####.png)");
}

}  // namespace

RenderSettings prepare_render_settings(const RenderArgs& a) {
  RenderSettings settings = a.settings;
  if (!a.quiet) {
    settings.before_kernel_compile = [](const std::string& device) {
      std::fprintf(stderr,
                   "compiling the render kernel for %s (not in the kernel cache yet: seconds on PoCL, up to minutes "
                   "on rusticl)\n",
                   device.c_str());
    };
    settings.before_tables_compute = [](const std::string& device) {
      std::fprintf(stderr,
                   "computing the albedo tables for %s (once per device, then cached: seconds on PoCL, minutes on "
                   "rusticl)\n",
                   device.c_str());
    };
  }
  apply_render_settings(a, &settings);  // names of enums, and what they set
  check_camera_options(a);
  return settings;
}

namespace {

// What can be checked before the scene loads: option names and output paths
RenderSettings check_render_args(const RenderArgs& a) {
  RenderSettings settings = prepare_render_settings(a);
  if (a.outputs.empty()) throw Error("no output file: pass -o OUT.exr or -o OUT.png");
  for (const auto& out : a.outputs) check_output_path(parse_output(out).path);
  check_variance_path(a);
  check_stats_path(a);
  check_distinct_paths(a);
  check_sequence_args(a);
  return settings;
}

}  // namespace

void complete_settings(const RenderArgs& a, const Scene& scene, RenderSettings* settings) {
  settings->strategy = parse_enum(kStrategyNames, "--strategy", a.strategy);
  resolve_image_size(a, scene, &settings->width, &settings->height);
  // CANDELA_LAUNCH_SECONDS: the target duration of one launch (default 0.2 s)
  if (const char* text = std::getenv("CANDELA_LAUNCH_SECONDS")) {
    char* end = nullptr;
    double v = std::strtod(text, &end);
    if (end == text || *end || !(v >= 1e-4 && v <= 60.0))
      throw Error(std::string("CANDELA_LAUNCH_SECONDS must be seconds from 0.0001 to 60, not '") + text + "'");
    settings->launch_seconds = v;
  }
}

namespace {

// Light selection by power alone: --light-selection power, or motion blur (the light tree's
// bounds hold one pose of the moving emitters)
bool power_selection(const RenderArgs& a) { return a.light_selection == "power" || !a.shutter.empty(); }

// The kernel features the renderer builds with: the compiled scene's, without the light
// tree when --light-selection power leaves it out (the generic kernel keeps every feature)
SceneFeatures kernel_features(const CompiledScene& c, const RenderArgs& a) {
  SceneFeatures features = c.features;
  if (!a.generic) features.light_tree = !c.buffers.light_tree.empty() && !power_selection(a);
  return features;
}

}  // namespace

Renderer make_renderer(const RenderArgs& a, Scene* scene, const RenderSettings& settings,
                       const std::vector<DeviceEntry>& devices, KernelPrebuild& prebuild) {
  // The kernels build while the BVH does: a cold build (seconds) overlaps the scene's
  // compile, and the renderers below find the programs in the kernel cache
  auto features_known = [&](const CompiledScene& c) {
    for (const DeviceEntry& d : devices) prebuild.start(d, kernel_features(c, a), settings);
  };
  auto compiled = std::make_shared<CompiledScene>(
      a.generic ? compile_scene(*scene, SceneFeatures::all(), features_known) : compile_scene(*scene, features_known));
  compiled->features = kernel_features(*compiled, a);
  if (power_selection(a)) drop_light_tree(&compiled->buffers);
  dev::Camera camera = compile_camera(*scene, settings.width, settings.height);
  if (scene->motion_steps > 0) {
    compiled->buffers.camera_steps.clear();
    for (const CameraDesc& c : scene->camera_steps)
      compiled->buffers.camera_steps.push_back(make_device_camera(c, settings.width, settings.height));
  }
  *scene = Scene();
  prebuild.wait();
  Renderer renderer(devices, std::move(compiled), camera, settings, true);
  for (size_t i = 0; i < prebuild.size() && i < renderer.worker_count(); ++i)
    renderer.worker(i).count_prebuild(prebuild.result(i));
  return renderer;
}

namespace {

// The render with its progress bar; Ctrl-C stops it between launches
RenderResult render_with_progress(Renderer& renderer, const RenderArgs& a, const RenderSettings& settings,
                                  uint32_t first_sample, uint32_t spp) {
  ProgressBar bar(!a.quiet, double(settings.width) * settings.height);
  bar.show_device_shares(renderer.worker_count() > 1);
  enter_phase(kRendering);
  RenderResult r = renderer.render(
      first_sample, spp, a.time,
      [&](const RenderProgress& p) {
        bar.update(p);
        if (p.spp_done == 0 && p.spp_partial > 0) raise_if_asked("first-pass");
        if (p.spp_done > 0 && p.spp_partial == 0) raise_if_asked("later-pass");
        if (p.spp_done > 0 && p.spp_partial > 0) raise_if_asked("mid-pass");
      },
      [] { return signalled(); });
  bar.finish();
  return r;
}

// The automatic exposure (scene/default_light.hpp, image_exposure) metered from the image,
// said in one line: the exposure the PNG/JPEG outputs get
void meter_exposure(const Film& film, RenderArgs* a) {
  if (a->exposure || !a->auto_exposure_share) return;
  std::vector<float> lum(film.pixels());
  for (size_t i = 0; i < film.pixels(); ++i) {
    glm::vec3 v = film.pixel(i);
    lum[i] = dev::luminance_rgb(v.x, v.y, v.z);
  }
  a->exposure = image_exposure(lum, film.width, film.height);
  if (a->exposure)
    std::fprintf(stderr,
                 "note: exposing PNG/JPEG outputs at %.1f stops, metered from the image (log-average luminance to "
                 "middle grey): the scene's own lights give %.3g times the studio's light on its surfaces "
                 "(--exposure 0 keeps them as they are; EXR stays linear)\n",
                 double(*a->exposure), *a->auto_exposure_share);
}

// The images (and the variance image), each with the report as metadata; each output is
// written on its own, so one that fails (reported) does not cost the others. False when
// any failed.
bool write_outputs(const RenderArgs& a, const Film& film, const RenderReport& report) {
  std::map<std::string, std::string> meta = image_metadata(report);
  bool ok = true;
  auto attempt = [&](const std::string& path, const std::function<void()>& write) {
    try {
      write();
      std::printf("wrote %s\n", path.c_str());
    } catch (const Error& e) {
      std::fprintf(stderr, "candela: error: %s\n", e.what());
      ok = false;
    }
  };
  ImageLayers layers;
  layers.aovs = requested_aovs(a);
  layers.transparent = a.transparent;
  for (const auto& out : a.outputs) {
    OutputSpec o = parse_output(out);
    ImageLayers these = layers;
    these.single = o.aov;
    attempt(o.path, [&] {
      write_image(o.path, film, meta, {a.exposure.value_or(0.0f), parse_tonemap(a.tonemap)}, these);
    });
  }
  if (!a.variance.empty()) attempt(a.variance, [&] { write_variance_image(a.variance, film, meta); });
  return ok;
}

// The film's denoised RGB (render/denoise.hpp), on OIDN's choice of device when candela
// renders on a GPU, else on the CPU; its time on stderr. False (reported) when OIDN fails:
// the outputs are then written undenoised, so the render is not lost.
bool denoise(const RenderArgs& a, const std::vector<DeviceEntry>& devices, Film* film) {
  bool gpu = std::any_of(devices.begin(), devices.end(), [](const DeviceEntry& d) { return d.type == "gpu"; });
  try {
    DenoiseResult d = denoise_film(*film, parse_enum(kDenoiseQualityNames, "--denoise", a.denoise), gpu);
    film->denoised = std::move(d.rgb);
    if (!a.quiet)
      std::fprintf(stderr, "denoised in %.2fs (Open Image Denoise, %s quality, %s)\n", d.seconds, a.denoise.c_str(),
                   d.device.c_str());
    return true;
  } catch (const Error& e) {
    std::fprintf(stderr, "candela: error: %s; the outputs are written undenoised\n", e.what());
    return false;
  }
}

bool write_stats_reporting(const RenderReport& report, const std::string& path) {
  try {
    write_stats(report, path);
    return true;
  } catch (const Error& e) {
    std::fprintf(stderr, "candela: error: %s\n", e.what());
    return false;
  }
}

bool any_samples(const Film& film) {
  for (size_t p = 0; p < film.pixels(); ++p)
    if (film.samples(p) > 0) return true;
  return false;
}

// 0, or 128 + the signal that stopped the render (130 SIGINT, 143 SIGTERM)
int exit_status(const RenderResult& r) {
  if (int sig = g_signal.load()) return 128 + sig;
  return r.interrupted ? 130 : 0;
}

void print_result(const RenderReport& report, bool partial_pass, const Film& film) {
  std::printf("%u spp in %.2fs: %.3f Msamples/s on %s%s\n", report.spp, report.seconds,
              report.samples_per_second * 1e-6, report.device.c_str(), report.interrupted ? " (interrupted)" : "");
  print_device_shares(report.devices);
  if (partial_pass && report.spp == 0) {
    size_t with = 0;
    for (size_t p = 0; p < film.pixels(); ++p) with += film.samples(p) > 0;
    std::fprintf(stderr,
                 "note: stopped inside the first pass: %.1f %% of the pixels have samples, the others are black\n",
                 100.0 * double(with) / double(std::max<size_t>(film.pixels(), 1)));
  } else if (partial_pass) {
    std::fprintf(stderr, "note: stopped inside a pass; some pixels hold more than %u samples\n", report.spp);
  }
  if (report.dropped_samples)
    std::fprintf(stderr, "warning: %llu non-finite samples were dropped\n", (unsigned long long)report.dropped_samples);
}

// Adaptive sampling: how many samples the pixels got
void print_adaptive(const Film& film) {
  double total = 0.0, most = 0.0, fewest = film.pixels() ? 1e30 : 0.0;
  for (size_t p = 0; p < film.pixels(); ++p) {
    total += film.samples_taken(p);
    most = std::max<double>(most, film.samples_taken(p));
    fewest = std::min<double>(fewest, film.samples_taken(p));
  }
  std::printf("adaptive: %.1f samples per pixel on average, %.0f to %.0f\n",
              total / double(std::max<size_t>(film.pixels(), 1)), fewest, most);
}

}  // namespace

uint32_t requested_aovs(const RenderArgs& a) {
  uint32_t set = a.aov.empty() ? 0 : parse_aov_list(a.aov);
  for (const auto& out : a.outputs) set |= parse_output(out).aov;
  if (!a.denoise.empty()) set |= aov_bit(Aov::Albedo) | aov_bit(Aov::Normal);
  return set;
}

CLI::App* add_render_command(CLI::App* app, RenderArgs* args) {
  auto* render = app->add_subcommand("render", "Render a glTF scene");
  add_render_settings(render, args);
  return render;
}

namespace {

// The render of a loaded scene, its outputs written: the exit status
int render_scene(RenderArgs& a, RenderSettings settings, Scene& scene, const std::vector<DeviceEntry>& devices,
                 KernelPrebuild& prebuild) {
  complete_settings(a, scene, &settings);
  uint32_t spp = a.time > 0 ? 0 : (a.spp ? a.spp : 64);
  check_sample_offset(a, spp);
  uint32_t first_sample = mpi_shard(&a, &spp);
  if (!a.quiet && !a.repeat && devices.size() == 1)
    std::fprintf(stderr, "device: %s\n", joined_descriptions(devices).c_str());
  std::string camera = camera_fingerprint(scene, settings.width, settings.height);
  dev::Camera view = compile_camera(scene, settings.width, settings.height);
  std::string lighting = lighting_fingerprint(scene);
  raise_if_asked("kernel-build");
  Renderer renderer = make_renderer(a, &scene, settings, devices, prebuild);
  if (!a.quiet && !a.repeat) print_render_summary(renderer, devices);
  RenderResult r = render_with_progress(renderer, a, settings, first_sample, spp);
  enter_phase(kWriting);
  if (!mpi_combine(&r)) return exit_status(r);
  if (r.spp == 0 && !any_samples(r.film)) throw Error("interrupted before any sample was rendered; nothing written");
  RenderReport report = make_render_report(a, settings, renderer, r, devices);
  report.camera = camera;
  report.view = view;
  report.has_view = true;
  report.lighting = lighting;
  raise_if_asked("writing");
  meter_exposure(r.film, &a);
  if (a.share_exposure) a.exposure = mpi_sequence_exposure(a.frame_position, a.exposure);
  bool denoised = a.denoise.empty() || denoise(a, devices, &r.film);
  bool all_written = write_outputs(a, r.film, report) && denoised;
  print_result(report, r.partial_pass, r.film);
  if (settings.noise_threshold > 0.0 && !a.quiet) print_adaptive(r.film);
  if (!a.stats.empty()) all_written = write_stats_reporting(report, a.stats) && all_written;
  if (!all_written) return 1;
  return exit_status(r);
}

// The scene of a frame at a->anim_time; with motion blur posed at the shutter's middle (the
// poses across it are added once its camera is settled: add_motion_poses)
Scene load_frame_scene(RenderArgs* a, const GltfDocument& document) {
  if (a->shutter.empty()) return load_render_scene(a, &document);
  double frame_time = *a->anim_time;
  a->anim_time = shutter_middle(*a, frame_time);
  Scene scene = load_render_scene(a, &document);
  a->anim_time = frame_time;
  return scene;
}

// --frames: the document read once; each frame posed, compiled and rendered into the outputs
// its number names. The first frame's metered exposure holds for the others (no flicker).
int render_sequence(const RenderArgs& args, const RenderSettings& settings, const std::vector<DeviceEntry>& devices,
                    KernelPrebuild& first_prebuild) {
  GltfDocument document(args.scene, render_load_options(args));
  first_prebuild.loaded();
  std::vector<long> frames = parse_frames(args.frames);
  auto start = std::chrono::steady_clock::now();
  size_t rendered = 0, skipped = 0;
  std::optional<float> exposure = args.exposure;
  std::optional<CameraDesc> framed;
  mpi_split_by_frames();
  for (size_t i = 0; i < frames.size(); ++i) {
    if (!mpi_renders_frame(i)) continue;  // another rank's
    RenderArgs a = args;
    a.anim_time = double(frames[i]) / args.fps;
    for (std::string& out : a.outputs) out = frame_path(out, frames[i]);
    if (!a.variance.empty()) a.variance = frame_path(a.variance, frames[i]);
    if (!a.stats.empty()) a.stats = frame_path(a.stats, frames[i]);
    uint32_t spp = a.time > 0 ? 0 : (a.spp ? a.spp : 64);
    bool done = a.skip_existing;
    for (const std::string& out : a.outputs) done = done && frame_written(out, spp);
    if (done) {
      ++skipped;
      if (!a.quiet)
        std::fprintf(stderr, "frame %ld (%zu of %zu): written already, skipped\n", frames[i], i + 1, frames.size());
      continue;
    }
    if (!a.quiet)
      std::fprintf(stderr, "frame %ld (%zu of %zu) at %.6g s\n", frames[i], i + 1, frames.size(), *a.anim_time);
    a.repeat = rendered > 0;
    a.exposure = exposure;
    enter_phase(kPreparing);
    Scene scene = load_frame_scene(&a, document);
    // A file without a camera: the first frame's camera (framed, or placed by the options)
    // holds for all, not framing each pose anew
    if (scene.cameras.empty() && framed) {
      scene.camera = framed;
    } else if (scene.cameras.empty()) {
      // (a rank of an MPI job frames the sequence's first frame too, whichever it renders)
      RenderArgs first = a;
      first.anim_time = double(frames[0]) / args.fps;
      first.repeat = true;
      Scene posed = i == 0 ? Scene() : load_frame_scene(&first, document);
      const Scene& framing = i == 0 ? scene : posed;
      int w = 0, h = 0;
      resolve_image_size(a, framing, &w, &h);
      framed = resolve_camera(framing, float(w) / float(h));
      if (i != 0) scene.camera = framed;
    }
    if (!a.shutter.empty()) add_motion_poses(a, document, &scene);
    a.share_exposure = rendered == 0 && mpi_ranks() > 0;
    a.frame_position = i;
    // Frame f renders with seed S + f (S from --seed): frames decorrelated, runs repeatable
    RenderSettings frame_settings = settings;
    frame_settings.seed = uint32_t(uint64_t(settings.seed) + uint64_t(frames[i]));
    KernelPrebuild later_prebuild;
    int status = render_scene(a, frame_settings, scene, devices, rendered == 0 ? first_prebuild : later_prebuild);
    ++rendered;
    if (a.exposure) exposure = a.exposure;
    if (status != 0) {
      if (!a.quiet)
        std::fprintf(stderr, "stopped at frame %ld: %zu of %zu frames rendered\n", frames[i], rendered, frames.size());
      return status;
    }
  }
  if (rendered == 0 && mpi_ranks() > 0) mpi_sequence_exposure(std::nullopt, std::nullopt);  // a rank without frames
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!args.quiet)
    std::fprintf(stderr, "%zu frame%s rendered (%zu skipped, written already) in %.2f s\n", rendered,
                 rendered == 1 ? "" : "s", skipped, seconds);
  return 0;
}

}  // namespace

int run_render(RenderArgs a) {
  catch_signals();
  RenderSettings settings = check_render_args(a);
  if (!a.denoise.empty()) load_denoiser();    // a missing library is named before the render
  check_regular_file(a.scene, "scene file");  // a missing scene is named before any device
  std::vector<DeviceEntry> devices = select_render_devices(a.device);
  // The tables every scene binds are computed (cold cache) while a long load goes on
  KernelPrebuild prebuild;
  for (const DeviceEntry& d : devices) prebuild.start_tables(d, settings);
  raise_if_asked("loading");
  if (!a.frames.empty()) return render_sequence(a, settings, devices, prebuild);
  if (!a.shutter.empty()) {  // motion blur: the document posed across the shutter
    GltfDocument document(a.scene, render_load_options(a));
    prebuild.loaded();
    Scene scene = load_frame_scene(&a, document);
    add_motion_poses(a, document, &scene);
    return render_scene(a, settings, scene, devices, prebuild);
  }
  Scene scene = load_render_scene(&a);
  prebuild.loaded();
  return render_scene(a, settings, scene, devices, prebuild);
}

int run_render_command(const RenderArgs& args) {
  return args.mpi ? run_render_under_mpi(args, run_render) : run_render(args);
}

}  // namespace candela
