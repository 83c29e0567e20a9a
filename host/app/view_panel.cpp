// `candela view`'s panel (view_panel.hpp): Dear ImGui over GLFW and OpenGL 2.
#include "app/view_panel.hpp"

#ifdef CANDELA_WITH_IMGUI
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl2.h>
#include <imgui.h>

#include <algorithm>
#include <cstdio>
#endif

#include <iterator>

#include "app/options.hpp"
#include "render/aov.hpp"
#include "scene/default_light.hpp"

namespace candela {

void panel_ready(PanelState* state) {
  const RenderArgs& a = state->session->args();
  state->device = state->session->device();
  state->offer = state->session->offer();
  if (state->ready) return;  // a reload: the panel's values stand
  state->tonemap = int(parse_tonemap(a.tonemap));
  Strategy strategy = parse_enum(kStrategyNames, "--strategy", a.strategy);
  for (size_t i = 0; i < std::size(kStrategyNames); ++i)
    if (kStrategyNames[i].value == strategy) state->strategy = int(i);
  state->max_depth = int(a.settings.max_depth);
  for (size_t i = 0; i < std::size(kDefaultLightNames); ++i)
    if (a.default_light == kDefaultLightNames[i].name) state->default_light = int(i);
  state->env_rotation = a.env_rotation.value_or(0.0f);
  const std::vector<std::string>& variants = state->offer.variants;
  for (size_t i = 0; i < variants.size(); ++i)
    if (variants[i] == a.variant) state->variant = int(i) + 1;
  state->anim_time_set = a.anim_time.has_value();
  state->anim_time = float(a.anim_time.value_or(state->offer.anim_start));
  state->first_strategy = state->strategy;
  state->first_max_depth = state->max_depth;
  state->ready = true;
}

#ifndef CANDELA_WITH_IMGUI
bool panel_built_in() { return false; }
void panel_init(GLFWwindow*, PanelState*) {}
void panel_draw(PanelState*) {}
void panel_shutdown() {}
bool panel_wants_mouse() { return false; }
bool panel_wants_keyboard() { return false; }
#else
namespace {
bool g_started = false;
}  // namespace

bool panel_built_in() { return true; }

// The options that reload the scene (where it has them) and the image shown
void scene_controls(PanelState* p) {
  ViewSession& session = *p->session;
  const ViewSession::Offer& offer = p->offer;
  std::string status = session.status();
  if (!status.empty()) ImGui::TextUnformatted(status.c_str());
  const char* lights[std::size(kDefaultLightNames)];
  for (size_t i = 0; i < std::size(kDefaultLightNames); ++i) lights[i] = kDefaultLightNames[i].name;
  if (ImGui::Combo("default light", &p->default_light, lights, int(std::size(kDefaultLightNames)))) {
    std::string name = lights[p->default_light];
    session.reload([name](RenderArgs& a) { a.default_light = name; });
  }
  if (offer.environment) {
    ImGui::SliderFloat("environment rotation", &p->env_rotation, -180.0f, 180.0f, "%.0f deg");
    if (ImGui::IsItemDeactivatedAfterEdit()) {
      float degrees = p->env_rotation;
      session.reload([degrees](RenderArgs& a) { a.env_rotation = degrees; });
    }
  }
  if (!offer.variants.empty()) {
    std::vector<const char*> names = {"(default)"};
    for (const std::string& v : offer.variants) names.push_back(v.c_str());
    if (ImGui::Combo("variant", &p->variant, names.data(), int(names.size()))) {
      std::string name = p->variant > 0 ? offer.variants[size_t(p->variant - 1)] : "";
      session.reload([name](RenderArgs& a) { a.variant = name; });
    }
  }
  if (offer.animated) {
    ImGui::SliderFloat("animation time", &p->anim_time, float(offer.anim_start), float(offer.anim_end), "%.3f s");
    if (ImGui::IsItemDeactivatedAfterEdit()) {
      double t = p->anim_time;
      p->anim_time_set = true;
      session.reload([t](RenderArgs& a) { a.anim_time = t; });
    }
  }
  std::vector<const char*> images = {"beauty"};
  std::vector<uint32_t> bits = {0};
  for (const auto& n : kAovNames)
    if (offer.aovs & aov_bit(n.value)) {
      images.push_back(n.name);
      bits.push_back(aov_bit(n.value));
    }
  images.push_back("variance");
  bits.push_back(kVarianceImage);
  int index = int(std::find(bits.begin(), bits.end(), uint32_t(p->image)) - bits.begin());
  bool changed = false;
  if (ImGui::Combo("image (V)", &index, images.data(), int(images.size()))) {
    p->image = bits[size_t(index)];
    changed = true;
  }
  if (offer.denoiser) changed |= ImGui::Checkbox("denoise when still", &p->denoise);
  if (changed) session.set_image(p->image, p->denoise);
}

void panel_init(GLFWwindow* window, PanelState*) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini beside the user's files
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL2_Init();
  g_started = true;
}

