// The live view's render thread (view.hpp: ViewSession): the scene loaded and compiled as
// `candela render` does, then rendered through the window's latest camera.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "app/options.hpp"
#include "app/render_devices.hpp"
#include "app/render_scene.hpp"
#include "app/report.hpp"
#include "app/view.hpp"
#include "base/error.hpp"
#include "compile/camera.hpp"
#include "render/aov.hpp"
#include "render/film.hpp"
#include "render/tonemap.hpp"
#include "scene/default_light.hpp"

namespace candela {
namespace {

using Clock = std::chrono::steady_clock;

// While the camera moves: the image at a quarter of the full size each way
constexpr int kPreviewDivisor = 4;
// Launches short enough that a camera change restarts the render at once
constexpr double kViewLaunchSeconds = 0.01;
// At the full size, the frames come at least this often
constexpr double kFrameSeconds = 0.1;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace

struct ViewSession::State {
  std::vector<DeviceEntry> devices;
  std::unique_ptr<Renderer> renderer;
  RenderSettings settings;           // completed for the scene: the full size
  std::optional<RenderResult> last;  // the newest frame's render, the film holding all its samples
  float exposure = 0.0f;             // the newest frame's (metered when automatic)
  double seconds = 0.0;              // the full-size render's time so far
  double last_rate = 0.0;            // the newest frame's samples per second
  // The scene's triangles as loaded (three corners each, world space) for pick(): the
  // device holds the compiled scene, and a click's ray cast is rare enough to test them all
  std::vector<glm::vec3> corners;
};

namespace {

// The distance along the ray to the triangle (a, b, c), two-sided, or a negative number
float hit_distance(glm::vec3 o, glm::vec3 d, glm::vec3 a, glm::vec3 b, glm::vec3 c) {
  glm::vec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
  float det = glm::dot(e1, p);
  if (std::abs(det) < 1e-20f) return -1.0f;
  float inv = 1.0f / det;
  glm::vec3 t = o - a;
  float u = glm::dot(t, p) * inv;
  if (u < 0.0f || u > 1.0f) return -1.0f;
  glm::vec3 q = glm::cross(t, e1);
  float v = glm::dot(d, q) * inv;
  if (v < 0.0f || u + v > 1.0f) return -1.0f;
  return glm::dot(e2, q) * inv;
}

}  // namespace

ViewSession::ViewSession(RenderArgs args, RenderSettings settings, std::function<void()> wake)
    : args_(std::move(args)), settings_(std::move(settings)), wake_(std::move(wake)), state_(new State) {
  status_ = "loading " + args_.scene;
  exposure_ = args_.exposure;
  tonemap_ = parse_tonemap(args_.tonemap);
  thread_ = std::thread([this] { run(); });
}

ViewSession::~ViewSession() { stop(); }

void ViewSession::stop() {
  quit_ = true;
  changed_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool ViewSession::update_camera(const std::function<void(ViewCamera&)>& change) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!ready_) return false;
    change(camera_);
    ++version_;
  }
  changed_.notify_all();
  return true;
}

ViewCamera ViewSession::camera() {
  std::lock_guard<std::mutex> lock(mutex_);
  return camera_;
}

uint64_t ViewSession::camera_version() {
  std::lock_guard<std::mutex> lock(mutex_);
  return version_;
}

std::optional<glm::vec3> ViewSession::pick(double u, double v) {
  CameraDesc desc;
  int width, height;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!ready_) return std::nullopt;
    desc = camera_.desc();
    width = width_;
    height = height_;
  }
  // The pinhole ray through (u, v), as the kernel's camera makes it
  dev::Camera c = make_device_camera(desc, width, height);
  glm::vec3 f(c.forward[0], c.forward[1], c.forward[2]), r(c.right[0], c.right[1], c.right[2]),
      up(c.up[0], c.up[1], c.up[2]), o(c.origin[0], c.origin[1], c.origin[2]);
  float sx = float(2.0 * u - 1.0), sy = float(1.0 - 2.0 * v);
  glm::vec3 d = f + sx * r + sy * up;
  if (c.type == CAMERA_ORTHOGRAPHIC) {
    o += sx * r + sy * up;
    d = f;
  }
  d = glm::normalize(d);
  const std::vector<glm::vec3>& p = state_->corners;  // written before ready_, unchanged since
  float nearest = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i + 2 < p.size(); i += 3) {
    float t = hit_distance(o, d, p[i], p[i + 1], p[i + 2]);
    if (t > 0.0f && t < nearest) nearest = t;
  }
  if (!std::isfinite(nearest)) return std::nullopt;
  return o + nearest * d;
}

std::optional<ViewFrame> ViewSession::take_frame() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<ViewFrame> f = std::move(frame_);
  frame_.reset();
  return f;
}

std::string ViewSession::status() {
  std::lock_guard<std::mutex> lock(mutex_);
  return status_;
}

std::string ViewSession::device() {
  std::lock_guard<std::mutex> lock(mutex_);
  return device_;
}

bool ViewSession::size(int* width, int* height) {
  std::lock_guard<std::mutex> lock(mutex_);
  *width = width_;
  *height = height_;
  return width_ > 0;
}

