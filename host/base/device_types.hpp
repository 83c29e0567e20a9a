// Host view of cl/shared/device_types.h, the one definition of every struct that crosses to
// the device, with its layout pinned down by static_asserts generated from CD_LAYOUT;
// tests/device/layout_test.cpp checks the same list on each device. The name tables of the
// material and light types come from their lists (CD_MATERIALS, CD_LIGHTS). cl/shared/color.h
// brings the colour helpers both sides share, cl/shared/light_profiles.h the lights' profiles.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <vector>

#include "base/uninit_vector.hpp"

// The glTF material's lists: the TEX_* slots are visible throughout namespace candela
namespace candela {
#include "cl/shared/gltf_params.h"
namespace dev {
using candela::GltfMaterial;
}
}  // namespace candela

namespace candela::dev {
#include "cl/shared/color.h"
#include "cl/shared/device_types.h"
#include "cl/shared/light_profiles.h"
}  // namespace candela::dev

namespace candela::dev {
static_assert(sizeof(float) == 4 && sizeof(int) == 4 && sizeof(unsigned int) == 4);

#define CD_ASSERT_SIZE(type, bytes) static_assert(sizeof(type) == (bytes), #type " size");
#define CD_ASSERT_FIELD(type, field, offset) \
  static_assert(offsetof(type, field) == (offset), #type "::" #field " offset");
CD_LAYOUT(CD_ASSERT_SIZE, CD_ASSERT_FIELD)
#undef CD_ASSERT_SIZE
#undef CD_ASSERT_FIELD

// The host's vector for each scene buffer: the BVH's nodes and triangles, the largest, are
// written by the builder's threads, so resizing them leaves their elements uninitialized
template <class T>
struct HostBufferOf {
  using vector = std::vector<T>;
};
template <>
struct HostBufferOf<BvhNode> {
  using vector = UninitVector<BvhNode>;
};
template <>
struct HostBufferOf<BvhTriangle> {
  using vector = UninitVector<BvhTriangle>;
};

// Host copies of every scene buffer, one vector per entry of CD_SCENE_BUFFERS
#define CD_HOST_BUFFER(type, name) HostBufferOf<type>::vector name;
#define CD_BUFFER_BYTES(type, name) +name.size() * sizeof(type)
struct SceneBuffers {
  CD_SCENE_BUFFERS(CD_HOST_BUFFER)
  size_t bytes() const { return 0 CD_SCENE_BUFFERS(CD_BUFFER_BYTES); }
};
#undef CD_HOST_BUFFER
#undef CD_BUFFER_BYTES

// Number of entries in CD_SCENE_BUFFERS (the kernel has these plus params and the film)
#define CD_COUNT_BUFFER(type, name) +1
constexpr unsigned kSceneBufferCount = 0 CD_SCENE_BUFFERS(CD_COUNT_BUFFER);
#undef CD_COUNT_BUFFER

// Position of each scene buffer in CD_SCENE_BUFFERS: SceneBuffer::name
#define CD_BUFFER_INDEX(type, name) name,
enum class SceneBuffer : unsigned { CD_SCENE_BUFFERS(CD_BUFFER_INDEX) };
#undef CD_BUFFER_INDEX

// The ids of CD_MATERIALS and CD_LIGHTS number their lists: 0, 1, 2, ...
constexpr bool numbers_the_list(std::initializer_list<unsigned> ids) {
  unsigned n = 0;
  for (unsigned id : ids)
    if (id != n++) return false;
  return true;
}
#define CD_TYPE_ID(id, name, feature) id,
static_assert(numbers_the_list({CD_MATERIALS(CD_TYPE_ID)}), "CD_MATERIALS ids must be 0, 1, 2, ... in list order");
static_assert(numbers_the_list({CD_LIGHTS(CD_TYPE_ID)}), "CD_LIGHTS ids must be 0, 1, 2, ... in list order");
#undef CD_TYPE_ID

// Number of material and light types
#define CD_COUNT_TYPE(id, name, feature) +1
constexpr unsigned kMaterialTypeCount = 0 CD_MATERIALS(CD_COUNT_TYPE);
constexpr unsigned kLightTypeCount = 0 CD_LIGHTS(CD_COUNT_TYPE);
#undef CD_COUNT_TYPE

// Names of the material and light types (the name column of their lists), indexed by id
#define CD_TYPE_NAME(id, name, feature) #name,
constexpr const char* kMaterialTypeNames[] = {CD_MATERIALS(CD_TYPE_NAME)};
constexpr const char* kLightTypeNames[] = {CD_LIGHTS(CD_TYPE_NAME)};
#undef CD_TYPE_NAME

// Every light type has its parameters, the member of LightParams named as its entry, spanning the union
#define CD_LIGHT_PARAMS(id, name, feature)                         \
  static_assert(sizeof(LightParams{}.name) == sizeof(LightParams), \
                "CD_LIGHTS entry " #name ": its LightParams member must span the union");
CD_LIGHTS(CD_LIGHT_PARAMS)
#undef CD_LIGHT_PARAMS

// A spot light's cone parameters (SpotLight.cone_scale, cone_offset; spot_profile) from
// KHR_lights_punctual's inner and outer cone angles in radians: the extension's reference
// form t = cos x scale + offset
struct SpotCone {
  float scale, offset;
};
inline SpotCone spot_cone(double inner_cone, double outer_cone) {
  double cos_outer = std::cos(outer_cone);
  double scale = 1.0 / std::max(0.001, std::cos(inner_cone) - cos_outer);
  return {float(scale), float(-cos_outer * scale)};
}

// Names of the kernel features (the name column of CD_SCENE_FEATURES; SceneFeatures' fields)
#define CD_FEATURE_NAME(name, macro, fallback, needs) #name,
constexpr const char* kSceneFeatureNames[] = {CD_SCENE_FEATURES(CD_FEATURE_NAME)};
#undef CD_FEATURE_NAME
#define CD_FEATURE_MACRO(name, macro, fallback, needs) #macro,
constexpr const char* kSceneFeatureMacros[] = {CD_SCENE_FEATURES(CD_FEATURE_MACRO)};
#undef CD_FEATURE_MACRO

// The name of material or light type `type`; nullptr for an unknown one
constexpr const char* material_type_name(unsigned type) {
  return type < kMaterialTypeCount ? kMaterialTypeNames[type] : nullptr;
}
constexpr const char* light_type_name(unsigned type) {
  return type < kLightTypeCount ? kLightTypeNames[type] : nullptr;
}
}  // namespace candela::dev
