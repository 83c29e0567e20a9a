// glTF animations: each sampler's keys read and sampled at a time as the specification
// defines (3.11), and the document posed at that time before the loader reads it: node
// translation, rotation, scale and morph weights, and through KHR_animation_pointer the same
// node properties plus material factors, the numbers of a material's extensions (and of its
// textures' KHR_texture_transform), light colour, intensity, range and cone angles and
// camera lenses. Whatever reads the document (skins, morph targets, cameras, lights) then
// sees the pose.
#include "gltf/animation.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

// Spherical linear interpolation of unit quaternions a -> b along the shorter arc, normalized
void slerp(const float* a, const float* b, double s, float* out) {
  double dot = 0.0;
  for (int i = 0; i < 4; ++i) dot += double(a[i]) * b[i];
  double sign = dot < 0.0 ? -1.0 : 1.0;  // q and -q are the same rotation: take the nearer
  dot *= sign;
  double wa, wb;
  if (dot > 0.9995) {  // nearly the same: linear, then normalized
    wa = 1.0 - s;
    wb = s;
  } else {
    double theta = std::acos(std::min(dot, 1.0)), sin_theta = std::sin(theta);
    wa = std::sin((1.0 - s) * theta) / sin_theta;
    wb = std::sin(s * theta) / sin_theta;
  }
  double q[4], norm = 0.0;
  for (int i = 0; i < 4; ++i) {
    q[i] = wa * a[i] + wb * sign * b[i];
    norm += q[i] * q[i];
  }
  norm = std::sqrt(norm);
  for (int i = 0; i < 4; ++i) out[i] = float(norm > 0.0 ? q[i] / norm : (i == 3 ? 1.0 : 0.0));
}

void normalize_quaternion(std::vector<float>* q) {
  double norm = 0.0;
  for (float v : *q) norm += double(v) * v;
  norm = std::sqrt(norm);
  if (norm > 0.0)
    for (float& v : *q) v = float(v / norm);
}

}  // namespace

std::vector<float> sample_curve(const AnimationCurve& c, double t, bool rotation) {
  const size_t n = c.times.size(), w = c.width;
  const bool cubic = c.interpolation == Interpolation::CubicSpline;
  const size_t stride = cubic ? 3 * w : w, at_value = cubic ? w : 0;
  auto value = [&](size_t k) { return c.values.data() + k * stride + at_value; };
  std::vector<float> out(w, 0.0f);
  if (n == 0 || c.values.size() < n * stride) return out;
  size_t k = 0;
  if (t >= c.times[n - 1]) {
    k = n - 1;
  } else if (t > c.times[0]) {
    // times[k] <= t < times[k + 1]: an interval of positive length
    auto after = std::upper_bound(c.times.begin(), c.times.end(), t, [](double x, float key) { return x < key; });
    k = size_t(after - c.times.begin()) - 1;
  }
  const bool between = t > c.times[0] && t < c.times[n - 1];
  if (!between || c.interpolation == Interpolation::Step) {
    std::copy(value(k), value(k) + w, out.begin());
    if (rotation) normalize_quaternion(&out);
    return out;
  }
  const double t0 = c.times[k], t1 = c.times[k + 1], td = t1 - t0;
  const double s = td > 0.0 ? (t - t0) / td : 0.0;
  const float *v0 = value(k), *v1 = value(k + 1);
  if (!cubic) {
    if (rotation) {
      slerp(v0, v1, s, out.data());
      return out;
    }
    for (size_t i = 0; i < w; ++i) out[i] = float((1.0 - s) * v0[i] + s * v1[i]);
    return out;
  }
  // Hermite basis; the out-tangent of key k and the in-tangent of key k + 1, times td
  const float* b0 = c.values.data() + k * stride + 2 * w;
  const float* a1 = c.values.data() + (k + 1) * stride;
  const double s2 = s * s, s3 = s2 * s;
  const double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
  for (size_t i = 0; i < w; ++i) out[i] = float(h00 * v0[i] + h10 * td * b0[i] + h01 * v1[i] + h11 * td * a1[i]);
  if (rotation) normalize_quaternion(&out);
  return out;
}