bool ViewSession::ready() {
  std::lock_guard<std::mutex> lock(mutex_);
  return ready_;
}

std::exception_ptr ViewSession::error() {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

void ViewSession::set_display(std::optional<float> exposure, Tonemap tonemap) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    exposure_ = exposure;
    tonemap_ = tonemap;
    ++display_version_;
  }
  changed_.notify_all();
}

void ViewSession::set_kernel(Strategy strategy, uint32_t max_depth) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    kernel_ = {strategy, max_depth};
    ++version_;
  }
  changed_.notify_all();
}

float ViewSession::exposure() {
  std::lock_guard<std::mutex> lock(mutex_);
  return state_->exposure;
}

void ViewSession::request_save() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    save_asked_ = true;
  }
  changed_.notify_all();
}

std::vector<std::string> ViewSession::saved() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<std::string> names = std::move(saved_);
  saved_.clear();
  return names;
}

void ViewSession::run() {
  try {
    setup();
    render_loop();
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::current_exception();
  }
  if (wake_) wake_();
}

void ViewSession::setup() {
  State& st = *state_;
  st.devices = select_render_devices(args_.device);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    device_ = joined_descriptions(st.devices);
  }
  KernelPrebuild prebuild;
  for (const DeviceEntry& d : st.devices) prebuild.start_tables(d, settings_);
  Scene scene = load_render_scene(&args_);
  prebuild.loaded();
  RenderSettings s = settings_;
  s.launch_seconds = kViewLaunchSeconds;  // CANDELA_LAUNCH_SECONDS still sets it (complete_settings)
  s.launch_growth = 2.0;
  complete_settings(args_, scene, &s);
  auto say_compiling = s.before_kernel_compile;
  s.before_kernel_compile = [this, say_compiling](const std::string& device) {
    if (say_compiling) say_compiling(device);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      status_ = "compiling the render kernel for " + device;
    }
    if (wake_) wake_();
  };
  // The cameras: the one render would use, the scene's own, the bounds that frame all
  ViewCamera::Start start;
  float aspect = float(s.width) / float(s.height);
  start.initial = resolve_camera(scene, aspect);
  std::optional<CameraDesc> kept = scene.camera;
  for (const CameraDesc& c : scene.cameras) {
    scene.camera = c;
    start.cameras.push_back(resolve_camera(scene, aspect));
  }
  scene.camera = kept;
  const RenderArgs& a = args_;
  start.options_camera =
      !a.look_from.empty() || !a.look_at.empty() || !a.up.empty() || a.fov || a.aperture || a.focus_distance;
  start.initial_is_scene_camera = !start.options_camera && !scene.cameras.empty();
  start.first = start.initial_is_scene_camera ? a.camera.value_or(0) : -1;
  start.bounds = framing_bounds(scene);
  start.aperture = a.aperture;
  start.focus_distance = a.focus_distance;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    camera_ = ViewCamera(start);
    width_ = s.width;
    height_ = s.height;
    status_ = "preparing the scene";
  }
  if (wake_) wake_();
  for (const MeshDesc& m : scene.meshes)
    for (uint32_t i : m.indices) st.corners.push_back(m.positions[i]);
  st.renderer = std::make_unique<Renderer>(make_renderer(args_, &scene, s, st.devices, prebuild));
  st.settings = s;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ready_ = true;
    status_.clear();
  }
}

ViewFrame ViewSession::display(const Film& film, uint32_t spp, uint64_t version, bool preview) {
  State& st = *state_;
  // The display transform of PNG outputs: the exposure (metered from the image when
  // automatic, as render meters it), the tone map, the sRGB encoding
  std::optional<float> given;
  Tonemap tonemap;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    given = exposure_;
    tonemap = tonemap_;
  }
  float exposure = given.value_or(0.0f);
  if (!given && args_.auto_exposure_share) {
    std::vector<float> lum(film.pixels());
    for (size_t i = 0; i < film.pixels(); ++i) {
      glm::vec3 v = film.pixel(i);
      lum[i] = dev::luminance_rgb(v.x, v.y, v.z);
    }
    exposure = image_exposure(lum, film.width, film.height).value_or(0.0f);
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    st.exposure = exposure;
  }
  float scale = std::exp2(exposure);
  ViewFrame f;
  f.width = film.width;
  f.height = film.height;
  f.spp = spp;
  f.version = version;
  f.preview = preview;
  f.rgba.resize(film.pixels() * 4);
  for (size_t i = 0; i < film.pixels(); ++i) {
    glm::vec3 v = tonemap_apply(tonemap, film.pixel(i) * scale);
    for (int c = 0; c < 3; ++c)
      f.rgba[4 * i + c] = uint8_t(std::lround(std::clamp(linear_to_srgb(v[c]), 0.0f, 1.0f) * 255.0f));
    f.rgba[4 * i + 3] = 255;
  }
  return f;
}

