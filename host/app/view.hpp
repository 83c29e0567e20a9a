// `candela view SCENE [render options]`: the scene rendered progressively in a window, the
// camera under the mouse. The render is `candela render`'s (the same settings, device
// selection, scene compilation and kernel); view_session.cpp runs it on a thread of its own,
// view_window.cpp (built with GLFW) shows it and takes the input.
#pragma once

#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/render_command.hpp"
#include "render/tonemap.hpp"
#include "scene/scene.hpp"

namespace candela {

CLI::App* add_view_command(CLI::App* app, RenderArgs* args);
// The window until it closes (0), or Error when there is no display or OpenGL context
int run_view(RenderArgs args);
// Whether this candela has the window (built with GLFW)
bool view_built_in();

// The camera the view renders through: the scene's camera as it is until moved, then a
// perspective camera from `from` looking at `at` (the pivot of orbits), the same camera
// that `candela render` makes from render_args()
class ViewCamera {
 public:
  // The scene's cameras (each as resolve_camera gives it), the one shown first (`first`:
  // an index into them, or -1 for `initial`, the camera the options or the framing made),
  // and the bounds that frame all
  struct Start {
    std::vector<CameraDesc> cameras;
    CameraDesc initial;
    int first = -1;
    bool initial_is_scene_camera = false;  // `initial` is cameras[first] as it is
    bool options_camera = false;           // `initial` is what --look-from and the like made
    Bounds bounds;
    std::optional<float> aperture, focus_distance;  // --aperture, --focus-distance as given
  };
  ViewCamera() = default;
  explicit ViewCamera(Start start);

  CameraDesc desc() const;
  // The options that make `candela render` draw this view at width x height
  std::string render_args(int width, int height) const;
  bool moved() const { return moved_; }

  void orbit(float yaw, float pitch);              // radians
  void look(float yaw, float pitch);               // turns about the camera (fly)
  void fly(float forward, float right, float up);  // steps of 5 % of the scene's radius
  void pan(float dx, float dy, int height);        // pixels of a window `height` tall
  void dolly(float steps);                         // wheel steps, positive: closer
  void frame_all(float aspect);                    // the bounds in view, same direction
  void focus(glm::vec3 point);                     // the pivot at `point`, turned to face it
  void reset();                                    // the first camera
  void scene_camera(int index);                    // the scene's camera `index`
  int scene_camera_count() const { return int(start_.cameras.size()); }
  int scene_camera_index() const { return index_; }

 private:
  void look_from_desc(const CameraDesc& c);  // from/at/up/fov of a camera, unchanged
  void detach();                             // about to move: from here on from/at/up/fov
  Start start_;
  CameraDesc base_;   // the camera the look-from options override (its aperture, focus)
  CameraDesc shown_;  // unchanged: the camera shown as it is
  int index_ = -1;    // the scene camera shown or overridden; -1: none
  bool moved_ = false;
  glm::vec3 from_{0.0f}, at_{0.0f, 0.0f, -1.0f}, up_{0.0f, 1.0f, 0.0f};
  float fov_ = 45.0f;  // degrees
};

// One image for the window: 8-bit RGBA through the display transform, rows top first
struct ViewFrame {
  int width = 0, height = 0;
  std::vector<uint8_t> rgba;
  uint32_t spp = 0;
  uint64_t version = 0;  // the camera version it shows
  bool preview = false;
  double samples_per_second = 0.0;
  std::string camera;  // the camera it shows as render options (ViewCamera::render_args)
};

// The image set_image shows besides the beauty and the AOVs: each pixel's standard error
// (the square root of its mean's variance, by luminance) over the image's largest, sRGB-encoded
constexpr uint32_t kVarianceImage = 1u << 31;

// The render of a view on its own thread: loads and compiles the scene, then renders the
// camera's latest version, restarting (at the preview size, one sample per pixel a frame)
// whenever it changes and refining at the full size once it rests
class ViewSession {
 public:
  ViewSession(RenderArgs args, RenderSettings settings, std::function<void()> wake);
  ~ViewSession();
  ViewSession(const ViewSession&) = delete;
  ViewSession& operator=(const ViewSession&) = delete;

