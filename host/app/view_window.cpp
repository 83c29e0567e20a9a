// `candela view`'s window (built with GLFW and OpenGL): the session's frames on a texture,
// the mouse and keys moving its camera (view.hpp; the keys are listed in docs/cli.md).
#define GLFW_INCLUDE_NONE
#include <GL/gl.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>

#include "app/render_scene.hpp"
#include "app/view.hpp"
#include "app/view_panel.hpp"
#include "base/error.hpp"
#include "base/file_access.hpp"
#include "scene/default_light.hpp"

namespace candela {
namespace {

using Clock = std::chrono::steady_clock;

std::atomic<bool> g_interrupted{false};
void on_interrupt(int) { g_interrupted = true; }

std::string g_glfw_error;
void on_glfw_error(int, const char* text) { g_glfw_error = text ? text : "unknown GLFW error"; }

constexpr double kOrbitRadiansPerPixel = 0.008;

// The window's input and what it has shown
struct Viewer {
  ViewSession* session = nullptr;
  GLFWwindow* window = nullptr;
  int width = 256, height = 256;
  bool orbiting = false, panning = false, looking = false;
  double x = 0.0, y = 0.0;  // the cursor, as the last motion left it
  bool cursor_known = false;
  // The first camera change no frame shows yet: since when, and its version
  bool pending = false;
  Clock::time_point pending_since;
  uint64_t pending_version = 0;
  std::vector<double> latencies;  // seconds from a change to the first frame that shows it
  PanelState panel;               // the panel's state, the last save's names among it
  uint64_t loads = 0;             // the session's loads() at the last look
  Clock::time_point last_click;   // the last left press: a second one soon after is a double-click
  double click_x = -1e9, click_y = -1e9;