namespace {

std::string animation_label(const tinygltf::Model& model, int a) {
  const std::string& name = model.animations[size_t(a)].name;
  return "glTF animation " + std::to_string(a) + (name.empty() ? "" : " ('" + name + "')");
}

// The sampler's keys, checked: times finite and non-decreasing, values a whole number of
// keys' worth
AnimationCurve read_curve(const tinygltf::Model& model, const tinygltf::Animation& anim, int sampler,
                          const std::string& where) {
  if (sampler < 0 || sampler >= (int)anim.samplers.size())
    throw Error(where + ": sampler " + std::to_string(sampler) + " does not exist");
  const tinygltf::AnimationSampler& s = anim.samplers[size_t(sampler)];
  AnimationCurve c;
  if (s.interpolation == "LINEAR")
    c.interpolation = Interpolation::Linear;
  else if (s.interpolation == "STEP")
    c.interpolation = Interpolation::Step;
  else if (s.interpolation == "CUBICSPLINE")
    c.interpolation = Interpolation::CubicSpline;
  else
    throw Error(where + ": interpolation '" + s.interpolation + "' is not LINEAR, STEP or CUBICSPLINE");
  c.times = read_accessor(model, s.input, 1);
  if (c.times.empty()) throw Error(where + ": its sampler has no keys");
  for (size_t k = 0; k < c.times.size(); ++k)
    if (!std::isfinite(c.times[k]) || (k > 0 && c.times[k] < c.times[k - 1]))
      throw Error(where + ": key times must be finite and increasing");
  c.values = read_accessor(model, s.output, 0);
  size_t elements = c.times.size() * (c.interpolation == Interpolation::CubicSpline ? 3 : 1);
  c.width = c.values.size() / elements;
  if (c.width == 0 || c.values.size() != elements * c.width)
    throw Error(where + ": its output holds " + std::to_string(c.values.size()) +
                " values, not a whole number per key");
  for (float v : c.values)
    if (!std::isfinite(v)) throw Error(where + ": its output values must be finite");
  return c;
}

// The JSON pointer a channel animates ("/nodes/3/rotation"); empty, with a warning, for one
// candela does not know
std::string channel_pointer(const tinygltf::AnimationChannel& ch, const std::string& where, Warnings* warn) {
  if (ch.target_path == "pointer") {
    auto ext = ch.target_extensions.find("KHR_animation_pointer");
    if (ext != ch.target_extensions.end() && ext->second.Has("pointer") && ext->second.Get("pointer").IsString())
      return ext->second.Get("pointer").Get<std::string>();
    warn->add(where + ": target path 'pointer' without a KHR_animation_pointer pointer is ignored");
    return "";
  }
  if (ch.target_node < 0) return "";  // no target: the channel may be ignored (glTF 3.11)
  return "/nodes/" + std::to_string(ch.target_node) + "/" + ch.target_path;
}

std::vector<std::string> split_pointer(const std::string& pointer) {
  std::vector<std::string> parts;
  size_t at = pointer.empty() || pointer[0] != '/' ? std::string::npos : 1;
  while (at != std::string::npos) {
    size_t next = pointer.find('/', at);
    parts.push_back(pointer.substr(at, next == std::string::npos ? std::string::npos : next - at));
    at = next == std::string::npos ? next : next + 1;
  }
  return parts;
}

// parts[i] as an index below n, else -1
int index_at(const std::vector<std::string>& parts, size_t i, size_t n) {
  if (i >= parts.size() || parts[i].empty() || parts[i].size() > 9 ||
      parts[i].find_first_not_of("0123456789") != std::string::npos)
    return -1;
  size_t v = std::stoul(parts[i]);
  return v < n ? int(v) : -1;
}

// Where a pointer's value goes in the document: a list of numbers, one number, or a number
// or list of numbers inside an extension object (`extensions`, at `keys`: the extension's
// name, then the members down to the property)
struct Slot {
  std::vector<double>* list = nullptr;
  double* number = nullptr;
  size_t width = 0;  // how many numbers it takes; 0 inside an extension where it is not given
  bool rotation = false;
  bool matrix_node = false;  // a node given by a matrix, which no channel may animate
  tinygltf::ExtensionMap* extensions = nullptr;
  std::vector<std::string> keys = {};
};

// The Value at keys[i...] under `v` (nullptr when absent or not an object on the way)
const tinygltf::Value* value_at(const tinygltf::Value& v, const std::vector<std::string>& keys, size_t i) {
  if (i == keys.size()) return &v;
  if (!v.IsObject() || !v.Has(keys[i])) return nullptr;
  return value_at(v.Get(keys[i]), keys, i + 1);
}

// `v` with the number (one value) or list at keys[i...] replaced by `values`
tinygltf::Value with_value(const tinygltf::Value& v, const std::vector<std::string>& keys, size_t i,
                           const std::vector<float>& values) {
  if (i == keys.size()) {
    if (values.size() == 1 && !v.IsArray()) return tinygltf::Value(double(values[0]));
    tinygltf::Value::Array list;
    for (float x : values) list.emplace_back(double(x));
    return tinygltf::Value(std::move(list));
  }
  tinygltf::Value::Object object = v.IsObject() ? v.Get<tinygltf::Value::Object>() : tinygltf::Value::Object();
  object[keys[i]] = with_value(object.count(keys[i]) ? object[keys[i]] : tinygltf::Value(), keys, i + 1, values);
  return tinygltf::Value(std::move(object));
}

// A property inside an extension the document has (parts[from] its name): a number, or a
// list of numbers, that is there, or a member the extension's object leaves at its default
Slot extension_slot(tinygltf::ExtensionMap& extensions, const std::vector<std::string>& parts, size_t from) {
  if (parts.size() < from + 2) return {};
  auto ext = extensions.find(parts[from]);
  if (ext == extensions.end() || !ext->second.IsObject()) return {};
  std::vector<std::string> inside(parts.begin() + ptrdiff_t(from) + 1, parts.end());
  std::vector<std::string> parent(inside.begin(), inside.end() - 1);
  const tinygltf::Value* container = value_at(ext->second, parent, 0);
  if (!container || !container->IsObject()) return {};
  const tinygltf::Value* v = value_at(ext->second, inside, 0);
  size_t width = 0;
  if (v && v->IsNumber()) width = 1;
  if (v && v->IsArray()) {
    for (size_t k = 0; k < v->ArrayLen(); ++k)
      if (!v->Get(int(k)).IsNumber()) return {};
    width = v->ArrayLen();
  }
  if ((v && width == 0) || inside.back() == "index" || inside.back() == "texCoord")
    return {};  // a string, an object, an index: not animatable
  Slot slot;
  slot.extensions = &extensions;
  slot.keys.assign(parts.begin() + ptrdiff_t(from), parts.end());
  slot.width = width;
  return slot;
}

// A textureInfo's KHR_texture_transform (or another extension of it): /.../xTexture/extensions/...
Slot texture_info_slot(tinygltf::ExtensionMap& extensions, const std::vector<std::string>& p, size_t at) {
  if (p.size() <= at + 1 || p[at] != "extensions") return {};
  return extension_slot(extensions, p, at + 1);
}

// The morph target count of a mesh (its first primitive's)
size_t morph_targets(const tinygltf::Model& model, int mesh) {
  if (mesh < 0 || mesh >= (int)model.meshes.size() || model.meshes[size_t(mesh)].primitives.empty()) return 0;
  return model.meshes[size_t(mesh)].primitives[0].targets.size();
}

Slot node_slot(tinygltf::Model& model, const std::vector<std::string>& p) {
  int n = index_at(p, 1, model.nodes.size());
  if (n < 0 || p.size() != 3) return {};
  tinygltf::Node& node = model.nodes[size_t(n)];
  Slot s;
  if (p[2] == "translation") s = {&node.translation, nullptr, 3};
  if (p[2] == "rotation") s = {&node.rotation, nullptr, 4, true};
  if (p[2] == "scale") s = {&node.scale, nullptr, 3};
  if (p[2] == "weights") s = {&node.weights, nullptr, morph_targets(model, node.mesh)};
  s.matrix_node = s.list && p[2] != "weights" && node.matrix.size() == 16;
  return s;
}

Slot material_slot(tinygltf::Model& model, const std::vector<std::string>& p) {
  int m = index_at(p, 1, model.materials.size());
  if (m < 0) return {};
  tinygltf::Material& mat = model.materials[size_t(m)];
  std::string rest;
  for (size_t i = 2; i < p.size(); ++i) rest += "/" + p[i];
  if (rest == "/pbrMetallicRoughness/baseColorFactor") return {&mat.pbrMetallicRoughness.baseColorFactor, nullptr, 4};
  if (rest == "/pbrMetallicRoughness/metallicFactor") return {nullptr, &mat.pbrMetallicRoughness.metallicFactor, 1};
  if (rest == "/pbrMetallicRoughness/roughnessFactor") return {nullptr, &mat.pbrMetallicRoughness.roughnessFactor, 1};
  if (rest == "/emissiveFactor") return {&mat.emissiveFactor, nullptr, 3};
  if (rest == "/alphaCutoff") return {nullptr, &mat.alphaCutoff, 1};
  if (rest == "/normalTexture/scale") return {nullptr, &mat.normalTexture.scale, 1};
  if (rest == "/occlusionTexture/strength") return {nullptr, &mat.occlusionTexture.strength, 1};
  if (p.size() > 2 && p[2] == "extensions") return extension_slot(mat.extensions, p, 3);
  if (p.size() > 4 && p[2] == "pbrMetallicRoughness" && p[3] == "baseColorTexture")
    return texture_info_slot(mat.pbrMetallicRoughness.baseColorTexture.extensions, p, 4);
  if (p.size() > 4 && p[2] == "pbrMetallicRoughness" && p[3] == "metallicRoughnessTexture")
    return texture_info_slot(mat.pbrMetallicRoughness.metallicRoughnessTexture.extensions, p, 4);
  if (p.size() > 3 && p[2] == "normalTexture") return texture_info_slot(mat.normalTexture.extensions, p, 3);
  if (p.size() > 3 && p[2] == "emissiveTexture") return texture_info_slot(mat.emissiveTexture.extensions, p, 3);
  return {};
}

Slot light_slot(tinygltf::Model& model, const std::vector<std::string>& p) {
  int l = index_at(p, 3, model.lights.size());
  if (l < 0 || p[1] != "KHR_lights_punctual" || p[2] != "lights") return {};
  tinygltf::Light& light = model.lights[size_t(l)];
  std::string rest;
  for (size_t i = 4; i < p.size(); ++i) rest += "/" + p[i];
  if (rest == "/color") return {&light.color, nullptr, 3};
  if (rest == "/intensity") return {nullptr, &light.intensity, 1};
  if (rest == "/range") return {nullptr, &light.range, 1};
  if (rest == "/spot/innerConeAngle") return {nullptr, &light.spot.innerConeAngle, 1};
  if (rest == "/spot/outerConeAngle") return {nullptr, &light.spot.outerConeAngle, 1};
  return {};
}

Slot camera_slot(tinygltf::Model& model, const std::vector<std::string>& p) {
  int c = index_at(p, 1, model.cameras.size());
  if (c < 0 || p.size() != 4) return {};
  tinygltf::Camera& cam = model.cameras[size_t(c)];
  if (p[2] == "perspective") {
    if (p[3] == "yfov") return {nullptr, &cam.perspective.yfov, 1};
    if (p[3] == "aspectRatio") return {nullptr, &cam.perspective.aspectRatio, 1};
    if (p[3] == "znear") return {nullptr, &cam.perspective.znear, 1};
    if (p[3] == "zfar") return {nullptr, &cam.perspective.zfar, 1};
  } else if (p[2] == "orthographic") {
    if (p[3] == "xmag") return {nullptr, &cam.orthographic.xmag, 1};
    if (p[3] == "ymag") return {nullptr, &cam.orthographic.ymag, 1};
    if (p[3] == "znear") return {nullptr, &cam.orthographic.znear, 1};
    if (p[3] == "zfar") return {nullptr, &cam.orthographic.zfar, 1};
  }
  return {};
}

// The property a pointer names; an empty slot for one candela does not animate
Slot pointer_slot(tinygltf::Model& model, const std::string& pointer) {
  std::vector<std::string> p = split_pointer(pointer);
  if (p.size() < 2) return {};
  if (p[0] == "nodes") return node_slot(model, p);
  if (p[0] == "materials") return material_slot(model, p);
  if (p[0] == "extensions" && p.size() >= 5) return light_slot(model, p);
  if (p[0] == "cameras") return camera_slot(model, p);
  return {};
}

}  // namespace

