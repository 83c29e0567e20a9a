// `candela view`'s panel (Dear ImGui, when built with it): what the view renders and its
// controls, over the image's top-left corner; Tab hides and shows it.
#pragma once

#include <functional>
#include <string>

#include "app/view.hpp"

struct GLFWwindow;

namespace candela {

// What the panel shows and the window's actions its buttons take
struct PanelState {
  ViewSession* session = nullptr;
  const ViewFrame* shown = nullptr;  // the frame on screen (no pixels); nullptr before the first
  std::string saved;                 // the names the last save wrote
  bool visible = true;
  // The display transform the panel sets: automatic (--exposure or the metered one) or
  // `exposure` stops, and the tone map
  bool exposure_automatic = true;
  float exposure = 0.0f;
  int tonemap = 0;   // kTonemapNames index
  int strategy = 0;  // kStrategyNames index
  int max_depth = 16;
  int first_strategy = 0, first_max_depth = 16;  // as the options gave them
  // The options a reload applies (kDefaultLightNames index, degrees, variant index + 1
  // (0: the default), seconds) and the image shown (0: beauty, else an Aov bit)
  int default_light = 0;
  float env_rotation = 0.0f, anim_time = 0.0f;
  int variant = 0;
  bool anim_time_set = false;
  uint32_t image = 0;
  bool denoise = false;
  ViewSession::Offer offer;
  std::string device;
  bool ready = false;                  // panel_ready ran
  std::function<void(int key)> press;  // the key's action (P, S, F, R, C)
};

// Whether the panel is built in (Dear ImGui found)
bool panel_built_in();
// Before the window's callbacks run: ImGui takes them over and calls the window's after
void panel_init(GLFWwindow* window, PanelState* state);
// Once the scene is ready: the controls start from its options
void panel_ready(PanelState* state);
// Draws the panel over the frame (before the buffers swap): until ready, the status
void panel_draw(PanelState* state);
void panel_shutdown();
// Whether ImGui takes the mouse or the keyboard now (the camera leaves them alone)
bool panel_wants_mouse();
bool panel_wants_keyboard();

}  // namespace candela
