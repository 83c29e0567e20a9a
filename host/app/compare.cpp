// `candela compare` (compare.hpp): child renders per device and the z-tests between their images.
#include "app/compare.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "base/error.hpp"
#include "render/image_stats.hpp"

namespace fs = std::filesystem;

namespace candela {

std::string self_executable() {
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error("cannot find the candela executable (/proc/self/exe): " + ec.message());
  return p.string();
}

namespace {

struct Child {
  int status = -1;       // exit status, or 128 + signal
  double seconds = 0.0;  // wall clock, process start to exit
  std::string log;       // its stdout and stderr
};

// Runs argv[0] with argv and the extra environment, its output into log_path
Child run_child(const std::vector<std::string>& argv, const std::vector<std::pair<std::string, std::string>>& env,
                const std::string& log_path) {
  auto start = std::chrono::steady_clock::now();
  std::fflush(nullptr);
  pid_t pid = fork();
  if (pid < 0) throw Error("cannot start a child render: fork failed");
  if (pid == 0) {
    for (const auto& [k, v] : env) setenv(k.c_str(), v.c_str(), 1);
    int fd = open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) {
      dup2(fd, STDOUT_FILENO);
      dup2(fd, STDERR_FILENO);
      close(fd);
    }
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    std::fprintf(stderr, "candela: error: cannot run %s\n", args[0]);
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw Error("waiting for a child render failed");
  }
  Child c;
  c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  c.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  std::ifstream f(log_path);
  std::stringstream ss;
  ss << f.rdbuf();
  c.log = ss.str();
  return c;
}

std::vector<std::string> split_words(const std::string& text) {
  std::istringstream ss(text);
  std::vector<std::string> words;
  for (std::string w; ss >> w;) words.push_back(w);
  return words;
}

// The child's "candela: error: ..." message (with the lines after it) without the prefix,
// else its output less CLI11's "Run with --help" hint
std::string child_error(const Child& c) {
  std::istringstream ss(c.log);
  std::string line, message, other;
  const std::string prefix = "candela: error: ";
  bool in_error = false;
  while (std::getline(ss, line)) {
    if (line.rfind(prefix, 0) == 0) {
      in_error = true;
      message = line.substr(prefix.size());
    } else if (in_error) {
      message += "\n" + line;
    } else if (!line.empty() && line.rfind("Run with --help", 0) != 0) {
      other += (other.empty() ? "" : "; ") + line;
    }
  }
  if (in_error) return message;
  return "the render failed (exit status " + std::to_string(c.status) + ")" + (other.empty() ? "" : ": " + other);
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream f(path);
  nlohmann::json j;
  try {
    f >> j;
  } catch (const std::exception& e) {
    throw Error("cannot read render statistics " + path + ": " + e.what());
  }
  return j;
}

struct DeviceRun {
  std::string selector, description;
  uint32_t seed = 0;
  std::vector<std::string> extra;  // --device-args
  double build_cold = 0.0, build_cached = 0.0, cold_start = 0.0;
  bool cached_hit = false;
  double render_seconds = 0.0, samples_per_second = 0.0;
  uint32_t spp = 0;
  RgbImage image, variance, same_seed_image;
  bool has_same_seed = false;
};

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

nlohmann::json ztest_json(const ZTest& t) {
  return {{"values", t.values},
          {"mean_z", t.mean_z},
          {"mean_z2", t.mean_z2},
          {"frac_abs_z_over_3", t.frac_over_3},
          {"frac_abs_z_over_4", t.frac_over_4},
          {"count_abs_z_over_4", t.count_over_4},
          {"max_abs_z", t.max_abs_z},
          {"zero_variance", t.zero_variance},
          {"zero_variance_mismatch", t.zero_variance_mismatch},
          {"undefined", t.undefined},
          {"consistent", t.consistent},
          {"reasons", t.reasons}};
}

// One run per device: its selector and seed (seed + position unless --same-seed)
std::vector<DeviceRun> plan_runs(const CompareArgs& args) {
  std::vector<DeviceRun> runs(args.devices.size());
  for (size_t i = 0; i < runs.size(); ++i) {
    runs[i].selector = args.devices[i];
    runs[i].seed = args.same_seed ? args.seed : args.seed + uint32_t(i);
  }
  return runs;
}

// --device-args I:OPTIONS: each device's extra render options, none of them also given to
// every render
void add_device_args(const CompareArgs& args, std::vector<DeviceRun>* runs) {
  for (const std::string& spec : args.device_args) {
    size_t colon = spec.find(':');
    char* end = nullptr;
    unsigned long index = colon == std::string::npos ? 0 : std::strtoul(spec.c_str(), &end, 10);
    if (colon == std::string::npos || colon == 0 || end != spec.c_str() + colon || index >= runs->size())
      throw Error("--device-args expects I:OPTIONS with I a device position from 0 to " +
                  std::to_string(runs->size() - 1) + ", got '" + spec + "'");
    auto words = split_words(spec.substr(colon + 1));
    for (const auto& w : words) {
      std::string name = w.substr(0, w.find('='));
      if (name.size() > 1 && name[0] == '-' &&
          std::find_if(args.render_options.begin(), args.render_options.end(), [&](const std::string& o) {
            return o.substr(0, o.find('=')) == name;
          }) != args.render_options.end())
        throw Error("--device-args gives " + name + ", which is also given to every render: give it per device only");
    }
    (*runs)[index].extra.insert((*runs)[index].extra.end(), words.begin(), words.end());
  }
}

// Mesa's rusticl shows its CPU device only when asked (children inherit this)
void enable_rusticl_if_named(const std::vector<std::string>& devices) {
  for (const auto& sel : devices) {
    std::string s = sel;
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (s.find("rusticl") != std::string::npos || s.find("llvmpipe") != std::string::npos)
      setenv("RUSTICL_ENABLE", "llvmpipe", 0);
  }
}

// The child renders of one device, in its own folder with its own empty caches
class DeviceRenders {
 public:
  DeviceRenders(const CompareArgs& args, const std::string& exe, const DeviceRun& run, const fs::path& dir)
      : args_(args), exe_(exe), run_(run), dir_(dir) {
    // Every cache of candela and of the OpenCL implementations starts empty for this device:
    // the first (1 spp) render builds cold, the next ones load what it cached
    env_ = {{"CANDELA_CACHE_DIR", (dir / "cache/candela").string()},
            {"POCL_CACHE_DIR", (dir / "cache/pocl").string()},
            {"MESA_SHADER_CACHE_DIR", (dir / "cache/mesa").string()},
            {"XDG_CACHE_HOME", (dir / "cache/xdg").string()}};
  }