  void move(const std::function<void(ViewCamera&)>& change) {
    if (!session->update_camera(change)) return;
    if (!pending) {
      pending = true;
      pending_since = Clock::now();
      pending_version = session->camera_version();
    }
  }
};

Viewer& viewer_of(GLFWwindow* w) { return *static_cast<Viewer*>(glfwGetWindowUserPointer(w)); }

// The pivot at the surface point under the cursor (the image spans the window)
void focus_at_cursor(Viewer& v) {
  int ww = 0, wh = 0;
  glfwGetWindowSize(v.window, &ww, &wh);
  if (ww <= 0 || wh <= 0) return;
  std::optional<glm::vec3> point = v.session->pick(v.x / ww, v.y / wh);
  if (point) v.move([&](ViewCamera& c) { c.focus(*point); });
}

// Two left presses within this long and this many pixels of each other
constexpr double kDoubleClickSeconds = 0.4, kDoubleClickPixels = 4.0;

void on_mouse_button(GLFWwindow* w, int button, int action, int mods) {
  Viewer& v = viewer_of(w);
  // Where the last motion left the cursor (glfwGetCursorPos would give where it is now,
  // past motions still queued)
  if (!v.cursor_known) glfwGetCursorPos(w, &v.x, &v.y);
  v.cursor_known = true;
  bool down = action == GLFW_PRESS;
  if (down && panel_wants_mouse()) return;
  if (button == GLFW_MOUSE_BUTTON_RIGHT) {
    v.looking = down;
  } else if (button == GLFW_MOUSE_BUTTON_MIDDLE ||
             (button == GLFW_MOUSE_BUTTON_LEFT && (mods & GLFW_MOD_SHIFT) && down)) {
    v.panning = down;
    if (button == GLFW_MOUSE_BUTTON_LEFT) v.orbiting = false;
  } else if (button == GLFW_MOUSE_BUTTON_LEFT) {
    v.orbiting = down;
    if (!down) v.panning = false;
    if (down) {
      Clock::time_point now = Clock::now();
      bool twice = std::chrono::duration<double>(now - v.last_click).count() < kDoubleClickSeconds &&
                   std::abs(v.x - v.click_x) <= kDoubleClickPixels && std::abs(v.y - v.click_y) <= kDoubleClickPixels;
      v.last_click = now;
      v.click_x = v.x;
      v.click_y = v.y;
      if (twice) {
        v.click_x = -1e9;  // a third press starts anew
        focus_at_cursor(v);
      }
    }
  }
}

void on_cursor(GLFWwindow* w, double x, double y) {
  Viewer& v = viewer_of(w);
  double dx = x - v.x, dy = y - v.y;
  v.x = x;
  v.y = y;
  if (!v.cursor_known) dx = dy = 0.0;
  v.cursor_known = true;
  if (dx == 0.0 && dy == 0.0) return;
  if (v.looking)
    v.move([&](ViewCamera& c) { c.look(float(-dx * kOrbitRadiansPerPixel), float(-dy * kOrbitRadiansPerPixel)); });
  else if (v.panning)
    v.move([&](ViewCamera& c) { c.pan(float(dx), float(dy), v.height); });
  else if (v.orbiting)
    v.move([&](ViewCamera& c) { c.orbit(float(-dx * kOrbitRadiansPerPixel), float(-dy * kOrbitRadiansPerPixel)); });
}

void on_scroll(GLFWwindow* w, double, double dy) {
  if (panel_wants_mouse()) return;
  viewer_of(w).move([&](ViewCamera& c) { c.dolly(float(dy)); });
}

// The camera options with the display options the panel changed
std::string printed_options(Viewer& v) {
  std::string text = v.session->camera().render_args(v.width, v.height);
  const RenderArgs& a = v.session->args();
  char exposure[48];
  std::snprintf(exposure, sizeof exposure, " --exposure %.9g", double(v.panel.exposure));
  if (!v.panel.exposure_automatic) text += exposure;
  std::string tonemap = kTonemapNames[v.panel.tonemap].name;
  if (tonemap != a.tonemap) text += " --tonemap " + tonemap;
  if (v.panel.strategy != v.panel.first_strategy)
    text += std::string(" --strategy ") + kStrategyNames[v.panel.strategy].name;
  if (v.panel.max_depth != v.panel.first_max_depth) text += " --max-depth " + std::to_string(v.panel.max_depth);
  std::string light = kDefaultLightNames[v.panel.default_light].name;
  if (light != "auto") text += " --default-light " + light;
  char number[48];
  std::snprintf(number, sizeof number, " --env-rotation %.9g", double(v.panel.env_rotation));
  if (v.panel.offer.environment && v.panel.env_rotation != 0.0f) text += number;
  if (v.panel.variant > 0) text += " --variant " + v.panel.offer.variants[size_t(v.panel.variant - 1)];
  std::snprintf(number, sizeof number, " --anim-time %.9g", double(v.panel.anim_time));
  if (v.panel.anim_time_set) text += number;
  return text;
}

void act(Viewer& v, int key) {
  GLFWwindow* w = v.window;
  if (!v.panel.ready) {
    if (key == GLFW_KEY_ESCAPE || key == GLFW_KEY_Q) glfwSetWindowShouldClose(w, GLFW_TRUE);
    return;
  }
  float aspect = float(v.width) / float(v.height);
  switch (key) {
    case GLFW_KEY_ESCAPE:
    case GLFW_KEY_Q:
      glfwSetWindowShouldClose(w, GLFW_TRUE);
      break;
    case GLFW_KEY_P:
      std::printf("camera: %s\n", printed_options(v).c_str());
      std::fflush(stdout);
      break;
    case GLFW_KEY_S:
      v.session->request_save();
      break;
    case GLFW_KEY_F:
      v.move([&](ViewCamera& c) { c.frame_all(aspect); });
      break;
    case GLFW_KEY_G:
      focus_at_cursor(v);
      break;
    case GLFW_KEY_L: {  // the next --default-light: auto, on, off (the scene loads again)
      v.panel.default_light = (v.panel.default_light + 1) % int(std::size(kDefaultLightNames));
      std::string name = kDefaultLightNames[v.panel.default_light].name;
      v.session->reload([name](RenderArgs& a) { a.default_light = name; });
      break;
    }
    case GLFW_KEY_N:  // denoise when still (where Open Image Denoise loads)
      v.panel.denoise = v.panel.offer.denoiser && !v.panel.denoise;
      v.session->set_image(v.panel.image, v.panel.denoise);
      break;
    case GLFW_KEY_V: {  // the next image: the beauty, then each AOV the render holds
      uint32_t images = v.panel.offer.aovs | kVarianceImage, next = 0;
      for (uint32_t bit = v.panel.image ? v.panel.image << 1 : 1; bit && !next; bit <<= 1)
        if (images & bit) next = bit;
      v.panel.image = next;
      v.session->set_image(next, v.panel.denoise);
      break;
    }
    case GLFW_KEY_R:
      v.move([&](ViewCamera& c) { c.reset(); });
      break;
    case GLFW_KEY_C:
      v.move([&](ViewCamera& c) {
        if (c.scene_camera_count() > 0) c.scene_camera((c.scene_camera_index() + 1) % c.scene_camera_count());
      });
      break;
    case GLFW_KEY_TAB:
      v.panel.visible = !v.panel.visible;
      break;
    default:
      if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9) v.move([&](ViewCamera& c) { c.scene_camera(key - GLFW_KEY_1); });
  }
}

// With the right button held, W A S D Q E fly (held down: repeated)
bool fly(Viewer& v, int key) {
  float f = 0.0f, r = 0.0f, u = 0.0f;
  switch (key) {
    case GLFW_KEY_W:
      f = 1.0f;
      break;
    case GLFW_KEY_S:
      f = -1.0f;
      break;
    case GLFW_KEY_D:
      r = 1.0f;
      break;
    case GLFW_KEY_A:
      r = -1.0f;
      break;
    case GLFW_KEY_E:
      u = 1.0f;
      break;
    case GLFW_KEY_Q:
      u = -1.0f;
      break;
    default:
      return false;
  }
  v.move([&](ViewCamera& c) { c.fly(f, r, u); });
  return true;
}

void on_key(GLFWwindow* w, int key, int, int action, int) {
  if (action == GLFW_RELEASE || panel_wants_keyboard()) return;
  Viewer& v = viewer_of(w);
  if (v.looking && v.panel.ready && fly(v, key)) return;
  if (action == GLFW_PRESS) act(v, key);
}

void upload(GLuint texture, const ViewFrame& f) {
  glBindTexture(GL_TEXTURE_2D, texture);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  GLint filter = f.preview ? GL_LINEAR : GL_NEAREST;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, f.width, f.height, 0, GL_RGBA, GL_UNSIGNED_BYTE, f.rgba.data());
}

