#include "renderer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "bvh_builder.hpp"
#include "error.hpp"
#include "kernel_sources.hpp"
#include "light_table.hpp"
#include "program_cache.hpp"

namespace candela {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

std::vector<dev::TriangleShading> shading_data(const std::vector<SceneTriangle>& tris) {
  std::vector<dev::TriangleShading> out(tris.size());
  for (size_t i = 0; i < tris.size(); ++i) {
    const SceneTriangle& t = tris[i];
    dev::TriangleShading& s = out[i];
    s = dev::TriangleShading{};
    for (int a = 0; a < 3; ++a) {
      s.n0[a] = t.n[0][a];
      s.n1[a] = t.n[1][a];
      s.n2[a] = t.n[2][a];
    }
    s.uv0_u = t.uv[0].x;
    s.uv0_v = t.uv[0].y;
    s.uv1_u = t.uv[1].x;
    s.uv1_v = t.uv[1].y;
    s.uv2_u = t.uv[2].x;
    s.uv2_v = t.uv[2].y;
  }
  return out;
}

std::vector<dev::TriangleColors> color_data(const std::vector<SceneTriangle>& tris) {
  std::vector<dev::TriangleColors> out(tris.size());
  for (size_t i = 0; i < tris.size(); ++i)
    for (int a = 0; a < 3; ++a) {
      out[i].c0[a] = tris[i].color[0][a];
      out[i].c1[a] = tris[i].color[1][a];
      out[i].c2[a] = tris[i].color[2][a];
    }
  return out;
}

// sRGB 8-bit code to linear value (IEC 61966-2-1), for texture decoding in the kernel
std::vector<float> srgb_decode_table() {
  std::vector<float> t(256);
  for (int i = 0; i < 256; ++i) {
    double c = i / 255.0;
    t[i] = float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
  }
  return t;
}

std::string format_mib(uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f MiB", bytes / 1048576.0);
  return buf;
}

// A read-only buffer holding `data`, or one dummy element when it is empty
template <typename T>
cl::Buffer upload(const cl::Context& ctx, const DeviceEntry& device, const std::vector<T>& data,
                  const char* what) {
  std::vector<T> one(1);
  const std::vector<T>& src = data.empty() ? one : data;
  size_t bytes = src.size() * sizeof(T);
  if (bytes > device.max_alloc)
    throw Error(std::string("the scene's ") + what + " need " + format_mib(bytes) +
                " in one buffer, more than " + device.description() + " allows (" +
                format_mib(device.max_alloc) + ")");
  try {
    return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, src.size() * sizeof(T),
                      const_cast<T*>(src.data()));
  } catch (const cl::Error& e) {
    throw Error(cl_error_message(std::string("uploading ") + what, e.err()));
  }
}

}  // namespace

