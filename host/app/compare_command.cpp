// `candela compare`: its options; compare.cpp runs the renders and the tests.
#include <sstream>

#include "app/commands.hpp"
#include "app/options.hpp"
#include "base/error.hpp"

namespace candela {

CLI::App* add_compare_command(CLI::App* app, CompareCommand* c) {
  CompareArgs& a = c->args;
  auto* cmd = app->add_subcommand(
      "compare",
      "Render a scene on several devices and test whether each agrees with the first within the measured noise "
      "(exit 0: consistent, 2: not); options it does not know are passed to every render");
  cmd->add_option("scene", a.scene, "Scene file (.gltf or .glb)")->required();
  cmd->add_option("--devices", c->devices,
                  "Comma-separated device selectors, the first is the reference; kept:DIR reads a render made "
                  "elsewhere from DIR (main.exr, main-variance.exr, main.json) instead of rendering")
      ->required();
  cmd->add_option("--spp", a.spp, "Samples per pixel on every device (default 64)")->check(integer_in(2, 1 << 24));
  cmd->add_option("--width", a.width, "Image width (default 64)")->check(integer_in(1, 65536));
  cmd->add_option("--height", a.height, "Image height (default from the camera's aspect ratio)")
      ->check(integer_in(1, 65536));
  cmd->add_option("--seed", a.seed, "Seed of the first device; device I renders seed + I (default 0)")
      ->check(integer_in(0, 4294967295LL));
  cmd->add_flag("--same-seed", a.same_seed,
                "Render the same seed on every device (correlated noise: the z-test no longer applies)");
  cmd->add_flag("!--no-determinism-check", a.determinism_check,
                "Skip the extra render of the first device's seed on the other devices");
  cmd->add_option(
      "--device-args", a.device_args,
      "I:OPTIONS: extra render options for the device at position I, e.g. '1:--strategy bsdf' (repeatable)");
  cmd->add_option("--json", a.json, "Also write the results as JSON to this file");
  cmd->add_option("--keep", a.keep, "Keep each device's image and variance image in this directory");
  cmd->add_flag("-q,--quiet", a.quiet, "No progress lines");
  cmd->allow_extras();
  return cmd;
}

int run_compare_command(CLI::App* cmd, CompareCommand* c) {
  std::stringstream ss(c->devices);
  for (std::string sel; std::getline(ss, sel, ',');) {
    if (sel.empty()) throw Error("--devices has an empty entry: '" + c->devices + "'");
    c->args.devices.push_back(sel);
  }
  c->args.render_options = cmd->remaining();
  return run_compare(c->args);
}

}  // namespace candela