std::vector<int> chosen_animations(const tinygltf::Model& model, const std::string& selection) {
  std::vector<int> all;
  for (size_t a = 0; a < model.animations.size(); ++a) all.push_back(int(a));
  if (selection.empty()) return all;
  for (size_t a = 0; a < model.animations.size(); ++a)
    if (model.animations[a].name == selection) return {int(a)};
  if (selection.find_first_not_of("0123456789") == std::string::npos && selection.size() < 10) {
    size_t a = std::stoul(selection);
    if (a < model.animations.size()) return {int(a)};
  }
  std::string names;
  for (size_t a = 0; a < model.animations.size(); ++a)
    names += (a ? ", " : "") + std::to_string(a) +
             (model.animations[a].name.empty() ? "" : " '" + model.animations[a].name + "'");
  throw Error("--animation: the scene has no animation '" + selection + "' (" +
              (names.empty() ? std::string("it has no animations") : "its animations: " + names) + ")");
}

void pose_animations(tinygltf::Model* model, const std::vector<int>& animations, double t, Warnings* warn) {
  for (int a : animations) {
    const tinygltf::Animation& anim = model->animations[size_t(a)];
    for (size_t ch = 0; ch < anim.channels.size(); ++ch) {
      const std::string where = animation_label(*model, a) + " channel " + std::to_string(ch);
      std::string pointer = channel_pointer(anim.channels[ch], where, warn);
      if (pointer.empty()) continue;
      Slot slot = pointer_slot(*model, pointer);
      if (!slot.list && !slot.number && !slot.extensions) {
        warn->add("animation of " + pointer + " is not supported and is ignored");
        continue;
      }
      if (slot.matrix_node) {
        warn->add(where + " targets a node given by a matrix, which animations may not target; ignored");
        continue;
      }
      AnimationCurve curve = read_curve(*model, anim, anim.channels[ch].sampler, where);
      if (slot.width != 0 && curve.width != slot.width)
        throw Error(where + ": " + pointer + " takes " + std::to_string(slot.width) + " values a key, its output has " +
                    std::to_string(curve.width));
      std::vector<float> v = sample_curve(curve, t, slot.rotation);
      if (slot.number) {
        *slot.number = v[0];
      } else if (slot.list) {
        slot.list->assign(v.begin(), v.end());
      } else {
        tinygltf::Value& ext = (*slot.extensions)[slot.keys[0]];
        ext = with_value(ext, slot.keys, 1, v);
      }
    }
  }
}