// The texture over the whole window, its first row at the top
void draw(GLFWwindow* window, GLuint texture, bool any) {
  int fw = 0, fh = 0;
  glfwGetFramebufferSize(window, &fw, &fh);
  glViewport(0, 0, fw, fh);
  glClearColor(0.2f, 0.2f, 0.2f, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  if (any) {
    glEnable(GL_TEXTURE_2D);
    glBindTexture(GL_TEXTURE_2D, texture);
    glColor4f(1.0f, 1.0f, 1.0f, 1.0f);
    glBegin(GL_QUADS);
    glTexCoord2f(0.0f, 1.0f);
    glVertex2f(-1.0f, -1.0f);
    glTexCoord2f(1.0f, 1.0f);
    glVertex2f(1.0f, -1.0f);
    glTexCoord2f(1.0f, 0.0f);
    glVertex2f(1.0f, 1.0f);
    glTexCoord2f(0.0f, 0.0f);
    glVertex2f(-1.0f, 1.0f);
    glEnd();
    glDisable(GL_TEXTURE_2D);
  }
}

std::string title_of(Viewer& v, const std::string& scene, const std::optional<ViewFrame>& shown) {
  std::string title = "candela view: " + scene + ": ";
  std::string status = v.session->status();
  if (!v.session->ready() || !shown) return title + (status.empty() ? "rendering" : status);
  char text[160];
  std::snprintf(text, sizeof text, "%u spp%s, %.2f Msamples/s", shown->spp, shown->preview ? " (preview)" : "",
                shown->samples_per_second * 1e-6);
  title += text;
  title += ": " + shown->camera;
  if (!v.panel.saved.empty()) title += ": saved " + v.panel.saved;
  return title;
}

// One line on stderr: how soon frames followed the camera's changes
void report_latency(const Viewer& v) {
  if (v.latencies.empty()) return;
  std::vector<double> s = v.latencies;
  std::sort(s.begin(), s.end());
  std::fprintf(stderr,
               "view: camera change to updated frame: median %.1f ms, max %.1f ms over %zu changes (preview %dx%d)\n",
               1e3 * s[s.size() / 2], 1e3 * s.back(), s.size(), std::max(1, v.width / 4), std::max(1, v.height / 4));
}

// Leaves at once while the session still loads or compiles (nothing to save yet)
[[noreturn]] void leave_now(int status) {
  glfwTerminate();
  std::fflush(stdout);
  std::fflush(stderr);
  std::_Exit(status);
}

}  // namespace

