// The subcommands besides `render` (render_command.hpp): each adds itself to the app with
// its options, and runs once parsed.
#pragma once

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "app/compare.hpp"
#include "app/merge.hpp"

namespace candela {

// `candela devices`: the OpenCL platforms and devices
CLI::App* add_devices_command(CLI::App* app);
int run_devices_command();

// `candela compare` (compare.hpp)
struct CompareCommand {
  CompareArgs args;
  std::string devices;  // --devices, comma-separated
};
CLI::App* add_compare_command(CLI::App* app, CompareCommand* c);
int run_compare_command(CLI::App* cmd, CompareCommand* c);

// `candela info SCENE`: what the scene holds as candela reads it
struct InfoArgs {
  std::string scene;
  bool allow_outside_paths = false;
  std::optional<double> anim_time;  // --anim-time: the scene as posed then (geometry, cameras, lights)
  std::string animation;            // --animation N|NAME
};
CLI::App* add_info_command(CLI::App* app, InfoArgs* args);
int run_info_command(const InfoArgs& args);

// `candela merge` (merge.hpp; run_merge runs it)
CLI::App* add_merge_command(CLI::App* app, MergeArgs* m);

}  // namespace candela