  // `candela render` into DIR/NAME.exr (and its variance with `outputs`) and DIR/NAME.json
  Child render(const std::string& name, uint32_t spp, uint32_t seed, bool outputs) const {
    std::vector<std::string> v = {exe_,
                                  "render",
                                  args_.scene,
                                  "-o",
                                  (dir_ / (name + ".exr")).string(),
                                  "--stats",
                                  (dir_ / (name + ".json")).string(),
                                  "--spp",
                                  std::to_string(spp),
                                  "--width",
                                  std::to_string(args_.width),
                                  "--seed",
                                  std::to_string(seed),
                                  "--device",
                                  run_.selector,
                                  "-q"};
    if (args_.height > 0) v.insert(v.end(), {"--height", std::to_string(args_.height)});
    if (outputs) v.insert(v.end(), {"--variance", (dir_ / (name + "-variance.exr")).string()});
    v.insert(v.end(), args_.render_options.begin(), args_.render_options.end());
    v.insert(v.end(), run_.extra.begin(), run_.extra.end());
    Child c = run_child(v, env_, (dir_ / (name + ".log")).string());
    if (c.status != 0) throw Error("device '" + run_.selector + "': " + child_error(c));
    return c;
  }

 private:
  const CompareArgs& args_;
  const std::string& exe_;
  const DeviceRun& run_;
  fs::path dir_;
  std::vector<std::pair<std::string, std::string>> env_;
};

// The measured render in DIR: its statistics (main.json, read into `stats`), its image and
// its variance image
void take_main_render(const nlohmann::json& stats, const fs::path& dir, DeviceRun* r) {
  r->build_cached = stats.value("kernel_build_seconds", 0.0);
  r->cached_hit = stats.value("kernel_from_cache", false);
  r->render_seconds = stats.value("seconds", 0.0);
  r->samples_per_second = stats.value("samples_per_second", 0.0);
  r->spp = stats.value("spp", 0u);
  r->image = read_rgb_image((dir / "main.exr").string(), "render");
  r->variance = read_rgb_image((dir / "main-variance.exr").string(), "variance image");
}

// A 1 spp render that builds the kernel cold, then the measured one with its variance
void render_cold_and_main(const CompareArgs& args, const DeviceRenders& renders, const fs::path& dir, DeviceRun* r) {
  if (!args.quiet) std::fprintf(stderr, "compare: %s: cold kernel build...\n", r->selector.c_str());
  Child cold = renders.render("cold", 1, r->seed, false);
  nlohmann::json cold_stats = read_json((dir / "cold.json").string());
  r->build_cold = cold_stats.value("kernel_build_seconds", 0.0);
  r->cold_start = cold.seconds;
  r->description = cold_stats.value("device", r->selector);
  if (!args.quiet)
    std::fprintf(stderr, "compare: %s: %u spp with seed %u...\n", r->selector.c_str(), args.spp, r->seed);
  renders.render("main", args.spp, r->seed, true);
  take_main_render(read_json((dir / "main.json").string()), dir, r);
}

// The determinism check: the first device's seed rendered on another device
void render_same_seed(const CompareArgs& args, const DeviceRenders& renders, const fs::path& dir,
                      const DeviceRun& first, DeviceRun* r) {
  if (r->seed == first.seed) {
    r->same_seed_image = r->image;
    r->has_same_seed = true;
    return;
  }
  if (!args.quiet)
    std::fprintf(stderr, "compare: %s: %u spp with seed %u (determinism check)...\n", r->selector.c_str(), args.spp,
                 first.seed);
  renders.render("same-seed", args.spp, first.seed, false);
  r->same_seed_image = read_rgb_image((dir / "same-seed.exr").string(), "render");
  r->has_same_seed = true;
}

// --keep: the device's images, copied out of the temporary folder
void keep_images(const CompareArgs& args, const fs::path& dir, size_t i) {
  if (args.keep.empty()) return;
  fs::create_directories(args.keep);
  for (const char* name : {"main.exr", "main-variance.exr", "same-seed.exr"})
    if (fs::exists(dir / name))
      fs::copy_file(dir / name, fs::path(args.keep) / ("device" + std::to_string(i) + "-" + name),
                    fs::copy_options::overwrite_existing);
}

// A device entry `kept:DIR`: a render made earlier, on a machine this one may not reach
// (scripts/gpu/check.sh writes them), read from DIR: main.exr, main-variance.exr and main.json,
// and cold.json and same-seed.exr where there. Its size, spp and seed must be the ones this
// comparison plans for that position.
bool is_kept(const DeviceRun& r) { return r.selector.rfind("kept:", 0) == 0; }

void read_kept(const CompareArgs& args, const DeviceRun& first, size_t i, DeviceRun* r) {
  const fs::path dir = r->selector.substr(5);
  auto file = [&](const char* name) {
    fs::path p = dir / name;
    if (!fs::is_regular_file(p)) throw Error("kept render " + dir.string() + " has no " + name);
    return p.string();
  };
  nlohmann::json stats = read_json(file("main.json"));
  auto mismatch = [&](const char* what, int64_t kept, int64_t planned) {
    if (kept != planned)
      throw Error("kept render " + dir.string() + " has " + what + " " + std::to_string(kept) + ", this comparison " +
                  std::to_string(planned) + " (device " + std::to_string(i) + " renders seed --seed + " +
                  std::to_string(i) + ")");
  };
  mismatch("seed", stats.value("seed", int64_t(-1)), r->seed);
  mismatch("spp", stats.value("spp", int64_t(-1)), args.spp);
  mismatch("width", stats.value("width", int64_t(-1)), args.width);
  if (args.height > 0) mismatch("height", stats.value("height", int64_t(-1)), args.height);
  r->description = stats.value("device", r->selector);
  if (fs::is_regular_file(dir / "cold.json"))
    r->build_cold = read_json((dir / "cold.json").string()).value("kernel_build_seconds", 0.0);
  file("main.exr");
  file("main-variance.exr");
  take_main_render(stats, dir, r);
  if (i > 0 && args.determinism_check && fs::is_regular_file(dir / "same-seed.exr")) {
    r->same_seed_image = r->seed == first.seed ? r->image : read_rgb_image((dir / "same-seed.exr").string(), "render");
    r->has_same_seed = true;
  }
}

void render_devices(const CompareArgs& args, const fs::path& tmp, std::vector<DeviceRun>* runs) {
  const std::string exe = self_executable();
  for (size_t i = 0; i < runs->size(); ++i) {
    DeviceRun& r = (*runs)[i];
    if (is_kept(r)) {
      read_kept(args, (*runs)[0], i, &r);
      continue;
    }
    fs::path dir = tmp / ("device" + std::to_string(i));
    fs::create_directories(dir);
    DeviceRenders renders(args, exe, r, dir);
    render_cold_and_main(args, renders, dir, &r);
    if (i > 0 && args.determinism_check) render_same_seed(args, renders, dir, (*runs)[0], &r);
    keep_images(args, dir, i);
  }
}

// The results table, its notes and the verdict, as printed and as JSON
struct Comparison {
  nlohmann::json devices = nlohmann::json::array();
  std::vector<std::string> notes;
  bool consistent = true;
};

nlohmann::json run_json(const DeviceRun& r) {
  return {{"selector", r.selector},
          {"device", r.description},
          {"seed", r.seed},
          {"spp", r.spp},
          {"render_options", r.extra},
          {"kernel_build_cold_seconds", r.build_cold},
          {"cold_start_seconds", r.cold_start},
          {"kernel_build_cached_seconds", r.build_cached},
          {"kernel_from_cache", r.cached_hit},
          {"render_seconds", r.render_seconds},
          {"samples_per_second", r.samples_per_second}};
}

void print_table_header(const CompareArgs& args, const DeviceRun& ref) {
  std::printf("compare %s: %dx%d, %u spp, %s\n", args.scene.c_str(), ref.image.width, ref.image.height, ref.spp,
              args.same_seed ? "the same seed on every device (the z-test assumes independent noise: see README)"
                             : "an independent seed per device (seed + position)");
  std::printf("%-3s %-40s %5s %10s %12s %9s %11s %10s %9s %8s %8s  %s\n", "#", "device", "seed", "build cold",
              "build cached", "render s", "Msamples/s", "relMSE", "mean z^2", "|z|>3", "|z|>4", "verdict");
}

// The determinism note and JSON of a device that rendered the first device's seed
void add_same_seed_result(const DeviceRun& ref, const DeviceRun& r, nlohmann::json* jd, Comparison* c) {
  SameSeedDiff d = same_seed_diff(ref.image, r.same_seed_image);
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "determinism, seed %u on %s against %s: max |a-b| %.3g, max relative %.3g, %.1f%% bit-identical",
                ref.seed, r.selector.c_str(), ref.selector.c_str(), d.max_abs, d.max_rel, 100 * d.identical_fraction);
  c->notes.push_back(buf);
  (*jd)["same_seed"] = {{"seed", ref.seed},
                        {"max_abs_diff", d.max_abs},
                        {"max_rel_diff", d.max_rel},
                        {"identical_fraction", d.identical_fraction}};
}

