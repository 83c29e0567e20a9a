// candela command line: `candela devices`, `candela render SCENE -o OUT ...`.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <sys/resource.h>
#include <unistd.h>

#include "device/device.hpp"
#include "scene/environment.hpp"
#include "base/error.hpp"
#include "gltf/gltf_loader.hpp"
#include "device/kernel_sources.hpp"
#include "render/renderer.hpp"
#include "compile/bvh_builder.hpp"
#include "app/compare.hpp"
#include "render/image_stats.hpp"
#include "app/merge.hpp"
#include "app/mpi_render.hpp"

namespace {

using namespace candela;

std::atomic<bool> g_interrupted{false};

void on_sigint(int) {
  if (g_interrupted.exchange(true)) std::_Exit(130);  // second Ctrl-C: leave at once
}

struct RenderArgs {
  std::string scene;
  std::vector<std::string> outputs;
  uint32_t spp = 0;
  double time = 0.0;
  int width = 0, height = 0;
  std::string device;
  uint32_t seed = 0;
  uint32_t max_depth = 16;
  std::string strategy;  // empty: the scene's (extras candela.strategy), else nee
  bool no_energy_compensation = false;
  std::string background;
  std::string env;
  std::optional<float> env_strength, env_rotation;
  bool no_default_light = false;
  std::string stats;
  float exposure = 0.0f;
  std::string tonemap = "neutral";
  std::string look_from, look_at, up;
  std::optional<float> fov;  // degrees
  std::optional<float> aperture, focus_distance;
  std::string filter = "box";
  std::string sampler = "sobol";
  bool quiet = false;
  std::string variance;  // --variance: variance-of-the-mean image (host/image_stats.hpp)
  bool generic = false;  // --generic: the kernel with every scene feature compiled in
  uint32_t sample_offset = 0;  // --sample-offset: first sample index (shards, candela merge)
  bool mpi = false;  // --mpi: spread the samples over the ranks of an MPI job
};

glm::vec3 parse_vec3(const std::string& text, const std::string& option) {
  std::stringstream ss(text);
  glm::vec3 v;
  char comma1 = 0, comma2 = 0;
  if (!(ss >> v.x >> comma1 >> v.y >> comma2 >> v.z) || comma1 != ',' || comma2 != ',' ||
      !(ss >> std::ws).eof() || !std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
    throw Error(option + " expects three comma-separated numbers, e.g. 1,0.5,0; got '" + text + "'");
  return v;
}

std::string format_duration(double s) {
  char buf[32];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.1fs", s);
  else
    std::snprintf(buf, sizeof buf, "%dm%02ds", int(s) / 60, int(s) % 60);
  return buf;
}

// "  devices 0: 52% 1: 48%": each worker's share of the samples so far
std::string format_device_shares(const RenderProgress& p) {
  double total = 0.0;
  for (double v : p.worker_spp) total += v;
  std::string s = "  devices";
  char buf[32];
  for (size_t i = 0; i < p.worker_spp.size(); ++i) {
    std::snprintf(buf, sizeof buf, " %zu: %.0f%%", i, total > 0 ? 100.0 * p.worker_spp[i] / total : 0.0);
    s += buf;
  }
  return s;
}

// A bar redrawn in place on a terminal; elsewhere (logs, CI) a line every 10 seconds
class ProgressBar {
 public:
  ProgressBar(bool enabled, double pixels)
      : enabled_(enabled), terminal_(isatty(STDERR_FILENO)), pixels_(pixels) {}
  // With several devices, each one's share of the samples follows the line
  void show_device_shares(bool on) { shares_ = on; }
  void update(const RenderProgress& p) {
    if (!enabled_) return;
    if (!terminal_) {
      if (p.seconds < next_line_) return;
      next_line_ = p.seconds + 10.0;
    }
    double spp = p.spp_done + p.spp_partial;
    double frac = p.spp_target ? spp / p.spp_target : std::min(1.0, p.seconds / p.time_limit);
    double rate = p.seconds > 0 ? spp * pixels_ / p.seconds : 0.0;
    double eta = frac > 0 ? p.seconds * (1.0 - frac) / frac : 0.0;
    int width = 30, filled = int(frac * width + 0.5);
    std::string bar = std::string(filled, '#') + std::string(width - filled, '-');
    std::string shares = shares_ ? format_device_shares(p) : "";
    std::fprintf(stderr, terminal_ ? "\r[%s] %u%s spp  %.2f Msamples/s  ETA %s%s   " : "[%s] %u%s spp  %.2f Msamples/s  ETA %s%s\n", bar.c_str(), p.spp_done,
                 p.spp_target ? ("/" + std::to_string(p.spp_target)).c_str() : "", rate * 1e-6,
                 format_duration(eta).c_str(), shares.c_str());
    std::fflush(stderr);
    drawn_ = true;
  }
  void finish() {
    if (drawn_ && terminal_) std::fprintf(stderr, "\n");
  }

 private:
  bool enabled_, terminal_;
  bool shares_ = false;
  double pixels_;
  double next_line_ = 10.0;
  bool drawn_ = false;
};

// Image size: --width/--height, else derived from the camera's aspect ratio, else 512
void resolve_size(const RenderArgs& a, const Scene& scene, int* w, int* h) {
  float aspect = scene.camera ? scene.camera->aspect : 0.0f;
  *w = a.width;
  *h = a.height;
  if (*w == 0 && *h == 0) *w = 512;
  auto scaled = [](double v) { return int(std::clamp(std::round(v), 1.0, 65536.0)); };
  if (*h == 0) *h = aspect > 0 ? scaled(*w / double(aspect)) : *w;
  if (*w == 0) *w = aspect > 0 ? scaled(*h * double(aspect)) : *h;
}

void apply_camera_options(const RenderArgs& a, Scene* scene) {
  if (a.fov && !(*a.fov > 0 && *a.fov < 180)) throw Error("--fov must be between 0 and 180 degrees (exclusive)");
  if (a.aperture && !(*a.aperture >= 0 && std::isfinite(*a.aperture)))
    throw Error("--aperture must be a non-negative radius in scene units");
  if (a.focus_distance && !(*a.focus_distance > 0 && std::isfinite(*a.focus_distance)))
    throw Error("--focus-distance must be a positive distance in scene units");
  bool any = !a.look_from.empty() || !a.look_at.empty() || !a.up.empty() || a.fov || a.aperture ||
             a.focus_distance;
  if (!any) return;
  CameraDesc cam = scene->camera ? *scene->camera : framing_camera(*scene);
  if (!a.look_from.empty()) cam.position = parse_vec3(a.look_from, "--look-from");
  std::optional<float> look_at_distance;
  if (!a.look_at.empty()) {
    glm::vec3 target = parse_vec3(a.look_at, "--look-at");
    if (glm::length(target - cam.position) <= 0) throw Error("--look-at must differ from the camera position");
    cam.forward = glm::normalize(target - cam.position);
    look_at_distance = glm::length(target - cam.position);
  }
  if (!a.up.empty()) cam.up = parse_vec3(a.up, "--up");
  if (a.fov) {  // a field of view makes the camera perspective
    cam.projection = Projection::Perspective;
    cam.yfov = *a.fov * 3.14159265f / 180.0f;
  }
  if (a.aperture) {
    if (*a.aperture > 0 && cam.projection == Projection::Orthographic)
      throw Error("--aperture needs a perspective camera: the scene camera is orthographic (add --fov to replace it)");
    cam.aperture_radius = *a.aperture;
  }
  // Focus: --focus-distance, else the look-at point, else the scene camera's extras,
  // else (resolve_camera) the bounds' centre along the view axis
  if (a.focus_distance)
    cam.focus_distance = *a.focus_distance;
  else if (look_at_distance)
    cam.focus_distance = look_at_distance;
  scene->camera = cam;
}

PixelFilter parse_filter(const std::string& name) {
  if (name == "box") return PixelFilter::Box;
  if (name == "tent") return PixelFilter::Tent;
  if (name == "gaussian") return PixelFilter::Gaussian;
  throw Error("--filter must be box, tent or gaussian, not '" + name + "'");
}

Sampler parse_sampler(const std::string& name) {
  if (name == "sobol") return Sampler::Sobol;
  if (name == "independent") return Sampler::Independent;
  throw Error("--sampler must be sobol or independent, not '" + name + "'");
}

Strategy parse_strategy(const std::string& name) {
  if (name == "nee") return Strategy::Nee;
  if (name == "bsdf") return Strategy::Bsdf;
  if (name == "auto") return Strategy::Auto;
  throw Error("--strategy must be nee, bsdf or auto, not '" + name + "'");
}

// The scene with the command line's overrides, its warnings printed; fills in the
// strategy from the scene when the command line gives none
Scene load_scene(RenderArgs& a) {
  Scene scene = load_gltf(a.scene);
  if (a.strategy.empty()) a.strategy = scene.strategy.empty() ? "nee" : scene.strategy;
  if (!a.background.empty()) {
    scene.background = parse_vec3(a.background, "--background");
    if (scene.background.x < 0 || scene.background.y < 0 || scene.background.z < 0)
      throw Error("--background must not be negative");
    scene.environment.reset();  // the constant replaces the scene's map too
  }
  if (!a.env.empty()) scene.environment = load_environment(a.env, 1.0f, 0.0f);
  apply_camera_options(a, &scene);
  for (const auto& w : scene.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  // Default lighting: a scene without any light (and without a map) gets the built-in sky
  if (!scene.has_light() && !scene.environment) {
    if (a.no_default_light) {
      std::fprintf(stderr, "warning: the scene has no light: no emissive material and a black background; the image will be black\n");
    } else {
      std::fprintf(stderr, "%s\n", kBuiltinSkyNote);
      scene.environment = builtin_sky();
    }
  }
  if (scene.environment) {
    if (a.env_strength) scene.environment->strength = *a.env_strength;
    if (a.env_rotation) scene.environment->rotation = *a.env_rotation;
    if (!(scene.environment->strength >= 0.0f) || !std::isfinite(scene.environment->strength))
      throw Error("--env-strength must be finite and non-negative");
    if (!std::isfinite(scene.environment->rotation)) throw Error("--env-rotation must be finite");
    if (!scene.has_light())
      std::fprintf(stderr, "warning: the scene has no light: the environment map is black; the image will be black\n");
  } else if (a.env_strength || a.env_rotation) {
    std::fprintf(stderr, "warning: --env-strength and --env-rotation apply to an environment map; the scene has none\n");
  }
  // No BSDF-sampled ray can hit a point, spot or directional light
  if (size_t n = scene.punctual_light_count(); n > 0 && parse_strategy(a.strategy) == Strategy::Bsdf)
    std::fprintf(stderr, "warning: the scene's %zu punctual light%s contribute%s nothing under --strategy bsdf; use nee or auto\n", n,
                 n == 1 ? "" : "s", n == 1 ? "s" : "");
  if (!scene.camera) std::fprintf(stderr, "note: the scene has no camera; framing the whole scene from +z\n");
  return scene;
}

// ---- Speed against accuracy: render's --variance and --generic (README) ----

void check_variance_path(const RenderArgs& a) {
  if (a.variance.empty()) return;
  std::string ext = a.variance.size() >= 4 ? a.variance.substr(a.variance.size() - 4) : "";
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".exr") throw Error("--variance must name an .exr file (the variance is linear float data): " + a.variance);
}

// The variance of each pixel's mean beside the image, with the image's metadata
void write_variance_output(const RenderArgs& a, const Film& film, const std::map<std::string, std::string>& meta) {
  if (a.variance.empty()) return;
  write_variance_image(a.variance, film, meta);
  std::printf("wrote %s\n", a.variance.c_str());
}

void add_accuracy_render_options(CLI::App* render, RenderArgs* a) {
  render->add_option("--variance", a->variance,
                     "Also write the variance of each pixel's mean, M2 / (n (n - 1)) per channel, to this .exr "
                     "(infinite where a pixel has fewer than 2 samples)");
  render->add_flag("--generic", a->generic,
                   "Build the generic kernel with every scene feature compiled in, instead of the one specialized "
                   "to the scene (to measure what specialization gains)");
}

// The compiled scene: for --generic, with every kernel feature on (and the vertex arrays
// those features read)
std::shared_ptr<CompiledScene> compile_for_render(const RenderArgs& a, const Scene& scene) {
  return std::make_shared<CompiledScene>(a.generic ? compile_scene(scene, SceneFeatures::all())
                                                   : compile_scene(scene));
}

// ---- end of --variance and --generic ----

// ---- Several devices and machines: --device LIST|all, --sample-offset (README) ----

// --device: one selector (host/device/device.hpp), a comma-separated list of them, or `all`
// (every device `candela devices` lists, each once). A device named twice in a list gets
// two workers (two contexts and queues on it), as asked.
std::vector<DeviceEntry> select_render_devices(const std::string& selector) {
  std::string trimmed = selector;
  trimmed.erase(0, trimmed.find_first_not_of(" \t"));
  trimmed.erase(trimmed.find_last_not_of(" \t") + 1);
  std::string lower = trimmed;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (lower == "all") {
    std::vector<DeviceEntry> all = list_devices();
    if (all.empty()) throw Error("--device all: OpenCL platforms are installed but none has a device");
    return all;
  }
  if (trimmed.find(',') == std::string::npos) return {select_device(trimmed)};
  std::vector<DeviceEntry> devices;
  std::stringstream ss(trimmed);
  for (std::string sel; std::getline(ss, sel, ',');) {
    if (sel.find_first_not_of(" \t") == std::string::npos)
      throw Error("--device has an empty entry: '" + selector + "'");
    std::string l = sel;
    l.erase(0, l.find_first_not_of(" \t"));
    l.erase(l.find_last_not_of(" \t") + 1);
    std::transform(l.begin(), l.end(), l.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (l == "all")
      throw Error("--device all stands alone, not in a list: '" + selector + "'");
    devices.push_back(select_device(sel));
  }
  if (trimmed.back() == ',') throw Error("--device has an empty entry: '" + selector + "'");
  return devices;
}

std::string joined_descriptions(const std::vector<DeviceEntry>& devices) {
  std::string s;
  for (size_t i = 0; i < devices.size(); ++i) s += (i ? " + " : "") + devices[i].description();
  return s;
}

// The scene summary: the single-device lines as before; with several devices one line
// each (its kernel build) and a note for a device named more than once
void print_render_summary(const Renderer& r, const std::vector<DeviceEntry>& devices) {
  if (devices.size() == 1) {
    std::fprintf(stderr, "scene: %zu triangles, %zu lights, BVH %.2fs; kernel build %.2fs%s\n", r.triangles(),
                 r.lights(), r.bvh_build_seconds(), r.kernel_build_seconds(), r.kernel_from_cache() ? " (cached)" : "");
    return;
  }
  for (size_t i = 0; i < devices.size(); ++i) {
    const DeviceRenderer& w = r.worker(i);
    std::fprintf(stderr, "device %zu: %s [%s]; kernel build %.2fs%s\n", i, devices[i].description().c_str(),
                 devices[i].selector().c_str(), w.kernel_build_seconds(), w.kernel_from_cache() ? " (cached)" : "");
    for (size_t j = 0; j < i; ++j)
      if (devices[j].global_index == devices[i].global_index) {
        std::fprintf(stderr, "note: device %zu is device %zu again: two workers share its compute units\n", i, j);
        break;
      }
  }
  std::fprintf(stderr, "scene: %zu triangles, %zu lights, BVH %.2fs; %zu devices\n", r.triangles(), r.lights(),
               r.bvh_build_seconds(), devices.size());
}

// --stats "devices": each worker's samples (summed over pixels), share and rate
nlohmann::json device_shares_json(const std::vector<DeviceEntry>& devices, const RenderResult& r) {
  double total = 0.0;
  for (uint64_t n : r.worker_samples) total += double(n);
  nlohmann::json arr = nlohmann::json::array();
  for (size_t i = 0; i < devices.size(); ++i) {
    uint64_t n = i < r.worker_samples.size() ? r.worker_samples[i] : 0;
    arr.push_back({{"index", i},
                   {"selector", devices[i].selector()},
                   {"description", devices[i].description()},
                   {"samples", n},
                   {"share", total > 0 ? double(n) / total : 0.0},
                   {"samples_per_second", double(n) / std::max(r.seconds, 1e-9)}});
  }
  return arr;
}

void print_device_shares(const std::vector<DeviceEntry>& devices, const RenderResult& r) {
  if (devices.size() < 2) return;
  nlohmann::json shares = device_shares_json(devices, r);
  for (const auto& d : shares)
    std::printf("  device %zu: %.1f%% of the samples, %.3f Msamples/s, %s\n", d["index"].get<size_t>(),
                100.0 * d["share"].get<double>(), d["samples_per_second"].get<double>() * 1e-6,
                d["description"].get<std::string>().c_str());
}

void add_distributed_render_options(CLI::App* render, RenderArgs* a) {
  render->add_option("--sample-offset", a->sample_offset,
                     "First sample index (default 0): renders indices [K, K+spp), a shard for `candela merge`; "
                     "stored as candela:sample_offset");
  render->add_flag("--mpi", a->mpi,
                   "Spread --spp over the ranks of an MPI job (mpirun -np N candela render ... --mpi): each rank "
                   "renders a block of the sample indices, rank 0 merges and writes (needs -DCANDELA_MPI=ON)");
}

// --mpi: the job's session while a render runs under it (main), else null
MpiSession* g_mpi = nullptr;

// Under --mpi, this rank's first sample index and sample count (its block of the
// render's); other ranks than 0 render quietly
uint32_t mpi_shard(RenderArgs* a, uint32_t* spp) {
  if (!g_mpi) return a->sample_offset;
  if (*spp == 0) throw Error("--mpi needs --spp: each rank renders a fixed block of the sample indices");
  if (*spp < uint32_t(g_mpi->size()))
    throw Error("--mpi: --spp " + std::to_string(*spp) + " is fewer than the " + std::to_string(g_mpi->size()) + " ranks");
  uint32_t begin = 0, count = 0;
  mpi_block(*spp, g_mpi->rank(), g_mpi->size(), &begin, &count);
  if (g_mpi->rank() != 0) a->quiet = true;
  *spp = count;
  return a->sample_offset + begin;
}

// Under --mpi, rank 0 gets every rank's samples merged into its result; returns whether
// this rank writes the outputs (rank 0 only)
bool mpi_combine(RenderResult* r) {
  if (!g_mpi) return true;
  r->film = mpi_gather_films(*g_mpi, r->film, &r->spp, &r->seconds, &r->interrupted, &r->partial_pass);
  return g_mpi->rank() == 0;
}

// `render --mpi`: the session around the render; an error on one rank ends the job (the
// others would wait for its film for ever)
int run_render_under_mpi(const RenderArgs& a, int (*run)(RenderArgs)) {
  MpiSession session;
  g_mpi = &session;
  try {
    int rc = run(a);
    g_mpi = nullptr;
    return rc;
  } catch (const cl::Error& e) {
    std::fprintf(stderr, "candela: error: rank %d: %s\n", session.rank(), cl_error_message(e.what(), e.err()).c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "candela: error: rank %d: %s\n", session.rank(), e.what());
  }
  std::fflush(stderr);
  if (session.size() > 1) mpi_abort(1);
  g_mpi = nullptr;
  return 1;
}

void check_sample_offset(const RenderArgs& a, uint32_t spp) {
  if (spp > 0 && uint64_t(a.sample_offset) + spp > (uint64_t(1) << 32))
    throw Error("--sample-offset + --spp must not pass 2^32 sample indices");
}

// ---- end of several devices and machines ----

// --stats "grids": each density grid's device memory (a NanoVDB buffer or dense values, and
// its majorant cells)
nlohmann::json grids_json(const CompiledScene& scene) {
  nlohmann::json list = nlohmann::json::array();
  for (const GridMemory& g : scene.grids)
    list.push_back({{"source", g.source}, {"grid_bytes", g.grid_bytes}, {"majorant_bytes", g.majorant_bytes}});
  return list;
}

// Peak resident set of this process so far (getrusage: kilobytes on Linux)
size_t peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return size_t(u.ru_maxrss) * 1024;
}

void write_stats(const RenderArgs& a, const RenderSettings& settings, const Renderer& renderer,
                 const RenderResult& r, double samples_per_second, const std::vector<DeviceEntry>& devices) {
  nlohmann::json j = {{"spp", r.spp},
                      {"seconds", r.seconds},
                      {"samples_per_second", samples_per_second},
                      {"kernel_build_seconds", renderer.kernel_build_seconds()},
                      {"kernel_from_cache", renderer.kernel_from_cache()},
                      {"kernel_features", renderer.scene().features.build_options()},
                      {"bvh_build_seconds", renderer.bvh_build_seconds()},
                      {"scene_compile_seconds", renderer.scene().compile_seconds},
                      {"scene_device_bytes", renderer.scene().device_bytes},
                      {"grids", grids_json(renderer.scene())},
                      {"device_bytes_per_triangle", double(renderer.scene().device_bytes) / double(std::max<size_t>(1, renderer.triangles()))},
                      {"peak_rss_bytes", peak_rss_bytes()},
                      {"peak_rss_bytes_per_triangle", double(peak_rss_bytes()) / double(std::max<size_t>(1, renderer.triangles()))},
                      {"bvh_sah_cost", renderer.scene().bvh_sah_cost},
                      {"bvh_threads", bvh_build_threads()},
                      {"triangles", renderer.triangles()},
                      {"lights", renderer.lights()},
                      {"device", joined_descriptions(devices)},
                      {"devices", device_shares_json(devices, r)},
                      {"sample_offset", a.sample_offset},
                      {"mpi_ranks", g_mpi ? g_mpi->size() : 0},
                      {"width", settings.width},
                      {"height", settings.height},
                      {"strategy", a.strategy},
                      {"energy_compensation", settings.energy_compensation},
                      {"filter", a.filter},
                      {"sampler", a.sampler},
                      {"max_depth", a.max_depth},
                      {"seed", a.seed},
                      {"interrupted", r.interrupted},
                      {"dropped_samples", r.film.dropped_samples()},
                      {"generic_kernel", a.generic}};
  std::ofstream f(a.stats);
  if (!(f << j.dump(2) << "\n")) throw Error("cannot write stats file " + a.stats);
}

int run_render(RenderArgs a) {
  RenderSettings settings;
  if (!a.strategy.empty()) parse_strategy(a.strategy);  // a bad name fails before loading
  settings.filter = parse_filter(a.filter);
  settings.sampler = parse_sampler(a.sampler);
  parse_tonemap(a.tonemap);  // a bad name fails before loading
  if (!std::isfinite(a.exposure)) throw Error("--exposure must be a finite number of stops");
  if (a.outputs.empty()) throw Error("no output file: pass -o OUT.exr or -o OUT.png");
  for (const auto& out : a.outputs) check_output_path(out);
  check_variance_path(a);
  Scene scene = load_scene(a);
  settings.strategy = parse_strategy(a.strategy);
  resolve_size(a, scene, &settings.width, &settings.height);
  settings.seed = a.seed;
  settings.max_depth = a.max_depth;
  settings.energy_compensation = !a.no_energy_compensation;

  uint32_t spp = a.time > 0 ? 0 : (a.spp ? a.spp : 64);
  check_sample_offset(a, spp);
  uint32_t first_sample = mpi_shard(&a, &spp);
  std::vector<DeviceEntry> devices = select_render_devices(a.device);
  std::string device_text = joined_descriptions(devices);
  if (!a.quiet && devices.size() == 1) std::fprintf(stderr, "device: %s\n", device_text.c_str());
  // Host memory: the loaded scene's arrays go once compiled, the compiled scene's as the
  // devices take their copies (README, Performance: Memory)
  std::shared_ptr<CompiledScene> compiled = compile_for_render(a, scene);
  scene = Scene();
  Renderer renderer(devices, std::move(compiled), settings, true);
  if (!a.quiet) print_render_summary(renderer, devices);

  std::signal(SIGINT, on_sigint);
  double pixels = double(settings.width) * settings.height;
  ProgressBar bar(!a.quiet, pixels);
  bar.show_device_shares(devices.size() > 1);
  RenderResult r = renderer.render(
      first_sample, spp, a.time, [&](const RenderProgress& p) { bar.update(p); },
      [] { return g_interrupted.load(); });
  bar.finish();
  std::signal(SIGINT, SIG_DFL);
  if (!mpi_combine(&r)) return 0;

  if (r.spp == 0) throw Error("interrupted before any sample was rendered; nothing written");
  double samples_per_second = r.spp * pixels / std::max(r.seconds, 1e-9);
  uint64_t dropped = r.film.dropped_samples();
  std::map<std::string, std::string> meta = {
      {"spp", std::to_string(r.spp)},          {"seconds", std::to_string(r.seconds)},
      {"device", device_text},                 {"seed", std::to_string(a.seed)},
      {"strategy", a.strategy},                {"max_depth", std::to_string(a.max_depth)},
      {"dropped_samples", std::to_string(dropped)}, {"scene", a.scene},
      {"energy_compensation", settings.energy_compensation ? "on" : "off"}, {"filter", a.filter},
      {"sampler", a.sampler},
      {"sample_offset", std::to_string(a.sample_offset)}};
  for (const auto& out : a.outputs) {
    write_image(out, r.film, meta, {a.exposure, parse_tonemap(a.tonemap)});
    std::printf("wrote %s\n", out.c_str());
  }
  write_variance_output(a, r.film, meta);
  std::printf("%u spp in %.2fs: %.3f Msamples/s on %s%s\n", r.spp, r.seconds, samples_per_second * 1e-6,
              device_text.c_str(), r.interrupted ? " (interrupted)" : "");
  print_device_shares(devices, r);
  if (r.partial_pass)
    std::fprintf(stderr, "note: stopped inside a pass; some pixels hold more than %u samples\n", r.spp);
  if (dropped) std::fprintf(stderr, "warning: %llu non-finite samples were dropped\n", (unsigned long long)dropped);
  if (!a.stats.empty()) write_stats(a, settings, renderer, r, samples_per_second, devices);
  return r.interrupted ? 130 : 0;
}

CLI::App* add_render_command(CLI::App* app, RenderArgs* args) {
  RenderArgs& a = *args;
  auto* render = app->add_subcommand("render", "Render a glTF scene");
  render->add_option("scene", a.scene, "Scene file (.gltf or .glb)")->required();
  render->add_option("-o,--output", a.outputs, "Output image: .exr (linear), .png or .jpg (tone-mapped sRGB, --tonemap); repeatable")->required();
  auto* spp_opt = render->add_option("--spp", a.spp, "Samples per pixel (default 64)")->check(CLI::Range(1u, 1u << 24));
  render->add_option("--time", a.time, "Render for this many seconds instead of a sample count")
      ->check(CLI::PositiveNumber)
      ->excludes(spp_opt);
  render->add_option("--width", a.width, "Image width (default 512, or from --height and the camera aspect)")->check(CLI::Range(1, 65536));
  render->add_option("--height", a.height, "Image height (default from the camera aspect ratio, else the width)")->check(CLI::Range(1, 65536));
  render->add_option("--device", a.device, "OpenCL device: index, P.D, cpu, gpu, or a name substring (pocl, rusticl, nvidia); default first GPU, else first CPU. A comma-separated list (pocl,rusticl) or `all` renders on several devices at once");
  render->add_option("--seed", a.seed, "Random seed (default 0)");
  render->add_option("--max-depth", a.max_depth, "Maximum number of bounces (default 16)")->check(CLI::Range(0u, 100000u));
  render->add_option("--strategy", a.strategy, "nee (next-event estimation), bsdf (BSDF sampling only) or auto (per vertex: bsdf at near-specular surfaces, nee elsewhere); default: the scene's extras candela.strategy, else nee");
  render->add_flag("--no-energy-compensation", a.no_energy_compensation,
                   "Leave out the multiple scattering of rough GGX lobes (on by default: rough metal keeps its albedo)");
  auto* background_opt =
      render->add_option("--background", a.background, "Constant background radiance R,G,B (replaces the scene's background and environment map)");
  render->add_option("--env", a.env, "Equirectangular environment map (.hdr, .exr, .png, .jpg), replacing the scene's")
      ->excludes(background_opt);
  render->add_option("--env-strength", a.env_strength, "Environment map strength, a radiance scale (default 1, or the scene's)");
  render->add_option("--env-rotation", a.env_rotation, "Environment map rotation about +Y in degrees, counter-clockwise seen from above (default 0, or the scene's)");
  render->add_flag("--no-default-light", a.no_default_light,
                   "Keep a scene without any light black instead of lighting it with the built-in sky");
  render->add_option("--stats", a.stats, "Write render statistics as JSON to this file");
  render->add_option("--exposure", a.exposure, "Exposure of PNG/JPEG outputs in stops (default 0); EXR stays linear");
  render->add_option("--tonemap", a.tonemap,
                     "Display transform of PNG/JPEG outputs: neutral (Khronos PBR Neutral, default), agx (as Blender 4) or clamp");
  render->add_option("--look-from", a.look_from, "Camera position X,Y,Z (overrides the scene camera)");
  render->add_option("--look-at", a.look_at, "Camera target X,Y,Z");
  render->add_option("--up", a.up, "Camera up vector X,Y,Z (default 0,1,0)");
  render->add_option("--fov", a.fov, "Vertical field of view in degrees, 0 < FOV < 180 (makes the camera perspective)");
  render->add_option("--aperture", a.aperture,
                     "Thin-lens aperture radius in scene units for depth of field (default 0: pinhole; perspective cameras)");
  render->add_option("--focus-distance", a.focus_distance,
                     "Distance of the sharp plane along the view axis (default: the --look-at point, else the scene "
                     "camera's extras, else the scene bounds' centre)");
  render->add_option("--filter", a.filter, "Pixel filter: box (default), tent (radius 1 pixel) or gaussian (sigma 0.5 pixel)");
  render->add_option("--sampler", a.sampler,
                     "Random numbers: sobol (Owen-scrambled Sobol, stratified; default) or independent");
  render->add_flag("-q,--quiet", a.quiet, "No progress or scene summary");
  add_accuracy_render_options(render, &a);
  add_distributed_render_options(render, &a);
  return render;
}

// ---- `candela compare` (host/compare.cpp) ----

struct CompareCli {
  CompareArgs args;
  std::string devices;
};

CLI::App* add_compare_command(CLI::App* app, CompareCli* c) {
  CompareArgs& a = c->args;
  auto* cmd = app->add_subcommand(
      "compare",
      "Render a scene on several devices and test whether each agrees with the first within the measured noise "
      "(exit 0: consistent, 2: not); options it does not know are passed to every render");
  cmd->add_option("scene", a.scene, "Scene file (.gltf or .glb)")->required();
  cmd->add_option("--devices", c->devices, "Comma-separated device selectors, the first is the reference")->required();
  cmd->add_option("--spp", a.spp, "Samples per pixel on every device (default 64)")->check(CLI::Range(2u, 1u << 24));
  cmd->add_option("--width", a.width, "Image width (default 64)")->check(CLI::Range(1, 65536));
  cmd->add_option("--height", a.height, "Image height (default from the camera's aspect ratio)")->check(CLI::Range(1, 65536));
  cmd->add_option("--seed", a.seed, "Seed of the first device; device I renders seed + I (default 0)");
  cmd->add_flag("--same-seed", a.same_seed,
                "Render the same seed on every device (correlated noise: the z-test no longer applies)");
  cmd->add_flag("!--no-determinism-check", a.determinism_check,
                "Skip the extra render of the first device's seed on the other devices");
  cmd->add_option("--device-args", a.device_args,
                  "I:OPTIONS: extra render options for the device at position I, e.g. '1:--strategy bsdf' (repeatable)");
  cmd->add_option("--json", a.json, "Also write the results as JSON to this file");
  cmd->add_option("--keep", a.keep, "Keep each device's image and variance image in this directory");
  cmd->add_flag("-q,--quiet", a.quiet, "No progress lines");
  cmd->allow_extras();
  return cmd;
}

int run_compare_command(CLI::App* cmd, CompareCli* c) {
  std::stringstream ss(c->devices);
  for (std::string sel; std::getline(ss, sel, ',');) {
    if (sel.empty()) throw Error("--devices has an empty entry: '" + c->devices + "'");
    c->args.devices.push_back(sel);
  }
  c->args.render_options = cmd->remaining();
  return run_compare(c->args);
}

// ---- end of compare ----

// ---- `candela merge` (host/merge.cpp) ----

CLI::App* add_merge_command(CLI::App* app, MergeArgs* m) {
  auto* cmd = app->add_subcommand(
      "merge", "Merge .exr images of disjoint sample ranges of one render (render --sample-offset K --spp N) into one, "
               "weighted by each file's spp");
  cmd->add_option("inputs", m->inputs, "Images written by candela render (.exr with candela metadata)")->required();
  cmd->add_option("-o,--output", m->output, "Merged image (.exr)")->required();
  cmd->add_flag("-q,--quiet", m->quiet, "Only the 'wrote' line");
  return cmd;
}

// ---- end of merge ----

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"candela: a physically based path tracer running on OpenCL devices"};
  app.set_version_flag("--version", "candela " CANDELA_VERSION);
  app.require_subcommand(1);
  std::string kernel_dir;
  app.add_option("--kernel-dir", kernel_dir,
                 "Load kernel sources from this cl/ directory instead of the embedded copy "
                 "(also: CANDELA_KERNEL_DIR)");