Renderer::Renderer(const DeviceEntry& device, const Scene& scene, const RenderSettings& settings)
    : device_(device), settings_(settings) {
  if (settings.width <= 0 || settings.height <= 0 || settings.width > 65536 ||
      settings.height > 65536 || uint64_t(settings.width) * settings.height > (uint64_t(1) << 28))
    throw Error("image size must be between 1x1 and 65536x65536 with at most 2^28 pixels");
  if (device.opencl_c_version.rfind("OpenCL C 1.0", 0) == 0 ||
      device.opencl_c_version.rfind("OpenCL C 1.1", 0) == 0)
    throw Error(device.description() + " supports only " + device.opencl_c_version +
                "; candela needs OpenCL C 1.2");

  auto bvh_start = Clock::now();
  Bvh bvh = build_bvh(scene.triangles);
  std::vector<dev::Triangle> tris = bvh_ordered_triangles(scene.triangles, bvh);
  LightTable table = build_light_table(tris, scene.materials, scene.emission_texture_means(),
                                       scene.background, scene.bounds());
  bvh_build_seconds_ = seconds_since(bvh_start);
  triangles_ = tris.size();
  num_lights_ = table.lights.size();

  try {
    context_ = cl::Context(device_.device);
    queue_ = cl::CommandQueue(context_, device_.device);
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("creating a context on " + device_.description(), e.err()));
  }
  std::string options = "-cl-std=CL1.2 " + scene.features().build_options();
  ProgramBuild build = build_program(context_, device_, renderer_program_source(), options);
  kernel_build_seconds_ = build.seconds;
  kernel_from_cache_ = build.from_cache;
  kernel_ = cl::Kernel(build.program, "render_paths");
  local_size_ = std::min<size_t>(64, kernel_.getWorkGroupInfo<CL_KERNEL_WORK_GROUP_SIZE>(device_.device));

  nodes_ = upload(context_, device_, bvh.nodes, "the BVH");
  tris_ = upload(context_, device_, tris, "triangles");
  shading_ = upload(context_, device_, shading_data(scene.triangles), "vertex normals and UVs");
  colors_ = upload(context_, device_, scene.has_vertex_colors ? color_data(scene.triangles)
                                                              : std::vector<dev::TriangleColors>(),
                   "vertex colors");
  materials_ = upload(context_, device_, scene.materials, "materials");
  textures_ = upload(context_, device_, scene.textures, "texture descriptors");
  texels_ = upload(context_, device_, scene.texels, "textures");
  srgb_table_ = upload(context_, device_, srgb_decode_table(), "sRGB table");
  lights_ = upload(context_, device_, table.lights, "lights");
  light_thresholds_ = upload(context_, device_, table.thresholds, "the light table");

  CameraDesc cam = resolve_camera(scene);
  params_host_.camera = make_device_camera(cam, settings.width, settings.height);
  for (int c = 0; c < 3; ++c) params_host_.background[c] = scene.background[c];
  params_host_.width = uint32_t(settings.width);
  params_host_.height = uint32_t(settings.height);
  params_host_.seed = settings.seed;
  params_host_.max_depth = settings.max_depth;
  params_host_.rr_depth = settings.rr_depth;
  params_host_.strategy = uint32_t(settings.strategy);
  params_host_.num_lights = uint32_t(table.lights.size());

  size_t film_bytes = size_t(settings.width) * settings.height * 4 * sizeof(float);
  try {
    params_ = cl::Buffer(context_, CL_MEM_READ_ONLY, sizeof(dev::RenderParams));
    film_mean_ = cl::Buffer(context_, CL_MEM_READ_WRITE, film_bytes);
    film_m2_ = cl::Buffer(context_, CL_MEM_READ_WRITE, film_bytes);
    queue_.enqueueFillBuffer(film_mean_, 0.0f, 0, film_bytes);
    queue_.enqueueFillBuffer(film_m2_, 0.0f, 0, film_bytes);
    int arg = 0;
    for (cl::Buffer* b : {&nodes_, &tris_, &shading_, &colors_, &materials_, &textures_, &texels_, &srgb_table_, &lights_,
                          &light_thresholds_, &params_, &film_mean_, &film_m2_})
      kernel_.setArg(arg++, *b);
    queue_.finish();
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("allocating the film", e.err()));
  }
}

void Renderer::launch(uint32_t sample_begin, uint32_t count, size_t pixel_begin, size_t pixel_end) {
  params_host_.sample_begin = sample_begin;
  params_host_.sample_count = count;
  params_host_.pixel_begin = uint32_t(pixel_begin);
  params_host_.pixel_end = uint32_t(pixel_end);
  try {
    queue_.enqueueWriteBuffer(params_, CL_TRUE, 0, sizeof params_host_, &params_host_);
    // Work-groups of local_size_ work-items; the kernel skips the padding at the end
    size_t global = (pixel_end - pixel_begin + local_size_ - 1) / local_size_ * local_size_;
    queue_.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(global),
                                cl::NDRange(local_size_));
    queue_.finish();
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("running the path tracing kernel", e.err()));
  }
}