void ViewSession::render_loop() {
  State& st = *state_;
  Renderer& renderer = *st.renderer;
  const int width = st.settings.width, height = st.settings.height;
  const int preview_width = std::max(1, width / kPreviewDivisor);
  const int preview_height = std::max(1, height / kPreviewDivisor);
  const uint32_t limit = args_.spp ? args_.spp : kMaxSamplesPerPixel;
  uint64_t shown = ~uint64_t(0), display_shown = 0;
  bool full = false;
  uint32_t next = 0;
  Clock::time_point full_start = Clock::now();
  while (!quit_) {
    uint64_t version;
    ViewCamera camera;
    bool save_now, redisplay;
    std::optional<std::pair<Strategy, uint32_t>> kernel;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (version_ == shown && full && next >= limit && !save_asked_ && display_version_ == display_shown)
        changed_.wait_for(lock, std::chrono::milliseconds(100));  // converged: wait for a change
      redisplay = display_version_ != display_shown && st.last && version_ == shown;
      display_shown = display_version_;
      version = version_;
      camera = camera_;
      kernel = kernel_;
      kernel_.reset();
      save_now = save_asked_ && st.last;
      if (save_now) save_asked_ = false;
    }
    if (quit_) break;
    if (redisplay) {  // the newest frame through the new display transform
      ViewFrame f = display(st.last->film, st.last->spp, version, !full);
      f.camera = camera.render_args(width, height);
      f.samples_per_second = st.last_rate;
      std::lock_guard<std::mutex> lock(mutex_);
      frame_ = std::move(f);
    }
    if (save_now) save(*st.last);
    if (kernel) {  // another strategy or depth: the film restarts below (a new version)
      st.settings.strategy = kernel->first;
      st.settings.max_depth = kernel->second;
      args_.strategy = enum_name(kStrategyNames, kernel->first);
      args_.settings.max_depth = kernel->second;
      renderer.set_kernel_settings(st.settings);
    }
    if (version != shown) {  // moved: restart small
      renderer.set_view(make_device_camera(camera.desc(), preview_width, preview_height), preview_width,
                        preview_height);
      shown = version;
      full = false;
      next = 0;
    } else if (!full) {  // at rest: refine at the full size
      renderer.set_view(make_device_camera(camera.desc(), width, height), width, height);
      full = true;
      next = 0;
      full_start = Clock::now();
    } else if (next >= limit) {
      continue;
    }
    uint32_t count = full ? std::min(renderer.worker().suggested_batch(kFrameSeconds), limit - next) : 1;
    // A newer camera stops a full-size frame between launches; a preview frame (short) is
    // finished and shown, so that a drag shows a frame at least every other preview frame
    auto moved = [&] {
      if (quit_) return true;
      if (!full) return false;
      std::lock_guard<std::mutex> lock(mutex_);
      return version_ != version;
    };
    RenderResult r = renderer.render(next, count, 0.0, {}, moved);
    if (r.interrupted || r.partial_pass || r.spp < count) continue;  // a newer camera: start again
    next += r.spp;
    ViewFrame f = display(r.film, next, version, !full);
    f.camera = camera.render_args(width, height);
    if (full) {
      st.seconds = seconds_since(full_start);
      f.samples_per_second = double(next) * width * height / std::max(st.seconds, 1e-9);
    }
    st.last_rate = f.samples_per_second;
    r.spp = next;
    r.seconds = full ? st.seconds : r.seconds;
    st.last = std::move(r);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      frame_ = std::move(f);
    }
    if (wake_) wake_();
  }
}

void ViewSession::save(const RenderResult& result) {
  State& st = *state_;
  std::string prefix = "candela-view";
  if (!args_.outputs.empty()) {
    std::filesystem::path p = parse_output(args_.outputs.front()).path;
    prefix = (p.parent_path() / p.stem()).string();
  }
  std::string base;
  for (int n = 1;; ++n) {
    char number[16];
    std::snprintf(number, sizeof number, "-%04d", n);
    base = prefix + number;
    if (!std::filesystem::exists(base + ".png") && !std::filesystem::exists(base + ".exr")) break;
  }
  RenderSettings s = st.settings;
  s.width = result.film.width;
  s.height = result.film.height;
  RenderReport report = make_render_report(args_, s, *st.renderer, result, st.devices);
  std::map<std::string, std::string> meta = image_metadata(report);
  std::vector<std::string> written;
  try {
    Tonemap tonemap;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      tonemap = tonemap_;
    }
    ImageLayers layers;  // as render writes them: --aov's channels in the EXR, --transparent's alpha
    layers.aovs = requested_aovs(args_);
    layers.transparent = args_.transparent;
    write_image(base + ".png", result.film, meta, {st.exposure, tonemap}, layers);
    written.push_back(base + ".png");
    write_image(base + ".exr", result.film, meta, {}, layers);
    written.push_back(base + ".exr");
  } catch (const Error& e) {
    std::fprintf(stderr, "candela: error: %s\n", e.what());
  }
  for (const std::string& name : written) std::printf("wrote %s (%u spp)\n", name.c_str(), result.spp);
  std::fflush(stdout);
  std::lock_guard<std::mutex> lock(mutex_);
  saved_ = written;
}

}  // namespace candela