std::vector<AnimationDesc> describe_animations(const tinygltf::Model& model, Warnings* warn) {
  std::vector<AnimationDesc> out;
  for (size_t a = 0; a < model.animations.size(); ++a) {
    const tinygltf::Animation& anim = model.animations[a];
    AnimationDesc d;
    d.name = anim.name;
    d.channels = anim.channels.size();
    std::map<std::string, std::set<int>> nodes;  // node path -> nodes
    size_t pointers = 0;
    bool any_key = false;
    for (const tinygltf::AnimationChannel& ch : anim.channels) {
      if (ch.target_path == "pointer")
        ++pointers;
      else
        nodes[ch.target_path].insert(ch.target_node);
      if (ch.sampler < 0 || ch.sampler >= (int)anim.samplers.size()) continue;
      try {
        std::vector<float> times = read_accessor(model, anim.samplers[size_t(ch.sampler)].input, 1);
        if (times.empty()) continue;
        d.start = any_key ? std::min(d.start, double(times.front())) : times.front();
        d.end = any_key ? std::max(d.end, double(times.back())) : times.back();
        any_key = true;
      } catch (const Error& e) {
        warn->add(animation_label(model, int(a)) + ": " + e.what());
      }
    }
    for (const auto& [path, targets] : nodes)
      d.targets += (d.targets.empty() ? "" : ", ") + path + " of " + std::to_string(targets.size()) +
                   (targets.size() == 1 ? " node" : " nodes");
    if (pointers > 0)
      d.targets += (d.targets.empty() ? "" : ", ") + std::to_string(pointers) + " KHR_animation_pointer " +
                   (pointers == 1 ? "property" : "properties");
    out.push_back(d);
  }
  return out;
}

}  // namespace candela::gltf
