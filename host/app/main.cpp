// The candela executable: the CLI11 app, its subcommands, and the one `candela: error:` handler.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "app/commands.hpp"
#include "app/options.hpp"
#include "app/render_command.hpp"
#include "app/settings.hpp"
#include "app/view.hpp"
#include "base/error.hpp"
#include "device/device.hpp"
#include "device/kernel_sources.hpp"

namespace {

using namespace candela;

// Mesa's rusticl exposes its CPU device only when asked, before the ICD loader starts
void enable_rusticl_if_named(const std::string& device) {
  std::string wanted = lowercase(device);
  if ((wanted.find("rusticl") != std::string::npos || wanted.find("llvmpipe") != std::string::npos) &&
      !std::getenv("RUSTICL_ENABLE"))
    setenv("RUSTICL_ENABLE", "llvmpipe", 0);
}

// Intel's OpenCL CPU runtime where scripts/setup.sh installs it, beside the executable
void add_intel_runtime_beside_executable() {
  std::error_code ec;
  std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) add_installed_intel_runtime((exe.parent_path() / "intel-opencl").string());
}

int fail(const std::string& message) {
  std::fprintf(stderr, "candela: error: %s\n", message.c_str());
  return 1;
}

// A command-line parser message as one line: the parser's text with its line breaks
// folded, then where to look
std::string parse_error_message(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text + " (see --help)";
}

// The subcommand asked for, its exceptions turned into `candela: error:` lines
template <typename Run>
int run_reporting_errors(Run run) {
  try {
    return run();
  } catch (const Error& e) {
    return fail(e.what());
  } catch (const cl::Error& e) {
    return fail(cl_error_message(e.what(), e.err()));
  } catch (const std::exception& e) {
    return fail(e.what());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"candela: a physically based path tracer running on OpenCL devices"};
  app.set_version_flag("--version", "candela " CANDELA_VERSION);
  app.require_subcommand(1);
  std::string kernel_dir;
  app.add_option("--kernel-dir", kernel_dir,
                 "Load kernel sources from this cl/ directory instead of the embedded copy "
                 "(also: CANDELA_KERNEL_DIR)");
  CLI::App* devices_cmd = add_devices_command(&app);
  RenderArgs render_args;
  add_render_command(&app, &render_args);
  RenderArgs view_args;
  CLI::App* view_cmd = add_view_command(&app, &view_args);
  CompareCommand compare;
  CLI::App* compare_cmd = add_compare_command(&app, &compare);
  MergeArgs merge_args;
  CLI::App* merge_cmd = add_merge_command(&app, &merge_args);
  InfoArgs info_args;
  CLI::App* info_cmd = add_info_command(&app, &info_args);
  HelpOptionsArgs help_options_args;
  CLI::App* help_options_cmd = add_help_options_command(&app, &help_options_args);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return fail(parse_error_message(e.what()));
  }
  enable_rusticl_if_named(*view_cmd ? view_args.device : render_args.device);
  add_intel_runtime_beside_executable();
  return run_reporting_errors([&] {
    if (!kernel_dir.empty()) set_kernel_source_root(kernel_dir);
    if (*devices_cmd) return run_devices_command();
    if (*compare_cmd) return run_compare_command(compare_cmd, &compare);
    if (*merge_cmd) return run_merge(merge_args);
    if (*info_cmd) return run_info_command(info_args);
    if (*help_options_cmd) return run_help_options(help_options_args);
    if (*view_cmd) return run_view(view_args);
    return run_render_command(render_args);
  });
}