RenderResult Renderer::render(uint32_t sample_begin, uint32_t spp, double time_limit,
                              const std::function<void(const RenderProgress&)>& progress,
                              const std::function<bool()>& stop) {
  if (spp == 0 && !(time_limit > 0.0)) throw Error("render needs a sample count or a time limit");
  auto start = Clock::now();
  RenderProgress p;
  p.spp_target = spp;
  p.time_limit = time_limit;
  RenderResult result;
  const size_t pixels = size_t(settings_.width) * settings_.height;
  // The film counts samples in floats: a time-limited render stops at 2^24 per pixel
  const uint32_t limit = spp > 0 ? spp : kMaxSamplesPerPixel;
  // A pass adds `batch` samples to every pixel, in launches of at most `chunk` pixels,
  // each sized to take about launch_seconds (GPU watchdogs, progress, Ctrl-C)
  uint32_t batch = 1;
  size_t chunk = std::min(pixels, std::max<size_t>(local_size_, 4096));
  double cost = 0.0;  // seconds per pixel sample, from the last launch (sizes chunks)
  auto out_of_time = [&] { return spp == 0 && seconds_since(start) >= time_limit; };
  while (p.spp_done < limit && !result.interrupted) {
    batch = std::min(batch, limit - p.spp_done);
    double pass_seconds = 0.0;
    for (size_t begin = 0, end = 0; begin < pixels; begin = end) {
      bool stopped = stop && stop();
      // A time limit ends a pass early only once a whole pass exists to show
      if (stopped || (begin > 0 && p.spp_done > 0 && out_of_time())) {
        // Pixels before `begin` keep one batch more than the others (exact per-pixel
        // counts live in the film)
        result.interrupted = stopped;
        result.partial_pass = begin > 0;
        break;
      }
      end = std::min(pixels, begin + chunk);
      auto t0 = Clock::now();
      launch(sample_begin + p.spp_done, batch, begin, end);
      double dt = seconds_since(t0);
      pass_seconds += dt;
      cost = dt / (double(end - begin) * batch);
      size_t want = size_t(settings_.launch_seconds / std::max(cost * batch, 1e-12));
      chunk = std::clamp((want + local_size_ - 1) / local_size_ * local_size_,
                         std::min(local_size_, pixels), pixels);
      if (end < pixels && progress) {
        p.spp_partial = batch * double(end) / double(pixels);
        p.seconds = seconds_since(start);
        progress(p);
      }
    }
    p.spp_partial = 0.0;
    if (result.interrupted || result.partial_pass) break;
    p.spp_done += batch;
    p.seconds = seconds_since(start);
    if (progress) progress(p);
    if (out_of_time()) break;
    // Next pass: whole-image launches of several samples once one sample is cheap enough
    double pass = pass_seconds / batch;  // one sample of the whole image
    double want = settings_.launch_seconds / std::max(pass, 1e-12);
    batch = uint32_t(std::clamp(want, 1.0, std::min(2.0 * batch, 4096.0)));
    if (spp == 0) batch = uint32_t(std::clamp((time_limit - p.seconds) / std::max(pass, 1e-12), 1.0, double(batch)));
    if (want >= 1.0) chunk = pixels;
  }
  result.spp = p.spp_done;
  result.seconds = seconds_since(start);

  Film film(settings_.width, settings_.height);
  try {
    queue_.enqueueReadBuffer(film_mean_, CL_TRUE, 0, film.mean.size() * sizeof(float), film.mean.data());
    queue_.enqueueReadBuffer(film_m2_, CL_TRUE, 0, film.m2.size() * sizeof(float), film.m2.data());
  } catch (const cl::Error& e) {
    throw Error(cl_error_message("reading back the film", e.err()));
  }
  result.film = std::move(film);
  return result;
}

}  // namespace candela
