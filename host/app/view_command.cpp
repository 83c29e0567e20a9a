// `candela view`: its options (render's), and without GLFW the one line that says so.
#include "app/settings.hpp"
#include "app/view.hpp"
#include "base/error.hpp"

namespace candela {

CLI::App* add_view_command(CLI::App* app, RenderArgs* args) {
  auto* view = app->add_subcommand(
      "view",
      "Render a glTF scene progressively in a window, the camera under the mouse (render's options; keys: "
      "docs/cli.md, candela view)");
  add_render_settings(view, args);
  // -o OUT.png: where the save key writes (OUT-0001.png and .exr), not required here
  view->get_option("--output")->required(false);
  return view;
}

#ifndef CANDELA_WITH_VIEW
bool view_built_in() { return false; }

int run_view(RenderArgs) {
  throw Error(
      "this candela was built without GLFW and OpenGL (Debian: libglfw3-dev), so it has no window: candela view is "
      "unavailable (candela render works)");
}
#endif

}  // namespace candela