// Device i's row: against the first device, the error and the z-test of the difference
void compare_device(const CompareArgs& args, const DeviceRun& ref, const DeviceRun& r, size_t i, Comparison* c) {
  std::string desc = r.selector + ": " + r.description;
  if (desc.size() > 40) desc = desc.substr(0, 37) + "...";
  nlohmann::json jd = run_json(r);
  std::string cached = fmt("%.3fs", r.build_cached) + (r.cached_hit ? "" : "*");
  if (!r.cached_hit) c->notes.push_back("* " + r.selector + ": the second build did not come from the cache");
  if (i == 0) {
    std::printf("%-3zu %-40s %5u %9.3fs %12s %9.3f %11.3f %10s %9s %8s %8s  %s\n", i, desc.c_str(), r.seed,
                r.build_cold, cached.c_str(), r.render_seconds, r.samples_per_second * 1e-6, "-", "-", "-", "-",
                "reference");
    c->devices.push_back(jd);
    return;
  }
  if (r.spp != ref.spp)
    throw Error("device '" + r.selector + "' rendered " + std::to_string(r.spp) + " spp, not " +
                std::to_string(ref.spp));
  ErrorMetrics err = image_error(r.image, ref.image);
  ZTest t = z_test(ref.image, ref.variance, r.image, r.variance);
  c->consistent = c->consistent && t.consistent;
  std::printf("%-3zu %-40s %5u %9.3fs %12s %9.3f %11.3f %10.3g %9.3f %7.3f%% %7.3f%%  %s\n", i, desc.c_str(), r.seed,
              r.build_cold, cached.c_str(), r.render_seconds, r.samples_per_second * 1e-6, err.rel_mse, t.mean_z2,
              100 * t.frac_over_3, 100 * t.frac_over_4, t.consistent ? "statistically consistent" : "NOT consistent");
  for (const auto& why : t.reasons) c->notes.push_back(std::to_string(i) + " " + r.selector + ": " + why);
  jd["against_first"] = {{"rel_mse", err.rel_mse}, {"mse", err.mse}, {"mae", err.mae}, {"z_test", ztest_json(t)}};
  if (args.same_seed)
    c->notes.push_back(std::to_string(i) + " " + r.selector +
                       ": same seed: the z-test's independence assumption does not hold");
  if (r.has_same_seed) add_same_seed_result(ref, r, &jd, c);
  c->devices.push_back(jd);
}

