// The render settings: every option of `candela render`, each defined once in one table
// (settings.cpp). An entry holds the option's flag and --help text, its row in docs/cli.md,
// its default, the checks of its value, the RenderSettings it feeds (and through them the
// kernel argument or build option), and, for a setting the render records, its candela:KEY
// image metadata, its --stats key and whether `candela merge` requires it to match. The
// parser, the record of a render (report.hpp), merge's checks and the docs' option tables are
// generated from it; tests/app/settings_test.py keeps docs/cli.md, --help and real renders in
// step with it.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "app/render_command.hpp"
#include "render/renderer.hpp"

namespace candela {

// A recorded value: in the metadata a bool reads on|off and a number in decimal; in the
// stats JSON they are a JSON bool and number
using SettingValue = std::variant<bool, uint64_t, std::string>;

struct RenderSetting {
  using Add = std::function<CLI::Option*(CLI::App* render, RenderArgs& args, const RenderSetting& self)>;
  using Apply = std::function<void(const RenderArgs&, RenderSettings*)>;
  RenderSetting(std::string flags, std::string value_name, std::string help, std::string doc, std::string default_value,
                Add add, Apply apply = {})
      : flags(std::move(flags)),
        value_name(std::move(value_name)),
        help(std::move(help)),
        doc(std::move(doc)),
        default_value(std::move(default_value)),
        add(std::move(add)),
        apply(std::move(apply)) {}

  std::string flags;          // CLI11's names: "--filter", "-o,--output"; a positional's: "scene"
  std::string value_name;     // the value in docs/cli.md: "N", "box|tent|gaussian"; empty: a flag
  std::string help;           // the --help text
  std::string doc;            // its meaning in docs/cli.md (Markdown); empty: told in the next entry's row
  std::string default_value;  // its value when not given, as --help and the docs state it; empty: none
  // Adds the option to `render`, bound to its member of RenderArgs (or of RenderArgs::settings),
  // with the checks the parser makes of its value
  Add add;
  // Checks what the parser cannot (a name among an enum's) and sets what it feeds in the
  // settings; runs once parsed, before the scene loads. Unset: nothing to do.
  Apply apply;
  // The value a render records (from the args and the settings it rendered with); unset:
  // not recorded. Where: candela:`metadata` (nullptr: not), `stats` in the --stats JSON
  // (nullptr: not); `must_match`: `candela merge` merges only images that agree on it.
  std::function<SettingValue(const RenderArgs&, const RenderSettings&)> record;
  const char* metadata = nullptr;
  const char* stats = nullptr;
  bool must_match = false;
  // What it reaches in the kernel: "RenderParams.FIELD" (a field of dev::RenderParams, set in
  // host/render/renderer.cpp) or a build option's name ("CD_SAMPLER_SOBOL", "CD_FEATURE_*");
  // empty: none
  const char* kernel = "";
};

// Every render option, in --help order
const std::vector<RenderSetting>& render_settings();

// Adds every option of the table to `render`
void add_render_settings(CLI::App* render, RenderArgs* args);
// Runs every entry's apply on the parsed args
void apply_render_settings(const RenderArgs& args, RenderSettings* settings);

// The Markdown tables of docs/cli.md: "options" (every option and its meaning) and
// "record" (what a render records of each setting); Error for another name
std::string settings_markdown(const std::string& table);

// `candela help-options --markdown TABLE | --json` (hidden): the tables above, or the whole
// list with the record's other keys as JSON (for tests/app/settings_test.py)
struct HelpOptionsArgs {
  std::string markdown;
  bool json = false;
};
CLI::App* add_help_options_command(CLI::App* app, HelpOptionsArgs* args);
int run_help_options(const HelpOptionsArgs& args);

}  // namespace candela
