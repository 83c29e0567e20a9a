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
#include "render/denoise.hpp"
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
  std::vector<float> denoised;  // the last denoised beauty (the full size), shown until the next
  uint32_t denoised_spp = 0;    // its samples per pixel; 0: none for this camera
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

// kVarianceImage's values: 3 per pixel; a pixel without a variance (one sample) at the top
std::vector<float> standard_error_image(const Film& film) {
  std::vector<float> error(film.pixels()), rgb(film.pixels() * 3);
  float largest = 0.0f;
  for (size_t i = 0; i < film.pixels(); ++i) {
    glm::vec3 v = film.variance_of_mean(i);
    error[i] = std::sqrt(std::max(dev::luminance_rgb(v.x, v.y, v.z), 0.0f));
    if (std::isfinite(error[i])) largest = std::max(largest, error[i]);
  }
  for (size_t i = 0; i < film.pixels(); ++i) {
    float e = std::isfinite(error[i]) ? (largest > 0.0f ? error[i] / largest : 0.0f) : 1.0f;
    rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = linear_to_srgb(e);
  }
  return rgb;
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

uint64_t ViewSession::loads() {
  std::lock_guard<std::mutex> lock(mutex_);
  return loads_;
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

ViewSession::Offer ViewSession::offer() {
  std::lock_guard<std::mutex> lock(mutex_);
  return offer_;
}

void ViewSession::reload(std::function<void(RenderArgs&)> change) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    reloads_.push_back(std::move(change));
  }
  changed_.notify_all();
}

void ViewSession::set_image(uint32_t aov, bool denoise) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    image_aov_ = aov;
    denoise_ = denoise;
    ++display_version_;
  }
  changed_.notify_all();
}

void ViewSession::run() {
  try {
    setup();
    while (true) {
      render_loop();
      std::vector<std::function<void(RenderArgs&)>> changes;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        if (quit_ || reloads_.empty()) break;
        changes.swap(reloads_);
        ready_ = false;
        status_ = "loading " + args_.scene;
      }
      if (wake_) wake_();
      for (auto& change : changes) change(args_);
      state_->renderer.reset();
      state_->last.reset();
      state_->corners.clear();
      state_->denoised.clear();
      Clock::time_point start = Clock::now();
      setup();
      std::printf("loaded the scene again in %.2f s\n", seconds_since(start));
      std::fflush(stdout);
    }
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex_);
    error_ = std::current_exception();
  }
  if (wake_) wake_();
}

void ViewSession::setup() {
  State& st = *state_;
  if (st.devices.empty()) st.devices = select_render_devices(args_.device);
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
  Offer offer;
  offer.variants = scene.variants;
  offer.environment = scene.environment.has_value();
  for (const AnimationDesc& anim : scene.animations) {
    offer.anim_start = offer.animated ? std::min(offer.anim_start, anim.start) : anim.start;
    offer.anim_end = offer.animated ? std::max(offer.anim_end, anim.end) : anim.end;
    offer.animated = true;
  }
  offer.aovs = requested_aovs(args_) & ~aov_bit(Aov::Spp);
  try {
    load_denoiser();
    offer.denoiser = true;
  } catch (const Error&) {
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    // A reload keeps a moved camera; one as the scene or the options make it is made anew
    // (an animated camera, a framing of the new pose), the scene camera shown kept
    if (!loaded_ || !camera_.moved()) {
      int index = loaded_ ? camera_.scene_camera_index() : -1;
      camera_ = ViewCamera(start);
      if (index >= 0) camera_.scene_camera(index);
    }
    loaded_ = true;
    offer_ = offer;
    ++version_;  // a new scene: the render restarts
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
    ++loads_;
    frame_.reset();  // none of the scene as it was
    status_.clear();
  }
}