void panel_shutdown() {
  if (!g_started) return;
  ImGui_ImplOpenGL2_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  g_started = false;
}

bool panel_wants_mouse() { return g_started && ImGui::GetIO().WantCaptureMouse; }
bool panel_wants_keyboard() { return g_started && ImGui::GetIO().WantCaptureKeyboard; }

void panel_draw(PanelState* p) {
  ImGui_ImplOpenGL2_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  ViewSession& session = *p->session;
  if (!p->ready) {  // loading, compiling: what it waits for
    std::string status = session.status();
    ImGui::SetNextWindowPos(ImVec2(4, 4), ImGuiCond_Always);
    ImGui::Begin("candela view", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
    ImGui::TextUnformatted(status.empty() ? "starting" : status.c_str());
    ImGui::End();
  } else if (p->visible) {
    ImGui::SetNextWindowPos(ImVec2(4, 4), ImGuiCond_Once);
    ImGui::SetNextWindowBgAlpha(0.75f);
    ImGui::Begin("candela view (Tab hides)", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
    if (p->shown) {
      ImGui::Text("%u spp%s, %.2f Msamples/s", p->shown->spp, p->shown->preview ? " (preview)" : "",
                  p->shown->samples_per_second * 1e-6);
    }
    const RenderArgs& a = session.args();
    ImGui::Text("%s", p->device.c_str());
    const char* strategies[std::size(kStrategyNames)];
    for (size_t i = 0; i < std::size(kStrategyNames); ++i) strategies[i] = kStrategyNames[i].name;
    bool kernel = ImGui::Combo("strategy", &p->strategy, strategies, int(std::size(kStrategyNames)));
    kernel |= ImGui::SliderInt("max depth", &p->max_depth, 0, 64);
    if (kernel) session.set_kernel(kStrategyNames[p->strategy].value, uint32_t(std::max(p->max_depth, 0)));
    bool changed = ImGui::Checkbox("automatic exposure", &p->exposure_automatic);
    if (p->exposure_automatic) {
      p->exposure = session.exposure();
    } else {
      changed |= ImGui::SliderFloat("exposure (EV)", &p->exposure, -10.0f, 10.0f, "%.1f");
    }
    const char* names[std::size(kTonemapNames)];
    for (size_t i = 0; i < std::size(kTonemapNames); ++i) names[i] = kTonemapNames[i].name;
    changed |= ImGui::Combo("tone map", &p->tonemap, names, int(std::size(kTonemapNames)));
    if (changed)
      session.set_display(p->exposure_automatic ? a.exposure : std::optional<float>(p->exposure), Tonemap(p->tonemap));
    scene_controls(p);
    if (ImGui::Button("Frame all (F)")) p->press('F');
    ImGui::SameLine();
    if (ImGui::Button("Reset (R)")) p->press('R');
    ImGui::SameLine();
    if (ImGui::Button("Next camera (C)")) p->press('C');
    if (ImGui::Button("Print camera (P)")) p->press('P');
    ImGui::SameLine();
    if (ImGui::Button("Save PNG + EXR (S)")) p->press('S');
    if (p->shown) {
      ImGui::PushTextWrapPos(360.0f);
      ImGui::TextUnformatted(p->shown->camera.c_str());
      ImGui::PopTextWrapPos();
    }
    if (!p->saved.empty()) ImGui::Text("saved %s", p->saved.c_str());
    ImGui::End();
  }
  ImGui::Render();
  ImGui_ImplOpenGL2_RenderDrawData(ImGui::GetDrawData());
}
#endif

}  // namespace candela