bool view_built_in() { return true; }

int run_view(RenderArgs args) {
  RenderSettings settings = prepare_render_settings(args);
  if (settings.noise_threshold > 0.0)
    throw Error("--noise-threshold is for candela render: the view refines every pixel alike");
  if (!args.shutter.empty()) throw Error("--shutter is for candela render: the view shows one moment");
  check_regular_file(args.scene, "scene file");
  glfwSetErrorCallback(on_glfw_error);
  auto unset = [](const char* name) { return !std::getenv(name) || !*std::getenv(name); };
  if (unset("DISPLAY") && unset("WAYLAND_DISPLAY"))
    throw Error("no display: candela view opens a window (DISPLAY is not set; without a screen, run it under Xvfb)");
  if (!glfwInit()) throw Error("cannot open a window: " + g_glfw_error);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
  GLFWwindow* window = glfwCreateWindow(256, 256, "candela view", nullptr, nullptr);
  if (!window) {
    std::string why = g_glfw_error;
    glfwTerminate();
    throw Error("cannot create an OpenGL window: " + why);
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(0);
  GLuint texture = 0;
  glGenTextures(1, &texture);
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);

  Viewer v;
  v.window = window;
  glfwSetWindowUserPointer(window, &v);
  glfwSetMouseButtonCallback(window, on_mouse_button);
  glfwSetCursorPosCallback(window, on_cursor);
  glfwSetScrollCallback(window, on_scroll);
  glfwSetKeyCallback(window, on_key);
  ViewSession session(args, settings, [] { glfwPostEmptyEvent(); });
  v.session = &session;
  v.panel.session = &session;
  v.panel.press = [&v](int key) { act(v, key); };
  panel_init(window, &v.panel);
  bool visible = false;
  std::optional<ViewFrame> shown;  // without its pixels
  std::string title;
  while (!glfwWindowShouldClose(window) && !g_interrupted) {
    glfwWaitEventsTimeout(0.05);
    if (std::exception_ptr e = session.error()) {
      session.stop();
      glfwTerminate();
      std::rethrow_exception(e);
    }
    if (!visible && session.size(&v.width, &v.height)) {
      glfwSetWindowSize(window, v.width, v.height);
      glfwShowWindow(window);
      visible = true;
    }
    if (session.loads() != v.loads) {  // loaded, or loaded again: no frame of the scene as it was
      v.loads = session.loads();
      panel_ready(&v.panel);
      if (v.loads > 1) shown.reset();
    }
    std::optional<ViewFrame> f = session.take_frame();
    if (f) {
      upload(texture, *f);
      f->rgba.clear();
      shown = std::move(f);
    }
    if (visible) {
      draw(window, texture, shown.has_value());
      v.panel.shown = shown ? &*shown : nullptr;
      panel_draw(&v.panel);
      glfwSwapBuffers(window);
    }
    if (v.pending && shown && shown->version >= v.pending_version) {
      v.latencies.push_back(std::chrono::duration<double>(Clock::now() - v.pending_since).count());
      v.pending = false;
    }
    std::vector<std::string> saved = session.saved();
    if (!saved.empty()) {
      v.panel.saved.clear();
      for (const std::string& name : saved) v.panel.saved += (v.panel.saved.empty() ? "" : ", ") + name;
    }
    std::string now = title_of(v, args.scene, shown);
    if (now != title) glfwSetWindowTitle(window, (title = now).c_str());
  }
  if (!session.ready()) leave_now(0);
  session.stop();
  report_latency(v);
  panel_shutdown();
  glDeleteTextures(1, &texture);
  glfwDestroyWindow(window);
  glfwTerminate();
  return 0;
}

}  // namespace candela