  // Changes the camera (once the scene is loaded; false before): `change` edits it
  bool update_camera(const std::function<void(ViewCamera&)>& change);
  ViewCamera camera();
  uint64_t camera_version();
  // The surface point the current camera sees through (u, v) of the image (0..1 across,
  // 0..1 down), by a ray cast against the scene's triangles as loaded; none when it sees
  // the background
  std::optional<glm::vec3> pick(double u, double v);
  // The newest frame not taken yet
  std::optional<ViewFrame> take_frame();
  // What the window title says before the first frame: loading, compiling
  std::string status();
  std::string device();
  // The full image size, once the scene is loaded (false before)
  bool size(int* width, int* height);
  bool ready();                // the scene is compiled and rendering
  uint64_t loads();            // how many times the scene has been loaded and compiled so far
  std::exception_ptr error();  // what stopped the session, if anything
  // The display transform from now on (the newest frame shown again through it): the
  // exposure in stops (unset: --exposure, or the metered one) and the tone map
  void set_display(std::optional<float> exposure, Tonemap tonemap);
  // The strategy and maximum depth from now on (the render restarts)
  void set_kernel(Strategy strategy, uint32_t max_depth);
  // The exposure the newest frame was shown at
  float exposure();
  const RenderArgs& args() const { return args_; }  // as the scene completed them (once ready)
  // What the panel offers, once ready: the scene's variants, its animations' key times, an
  // environment map, the AOVs the render holds (Aov bits), whether Open Image Denoise loads
  struct Offer {
    std::vector<std::string> variants;
    bool animated = false, environment = false, denoiser = false;
    double anim_start = 0.0, anim_end = 0.0;
    uint32_t aovs = 0;
  };
  Offer offer();
  // Loads and compiles the scene again as the first time, with the options `change` edits
  // (--default-light, --env-rotation, --variant, --anim-time), the camera kept; status()
  // says what it waits for meanwhile
  void reload(std::function<void(RenderArgs&)> change);
  // The image shown: the beauty (aov 0), one AOV (an Aov bit) or kVarianceImage, and whether the beauty is
  // denoised once the render rests at the full size
  void set_image(uint32_t aov, bool denoise);
  // Saves the image as it stands (PNG through the display transform, EXR linear); the
  // names written come back through saved()
  void request_save();
  std::vector<std::string> saved();
  void stop();  // ends the render between launches and joins the thread

 private:
  void run();
  void setup();
  void render_loop();
  bool denoise_rested(const RenderResult& r, uint32_t spp, uint32_t limit, double rested);
  void save(const RenderResult& result);
  ViewFrame display(const Film& film, uint32_t spp, uint64_t version, bool preview);

  RenderArgs args_;
  RenderSettings settings_;
  std::function<void()> wake_;
  std::mutex mutex_;
  std::condition_variable changed_;
  ViewCamera camera_;
  uint64_t version_ = 0;
  std::optional<ViewFrame> frame_;
  std::string status_, device_;
  std::vector<std::string> saved_;
  bool ready_ = false, save_asked_ = false;
  std::optional<float> exposure_;  // set_display's
  Tonemap tonemap_ = Tonemap::Neutral;
  uint64_t display_version_ = 0;
  std::optional<std::pair<Strategy, uint32_t>> kernel_;  // set_kernel's, not applied yet
  std::exception_ptr error_;
  std::vector<std::function<void(RenderArgs&)>> reloads_;  // reload()'s, not applied yet
  Offer offer_;
  bool loaded_ = false;         // the first load is done (a reload keeps the camera)
  uint64_t loads_ = 0;
  uint32_t image_aov_ = 0;      // set_image's
  bool denoise_ = false;
  std::atomic<bool> quit_{false};
  int width_ = 0, height_ = 0;
  struct State;
  std::unique_ptr<State> state_;  // the renderer and what it needs (the thread's)
  std::thread thread_;
};

}  // namespace candela