ViewFrame ViewSession::display(const Film& film, uint32_t spp, uint64_t version, bool preview) {
  State& st = *state_;
  // The display transform of PNG outputs: the exposure (metered from the image when
  // automatic, as render meters it), the tone map, the sRGB encoding
  std::optional<float> given;
  Tonemap tonemap;
  uint32_t aov;
  bool denoise;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    given = exposure_;
    tonemap = tonemap_;
    aov = image_aov_;
    denoise = denoise_;
  }
  const bool denoised = denoise && !preview && st.denoised.size() == film.pixels() * 3;
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
  // One AOV as `-o FILE.png:NAME` shows it (its values already encoded)
  std::vector<float> values = aov && aov != kVarianceImage && !film.aov.empty() ? aov_display(film, Aov(aov))
                                                                                 : std::vector<float>();
  if (aov == kVarianceImage) values = standard_error_image(film);
  for (size_t i = 0; i < film.pixels(); ++i) {
    glm::vec3 v = denoised ? glm::vec3(st.denoised[3 * i], st.denoised[3 * i + 1], st.denoised[3 * i + 2])
                           : film.pixel(i);
    v = tonemap_apply(tonemap, v * scale);
    for (int c = 0; c < 3; ++c) {
      float e = values.empty() ? linear_to_srgb(v[c]) : values[3 * i + c];
      f.rgba[4 * i + c] = uint8_t(std::lround(std::clamp(e, 0.0f, 1.0f) * 255.0f));
    }
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
      if (!reloads_.empty()) return;  // run() loads the scene again
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
      if (full) denoise_rested(*st.last, next, limit, st.seconds);
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
      settings_.strategy = kernel->first;  // kept by a reload
      settings_.max_depth = kernel->second;
      renderer.set_kernel_settings(st.settings);
    }
    if (version != shown) {  // moved: restart small
      renderer.set_view(make_device_camera(camera.desc(), preview_width, preview_height), preview_width,
                        preview_height);
      shown = version;
      full = false;
      next = 0;
      st.denoised.clear();
      st.denoised_spp = 0;
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
      return version_ != version || !reloads_.empty();
    };
    RenderResult r = renderer.render(next, count, 0.0, {}, moved);
    if (r.interrupted || r.partial_pass || r.spp < count) continue;  // a newer camera: start again
    next += r.spp;
    if (full) {
      st.seconds = seconds_since(full_start);
      denoise_rested(r, next, limit, st.seconds);
    }
    ViewFrame f = display(r.film, next, version, !full);
    f.camera = camera.render_args(width, height);
    if (full) f.samples_per_second = double(next) * width * height / std::max(st.seconds, 1e-9);
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

// Denoising when still: once the full-size render has rested a while (or reached its
// samples), and again each time its samples double; the denoised beauty stays in
// State::denoised until the next. False when off, not due, or OIDN failed (reported).
bool ViewSession::denoise_rested(const RenderResult& r, uint32_t spp, uint32_t limit, double rested) {
  constexpr double kRestSeconds = 0.5;
  State& st = *state_;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!denoise_ || !offer_.denoiser) return false;
  }
  bool due = spp >= limit || rested >= kRestSeconds;
  if (!due || (st.denoised_spp && spp < 2 * st.denoised_spp && (spp < limit || st.denoised_spp >= spp))) return false;
  bool gpu = std::any_of(st.devices.begin(), st.devices.end(), [](const DeviceEntry& d) { return d.type == "gpu"; });
  std::string quality = args_.denoise.empty() || args_.denoise == "true" ? "balanced" : args_.denoise;
  try {
    DenoiseResult d = denoise_film(r.film, parse_enum(kDenoiseQualityNames, "--denoise", quality), gpu);
    st.denoised = std::move(d.rgb);
    st.denoised_spp = spp;
    return true;
  } catch (const Error& e) {
    std::fprintf(stderr, "candela: error: %s\n", e.what());
    std::lock_guard<std::mutex> lock(mutex_);
    offer_.denoiser = false;
    return false;
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