  auto* devices_cmd = app.add_subcommand("devices", "List OpenCL platforms and devices");

  RenderArgs a;
  add_render_command(&app, &a);
  CompareCli compare_cli;
  auto* compare_cmd = add_compare_command(&app, &compare_cli);
  MergeArgs merge_args;
  auto* merge_cmd = add_merge_command(&app, &merge_args);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  // Mesa's rusticl exposes its CPU device only when asked, before the ICD loader starts
  std::string wanted = a.device;
  std::transform(wanted.begin(), wanted.end(), wanted.begin(), [](unsigned char c) { return std::tolower(c); });
  if ((wanted.find("rusticl") != std::string::npos || wanted.find("llvmpipe") != std::string::npos) &&
      !std::getenv("RUSTICL_ENABLE"))
    setenv("RUSTICL_ENABLE", "llvmpipe", 0);

  try {
    if (!kernel_dir.empty()) set_kernel_source_root(kernel_dir);
    if (*devices_cmd) {
      std::printf("%s", format_device_table(list_devices()).c_str());
      for (const auto& p : list_empty_platforms()) {
        std::printf("platform %s has no devices\n", p.c_str());
        if (p.find("rusticl") != std::string::npos)
          std::printf("  (rusticl shows its CPU device with RUSTICL_ENABLE=llvmpipe)\n");
      }
      return 0;
    }
    if (*compare_cmd) return run_compare_command(compare_cmd, &compare_cli);
    if (*merge_cmd) return run_merge(merge_args);
    if (a.mpi) return run_render_under_mpi(a, run_render);
    return run_render(a);
  } catch (const Error& e) {
    std::fprintf(stderr, "candela: error: %s\n", e.what());
    return 1;
  } catch (const cl::Error& e) {
    std::fprintf(stderr, "candela: error: %s\n", cl_error_message(e.what(), e.err()).c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "candela: error: %s\n", e.what());
    return 1;
  }
}
