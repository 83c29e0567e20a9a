// Host view of cl/shared/device_types.h, the one definition of every struct that crosses to
// the device, with its layout pinned down by static_asserts generated from CD_LAYOUT;
// tests/layout_test.cpp checks the same list on each device. cl/shared/color.h brings the
// colour helpers both sides share.
#pragma once

#include <cmath>
#include <cstddef>
#include <vector>

namespace candela::dev {
#include "cl/shared/color.h"
#include "cl/shared/device_types.h"
}  // namespace candela::dev

namespace candela::dev {
static_assert(sizeof(float) == 4 && sizeof(int) == 4 && sizeof(unsigned int) == 4);

#define CD_ASSERT_SIZE(type, bytes) static_assert(sizeof(type) == (bytes), #type " size");
#define CD_ASSERT_FIELD(type, field, offset) \
  static_assert(offsetof(type, field) == (offset), #type "::" #field " offset");
CD_LAYOUT(CD_ASSERT_SIZE, CD_ASSERT_FIELD)
#undef CD_ASSERT_SIZE
#undef CD_ASSERT_FIELD

// Host copies of every scene buffer, one vector per entry of CD_SCENE_BUFFERS
#define CD_HOST_BUFFER(type, name) std::vector<type> name;
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
}  // namespace candela::dev
