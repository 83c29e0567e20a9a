#include "render/denoise.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <chrono>
#include <climits>
#include <cstddef>
#include <cstdlib>
#include <filesystem>

#include "base/error.hpp"

namespace candela {
namespace {

// The part of OIDN 2's C API that candela calls, as its documentation describes it: opaque
// handles, and the enum values used here
using Device = void*;
using Filter = void*;
using Buffer = void*;
constexpr int kDeviceDefault = 0, kDeviceCpu = 1;  // OIDNDeviceType
constexpr int kFormatFloat3 = 3;                   // OIDNFormat
constexpr int kErrorNone = 0;                      // OIDNError

struct Api {
  void* handle = nullptr;
  Device (*new_device)(int type) = nullptr;
  void (*commit_device)(Device) = nullptr;
  void (*release_device)(Device) = nullptr;
  int (*get_device_error)(Device, const char** message) = nullptr;
  int (*get_device_int)(Device, const char* name) = nullptr;
  Buffer (*new_buffer)(Device, size_t bytes) = nullptr;
  void (*release_buffer)(Buffer) = nullptr;
  void (*write_buffer)(Buffer, size_t offset, size_t bytes, const void* source) = nullptr;
  void (*read_buffer)(Buffer, size_t offset, size_t bytes, void* destination) = nullptr;
  Filter (*new_filter)(Device, const char* type) = nullptr;
  void (*release_filter)(Filter) = nullptr;
  void (*set_filter_image)(Filter, const char* name, Buffer, int format, size_t width, size_t height,
                           size_t byte_offset, size_t pixel_stride, size_t row_stride) = nullptr;
  void (*set_filter_bool)(Filter, const char* name, bool value) = nullptr;
  void (*set_filter_int)(Filter, const char* name, int value) = nullptr;
  void (*commit_filter)(Filter) = nullptr;
  void (*execute_filter)(Filter) = nullptr;
};

std::string executable_folder() {
  char path[PATH_MAX];
  ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return "";
  path[n] = '\0';
  return std::filesystem::path(path).parent_path().string();
}

Error missing(const std::string& why) {
  return Error("--denoise needs Open Image Denoise: " + why + " (run scripts/setup.sh)");
}

// The first line of dlerror()'s message
std::string load_error() {
  const char* e = dlerror();
  std::string text = e ? e : "unknown error";
  return text.substr(0, text.find('\n'));
}

template <typename F>
void bind(Api& api, F* slot, const char* name, const std::string& path) {
  void* symbol = dlsym(api.handle, name);
  if (!symbol) throw missing(path + " has no " + name + " (not Open Image Denoise 2)");
  *slot = reinterpret_cast<F>(symbol);
}

Api load_api() {
  Api api;
  std::string path;
  if (const char* env = std::getenv("CANDELA_OIDN_LIBRARY")) {
    path = env;
    api.handle = dlopen(env, RTLD_NOW | RTLD_LOCAL);
    if (!api.handle) throw missing("CANDELA_OIDN_LIBRARY=" + path + " cannot be loaded: " + load_error());
  } else {
    std::string beside = executable_folder() + "/oidn/lib/libOpenImageDenoise.so.2";
    std::error_code ec;
    if (std::filesystem::exists(beside, ec)) {
      path = beside;
      api.handle = dlopen(beside.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!api.handle) throw missing(beside + " cannot be loaded: " + load_error());
    } else {
      path = "libOpenImageDenoise.so.2";
      api.handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
      if (!api.handle)
        throw missing("libOpenImageDenoise.so.2 is neither in " + std::filesystem::path(beside).parent_path().string() +
                      " nor on the system loader's path");
    }
  }
  bind(api, &api.new_device, "oidnNewDevice", path);
  bind(api, &api.commit_device, "oidnCommitDevice", path);
  bind(api, &api.release_device, "oidnReleaseDevice", path);
  bind(api, &api.get_device_error, "oidnGetDeviceError", path);
  bind(api, &api.get_device_int, "oidnGetDeviceInt", path);
  bind(api, &api.new_buffer, "oidnNewBuffer", path);
  bind(api, &api.release_buffer, "oidnReleaseBuffer", path);
  bind(api, &api.write_buffer, "oidnWriteBuffer", path);
  bind(api, &api.read_buffer, "oidnReadBuffer", path);
  bind(api, &api.new_filter, "oidnNewFilter", path);
  bind(api, &api.release_filter, "oidnReleaseFilter", path);
  bind(api, &api.set_filter_image, "oidnSetFilterImage", path);
  bind(api, &api.set_filter_bool, "oidnSetFilterBool", path);
  bind(api, &api.set_filter_int, "oidnSetFilterInt", path);
  bind(api, &api.commit_filter, "oidnCommitFilter", path);
  bind(api, &api.execute_filter, "oidnExecuteFilter", path);
  return api;
}

const Api& api() {
  static const Api loaded = load_api();  // a throw leaves it to be tried again
  return loaded;
}

// Throws Error with OIDN's message when the device holds an error
void check(const Api& oidn, Device device, const char* what) {
  const char* message = nullptr;
  if (oidn.get_device_error(device, &message) != kErrorNone)
    throw Error(std::string("denoising failed (") + what + "): " + (message ? message : "no message"));
}

// Releases the device, filters and buffers however the denoise ends
struct Session {
  const Api& oidn;
  Device device = nullptr;
  std::vector<Buffer> buffers;
  std::vector<Filter> filters;
  explicit Session(const Api& a) : oidn(a) {}
  ~Session() {
    for (Filter f : filters) oidn.release_filter(f);
    for (Buffer b : buffers) oidn.release_buffer(b);
    if (device) oidn.release_device(device);
  }
  Buffer buffer(const std::vector<float>& values) {
    Buffer b = oidn.new_buffer(device, values.size() * sizeof(float));
    check(oidn, device, "buffer");
    buffers.push_back(b);
    oidn.write_buffer(b, 0, values.size() * sizeof(float), values.data());
    return b;
  }
  Filter filter() {
    Filter f = oidn.new_filter(device, "RT");
    check(oidn, device, "RT filter");
    filters.push_back(f);
    return f;
  }
};

const char* device_name(int type) {
  switch (type) {
    case 1:
      return "CPU";
    case 2:
      return "SYCL";
    case 3:
      return "CUDA";
    case 4:
      return "HIP";
    case 5:
      return "Metal";
    default:
      return "?";
  }
}

}  // namespace

void load_denoiser() { api(); }

DenoiseResult denoise_film(const Film& film, DenoiseQuality quality, bool prefer_gpu) {
  const Api& oidn = api();
  auto start = std::chrono::steady_clock::now();
  const size_t n = film.pixels(), w = size_t(film.width), h = size_t(film.height);
  std::vector<float> color(3 * n), albedo(3 * n, 0.0f), normal(3 * n, 0.0f);
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      color[3 * i + c] = film.mean[4 * i + c];
      if (!film.aov.empty()) {
        albedo[3 * i + c] = film.aov[8 * i + c];
        normal[3 * i + c] = film.aov[8 * i + 4 + c];
      }
    }
  Session s(oidn);
  s.device = oidn.new_device(prefer_gpu ? kDeviceDefault : kDeviceCpu);
  if (!s.device) throw Error("denoising failed: Open Image Denoise found no device");
  oidn.commit_device(s.device);
  check(oidn, s.device, "device");
  Buffer color_buf = s.buffer(color), albedo_buf = s.buffer(albedo), normal_buf = s.buffer(normal);
  Buffer output_buf = s.buffer(std::vector<float>(3 * n, 0.0f));
  check(oidn, s.device, "copies to the device");
  auto image = [&](Filter f, const char* name, Buffer b) {
    oidn.set_filter_image(f, name, b, kFormatFloat3, w, h, 0, 0, 0);
  };
  // The guides, each filtered in place on its own, then the beauty with cleanAux
  const bool guided = !film.aov.empty();
  for (Buffer guide : {albedo_buf, normal_buf}) {
    if (!guided) break;
    Filter f = s.filter();
    image(f, guide == albedo_buf ? "albedo" : "normal", guide);
    image(f, "output", guide);
    oidn.set_filter_int(f, "quality", int(quality));
    oidn.commit_filter(f);
    oidn.execute_filter(f);
    check(oidn, s.device, guide == albedo_buf ? "albedo guide" : "normal guide");
  }
  Filter beauty = s.filter();
  image(beauty, "color", color_buf);
  if (guided) {
    image(beauty, "albedo", albedo_buf);
    image(beauty, "normal", normal_buf);
  }
  image(beauty, "output", output_buf);
  oidn.set_filter_bool(beauty, "hdr", true);
  oidn.set_filter_bool(beauty, "cleanAux", guided);
  oidn.set_filter_int(beauty, "quality", int(quality));
  oidn.commit_filter(beauty);
  oidn.execute_filter(beauty);
  check(oidn, s.device, "image");
  DenoiseResult r;
  r.rgb.resize(3 * n);
  oidn.read_buffer(output_buf, 0, r.rgb.size() * sizeof(float), r.rgb.data());
  check(oidn, s.device, "copy from the device");
  r.device = device_name(oidn.get_device_int(s.device, "type"));
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

}  // namespace candela