void write_comparison_json(const CompareArgs& args, const DeviceRun& ref, const Comparison& c) {
  ZTestRule rule;
  nlohmann::json j = {
      {"scene", args.scene},         {"width", ref.image.width},
      {"height", ref.image.height},  {"spp", ref.spp},
      {"same_seed", args.same_seed}, {"render_options", args.render_options},
      {"devices", c.devices},        {"rule", {{"z2_slack", rule.z2_slack}, {"tail_allowance", rule.tail_allowance}}},
      {"consistent", c.consistent}};
  std::ofstream f(args.json);
  if (!(f << j.dump(2) << "\n")) throw Error("cannot write " + args.json);
}

// A temporary folder, removed with everything in it
struct TempDir {
  fs::path dir;
  explicit TempDir(fs::path d) : dir(std::move(d)) { fs::create_directories(dir); }
  ~TempDir() {
    std::error_code e;
    fs::remove_all(dir, e);
  }
};

}  // namespace

int run_compare(const CompareArgs& args) {
  if (args.devices.size() < 2) throw Error("compare needs at least two devices: --devices SEL,SEL");
  if (args.spp < 2) throw Error("compare needs --spp of at least 2 (the z-test needs each pixel's variance)");
  std::error_code ec;
  if (!fs::is_regular_file(args.scene, ec)) throw Error("scene file not found: " + args.scene);
  std::vector<DeviceRun> runs = plan_runs(args);
  add_device_args(args, &runs);
  enable_rusticl_if_named(args.devices);
  TempDir tmp(fs::temp_directory_path() / ("candela-compare-" + std::to_string(getpid())));
  render_devices(args, tmp.dir, &runs);
  const DeviceRun& ref = runs[0];
  print_table_header(args, ref);
  Comparison c;
  for (size_t i = 0; i < runs.size(); ++i) compare_device(args, ref, runs[i], i, &c);
  for (const auto& n : c.notes) std::printf("  %s\n", n.c_str());
  std::printf("verdict: %s\n", c.consistent ? "statistically consistent" : "NOT consistent");
  if (!args.json.empty()) write_comparison_json(args, ref, c);
  return c.consistent ? 0 : 2;
}

}  // namespace candela
