// What a CPU OpenCL driver's work-group vectorizer makes of a loop, as the renderer's path
// loop is one (a benchmark, not a test): the kernels do the same useful work, n_i steps of a
// short float computation per work-item, with
//   uniform:   the same trip count in every work-item (n);
//   unrolled:  64 steps, the loop unrolled (a kernel body without a loop);
//   divergent: a trip count of its own in each work-item (n/2 + hash(i) mod n, mean about n),
//              as a path's bounce count is;
//   masked:    the divergent counts, but every work-item loops to the largest (3n/2 - 1) and
//              keeps a step's result only while k < n_i: uniform control flow, 1.5x the steps;
//   barrier:   masked, to the work-group's largest count, with a barrier after every step;
//   lanes8:    explicit lanes, eight work-items' values in float8 in one work-item.
// It prints one JSON line per kernel and round: seconds (wall, launch to finish), nanoseconds
// per useful step and work-item, and whether the result equals the divergent kernel's bit for
// bit. On PoCL a kernel whose body has a loop runs each work-item alone (whatever its trip
// counts); the code between two barriers runs as a loop over the work-items with nothing
// inside it, which its vectorizer turns into SIMD across work-items.
//
// Usage: candela_simd_probe [DEVICE_SUBSTRING (pocl)] [ROUNDS (3)] [N (64)] [WORK_ITEMS (1048576)]
#include <CL/opencl.hpp>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

const char* kSource = R"CLC(
uint probe_hash(uint x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}
float probe_step(float x, float a) { return sqrt(fabs(x * a + 0.5f)) + 0.25f * x; }
uint probe_count(uint i, uint n) { return n / 2u + probe_hash(i) % n; }

__kernel void probe_counts(__global uint* out, uint n) { out[get_global_id(0)] = probe_count(get_global_id(0), n); }
__kernel void probe_uniform(__global float* out, uint n) {
  uint i = get_global_id(0);
  float x = (float)i * 1e-3f, a = 1.0f + (float)(i & 7u) * 0.01f;
  for (uint k = 0u; k < n; ++k) x = probe_step(x, a);
  out[i] = x;
}
__kernel void probe_unrolled(__global float* out, uint n) {
  uint i = get_global_id(0);
  float x = (float)i * 1e-3f, a = 1.0f + (float)(i & 7u) * 0.01f;
#pragma unroll
  for (uint k = 0u; k < 64u; ++k) x = probe_step(x, a);
  out[i] = x;
}
float8 probe_step8(float8 x, float8 a) { return sqrt(fabs(x * a + 0.5f)) + 0.25f * x; }
// Explicit lanes: each work-item carries eight work-items' values in float8 and loops until
// its last lane is done, a lane keeping its value once its own count is reached
__kernel void probe_lanes8(__global float* out, uint n) {
  uint base = 8u * get_global_id(0);
  uint8 i = (uint8)(base) + (uint8)(0u, 1u, 2u, 3u, 4u, 5u, 6u, 7u);
  uint8 m = (uint8)(n / 2u) + (uint8)(probe_hash(i.s0) % n, probe_hash(i.s1) % n, probe_hash(i.s2) % n,
                                      probe_hash(i.s3) % n, probe_hash(i.s4) % n, probe_hash(i.s5) % n,
                                      probe_hash(i.s6) % n, probe_hash(i.s7) % n);
  uint top = max(max(max(m.s0, m.s1), max(m.s2, m.s3)), max(max(m.s4, m.s5), max(m.s6, m.s7)));
  float8 x = convert_float8(i) * 1e-3f, a = 1.0f + convert_float8(i & 7u) * 0.01f;
  for (uint k = 0u; k < top; ++k) {
    float8 y = probe_step8(x, a);
    x = select(x, y, (int8)((uint8)(k) < m));
  }
  vstore8(x, 0, out + base);
}
__kernel void probe_divergent(__global float* out, uint n) {
  uint i = get_global_id(0), m = probe_count(i, n);
  float x = (float)i * 1e-3f, a = 1.0f + (float)(i & 7u) * 0.01f;
  for (uint k = 0u; k < m; ++k) x = probe_step(x, a);
  out[i] = x;
}
// The masked loop with a barrier in it: the trip count is the work-group's largest (one
// work-item finds it), so every work-item reaches each barrier; PoCL then runs each region
// between barriers as a loop over the group's work-items, which has no loop inside it
__kernel void probe_barrier(__global float* out, uint n) {
  __local uint counts[64];
  __local uint group_top;
  uint i = get_global_id(0), l = get_local_id(0), m = probe_count(i, n);
  counts[l] = m;
  barrier(CLK_LOCAL_MEM_FENCE);
  if (l == 0u) {
    uint top = 0u;
    for (uint j = 0u; j < 64u; ++j) top = max(top, counts[j]);
    group_top = top;
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  uint top = group_top;
  float x = (float)i * 1e-3f, a = 1.0f + (float)(i & 7u) * 0.01f;
  for (uint k = 0u; k < top; ++k) {
    float y = probe_step(x, a);
    x = k < m ? y : x;
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  out[i] = x;
}
__kernel void probe_masked(__global float* out, uint n) {
  uint i = get_global_id(0), m = probe_count(i, n), top = n / 2u + n - 1u;
  float x = (float)i * 1e-3f, a = 1.0f + (float)(i & 7u) * 0.01f;
  for (uint k = 0u; k < top; ++k) {
    float y = probe_step(x, a);
    x = k < m ? y : x;
  }
  out[i] = x;
}
)CLC";

}  // namespace

