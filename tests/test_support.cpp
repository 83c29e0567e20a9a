#include "test_support.hpp"

#include <cmath>
#include <fstream>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "error.hpp"
#include "kernel_sources.hpp"
#include "program_cache.hpp"

namespace candela::test {

DeviceEntry pocl_device() { return select_device("pocl"); }

std::optional<DeviceEntry> rusticl_device() {
  for (const auto& d : list_devices())
    if (d.platform_name == "rusticl") return d;
  return std::nullopt;
}

std::optional<DeviceEntry> device_by_name(const std::string& name) {
  if (name == "pocl") return pocl_device();
  if (name == "rusticl") return rusticl_device();
  throw Error("unknown test device " + name);
}

KernelRig::KernelRig(const DeviceEntry& d) : device(d) {
  context = cl::Context(device.device);
  queue = cl::CommandQueue(context, device.device);
  program = build_program(context, device, test_program_source(), "-cl-std=CL1.2").program;
}

namespace {
template <typename T>
cl::Buffer upload_or_dummy(const cl::Context& ctx, const std::vector<T>& data) {
  std::vector<T> one(1);
  const std::vector<T>& src = data.empty() ? one : data;
  return cl::Buffer(ctx, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, src.size() * sizeof(T), const_cast<T*>(src.data()));
}
}  // namespace

SceneOnDevice::SceneOnDevice(KernelRig& rig, const CompiledScene& scene) {
#define CD_TEST_UPLOAD(type, name) buffers.push_back(upload_or_dummy(rig.context, scene.buffers.name));
  CD_SCENE_BUFFERS(CD_TEST_UPLOAD)
#undef CD_TEST_UPLOAD
  params_host.num_lights = cl_uint(scene.buffers.lights.size());
  params_host.environment_light = scene.environment_light;
  params_host.width = params_host.height = 1;
  params = cl::Buffer(rig.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof params_host, &params_host);
}

cl_uint SceneOnDevice::bind(cl::Kernel& kernel, cl_uint first_arg) const {
  cl_uint arg = first_arg;
  for (const cl::Buffer& b : buffers) kernel.setArg(arg++, b);
  kernel.setArg(arg++, params);
  return arg;
}

std::string scene_path(const std::string& relative) {
  return std::string(CANDELA_SOURCE_DIR) + "/scenes/" + relative;
}

std::string base64(const std::string& in) {
  static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
    for (int k = 3; k >= 0; --k) out += t[(v >> (6 * k)) & 63];
  }
  size_t rest = in.size() - i;
  if (rest > 0) {
    uint32_t v = uint8_t(in[i]) << 16;
    if (rest == 2) v |= uint8_t(in[i + 1]) << 8;
    out += t[(v >> 18) & 63];
    out += t[(v >> 12) & 63];
    out += rest == 2 ? t[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

void write_quads_gltf(const std::string& path, const std::vector<TestQuad>& quads,
                      const std::string& materials_json, const float eye[3], const float target[3],
                      float yfov, const float background[3], const std::string& extra_json) {
  using nlohmann::json;
  std::string bin;
  json accessors = json::array(), views = json::array(), primitives = json::array();
  for (const auto& q : quads) {
    float tri[18];
    const int order[6] = {0, 1, 2, 0, 2, 3};
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (int k = 0; k < 6; ++k)
      for (int a = 0; a < 3; ++a) {
        tri[3 * k + a] = q.p[order[k]][a];
        lo[a] = std::min(lo[a], tri[3 * k + a]);
        hi[a] = std::max(hi[a], tri[3 * k + a]);
      }
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", sizeof tri}});
    bin.append(reinterpret_cast<const char*>(tri), sizeof tri);
    accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", 5126}, {"count", 6},
                         {"type", "VEC3"}, {"min", lo}, {"max", hi}});
    const float corner_uv[4][2] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    float uv[12];
    for (int k = 0; k < 6; ++k) {
      uv[2 * k] = corner_uv[order[k]][0];
      uv[2 * k + 1] = corner_uv[order[k]][1];
    }
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", sizeof uv}});
    bin.append(reinterpret_cast<const char*>(uv), sizeof uv);
    accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", 5126}, {"count", 6}, {"type", "VEC2"}});
    primitives.push_back({{"attributes", {{"POSITION", accessors.size() - 2}, {"TEXCOORD_0", accessors.size() - 1}}},
                          {"material", q.material}});
  }
  // Camera rotation taking -z to the viewing direction, +y up
  glm::vec3 f = glm::normalize(glm::vec3(target[0], target[1], target[2]) - glm::vec3(eye[0], eye[1], eye[2]));
  glm::vec3 r = glm::normalize(glm::cross(f, glm::vec3(0, 1, 0)));
  glm::vec3 u = glm::cross(r, f);
  glm::quat rot = glm::quat_cast(glm::mat3(r, u, -f));
  json j;
  j["asset"] = {{"version", "2.0"}};
  j["buffers"] = {{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}};
  j["bufferViews"] = views;
  j["accessors"] = accessors;
  j["meshes"] = {{{"primitives", primitives}}};
  j["materials"] = json::parse(materials_json);
  j["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", yfov}, {"znear", 0.001}}}}};
  j["nodes"] = {{{"mesh", 0}},
                {{"camera", 0}, {"translation", {eye[0], eye[1], eye[2]}}, {"rotation", {rot.x, rot.y, rot.z, rot.w}}}};
  j["scenes"] = {{{"nodes", {0, 1}}, {"extras", {{"candela", {{"background", {background[0], background[1], background[2]}}}}}}}};
  j["scene"] = 0;
  json extra = json::parse(extra_json);
  for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
  std::ofstream(path) << j.dump();
}

}  // namespace candela::test