int main(int argc, char** argv) {
  std::string want = argc > 1 ? argv[1] : "pocl";
  int rounds = argc > 2 ? std::atoi(argv[2]) : 3;
  cl_uint n = argc > 3 ? cl_uint(std::atoi(argv[3])) : 64u;
  size_t items = argc > 4 ? size_t(std::atoll(argv[4])) : size_t(1) << 20;
  if (rounds < 1 || n < 2 || items < 512 || items % 512 != 0) {
    std::fprintf(stderr, "usage: %s [DEVICE_SUBSTRING] [ROUNDS >= 1] [N >= 2] [WORK_ITEMS, a multiple of 512]\n",
                 argv[0]);
    return 2;
  }
  try {
    std::vector<cl::Platform> platforms;
    cl::Platform::get(&platforms);
    cl::Device device;
    bool found = false;
    for (const cl::Platform& p : platforms) {
      std::vector<cl::Device> devices;
      p.getDevices(CL_DEVICE_TYPE_ALL, &devices);
      for (const cl::Device& d : devices) {
        std::string name = p.getInfo<CL_PLATFORM_NAME>() + " " + d.getInfo<CL_DEVICE_NAME>();
        std::string lower = name;
        for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
        if (!found && (lower.find(want) != std::string::npos ||
                       (want == "pocl" && lower.find("portable computing language") != std::string::npos))) {
          device = d;
          found = true;
        }
      }
    }
    if (!found) {
      std::fprintf(stderr, "candela_simd_probe: no OpenCL device matches '%s'\n", want.c_str());
      return 1;
    }
    cl::Context context(device);
    cl::CommandQueue queue(context, device);
    cl::Program program(context, kSource);
    program.build({device}, "-cl-std=CL1.2");
    cl::Buffer out(context, CL_MEM_WRITE_ONLY, items * sizeof(float));
    std::vector<float> reference;  // probe_divergent's result
    double useful = 0.0;           // steps the divergent counts ask for
    {
      cl::Buffer counts(context, CL_MEM_WRITE_ONLY, items * sizeof(cl_uint));
      cl::Kernel k(program, "probe_counts");
      k.setArg(0, counts);
      k.setArg(1, n);
      queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(items), cl::NDRange(64));
      std::vector<cl_uint> m(items);
      queue.enqueueReadBuffer(counts, CL_TRUE, 0, items * sizeof(cl_uint), m.data());
      for (cl_uint c : m) useful += double(c);
    }
    const char* names[] = {"probe_uniform", "probe_unrolled", "probe_divergent",
                           "probe_masked",  "probe_barrier",  "probe_lanes8"};
    for (int round = 0; round <= rounds; ++round)  // round 0 warms the driver's lazy code generation up
      for (const char* name : names) {
        cl::Kernel k(program, name);
        k.setArg(0, out);
        k.setArg(1, n);
        auto t0 = std::chrono::steady_clock::now();
        size_t global = std::strcmp(name, "probe_lanes8") == 0 ? items / 8 : items;
        queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(global), cl::NDRange(64));
        queue.finish();
        double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        // The kernels that do the divergent counts' steps must agree with probe_divergent bit for bit
        std::vector<float> result(items);
        queue.enqueueReadBuffer(out, CL_TRUE, 0, items * sizeof(float), result.data());
        bool divergent_counts = std::strcmp(name, "probe_uniform") != 0 && std::strcmp(name, "probe_unrolled") != 0;
        if (std::strcmp(name, "probe_divergent") == 0) reference = result;
        const char* matches = !divergent_counts || reference.empty() ? "null" : result == reference ? "true" : "false";
        double steps = std::strcmp(name, "probe_uniform") == 0    ? double(n) * double(items)
                       : std::strcmp(name, "probe_unrolled") == 0 ? 64.0 * double(items)
                                                                  : useful;
        if (round > 0)
          std::printf(
              "{\"device\": \"%s\", \"kernel\": \"%s\", \"round\": %d, \"n\": %u, \"work_items\": %zu, "
              "\"seconds\": %.4f, \"ns_per_useful_step\": %.3f, \"matches_divergent\": %s}\n",
              device.getInfo<CL_DEVICE_NAME>().c_str(), name + 6, round, n, items, s, 1e9 * s / steps, matches);
      }
  } catch (const cl::BuildError& e) {
    for (const auto& log : e.getBuildLog()) std::fprintf(stderr, "%s\n", log.second.c_str());
    std::fprintf(stderr, "candela_simd_probe: build failed\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "candela_simd_probe: %s\n", e.what());
    return 1;
  }
  return 0;
}
