// The device compiler lays out every shared struct exactly as the host does: the test
// kernel reports the sizes and offsets of CD_LAYOUT (cl/shared/device_types.h), the same list
// the host's static_asserts come from.
#include <gtest/gtest.h>

#include <algorithm>

#include "base/device_types.hpp"
#include "support/test_support.hpp"

namespace candela::test {

class LayoutTest : public DeviceTest {};

TEST_P(LayoutTest, DeviceStructLayoutMatchesHost) {
  using namespace dev;
  std::vector<cl_uint> want;
  std::vector<std::string> names;
#define WANT_SIZE(type, bytes)  \
  want.push_back(sizeof(type)); \
  names.push_back("sizeof(" #type ")");
#define WANT_FIELD(type, field, offset)  \
  want.push_back(offsetof(type, field)); \
  names.push_back("offsetof(" #type ", " #field ")");
  CD_LAYOUT(WANT_SIZE, WANT_FIELD)
#undef WANT_SIZE
#undef WANT_FIELD
  auto out = rig().output<cl_uint>(want.size());
  rig().run("test_struct_layout", 1, out);
  std::vector<cl_uint> got = out.read();
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(got[i], want[i]) << names[i];
  EXPECT_GE(want.size(), 30u) << "every shared struct is listed";
}

// BSDF_LOBE_BYTES (cl/bsdf/bsdf_common.cl) covers the largest member of the lobe union, and
// the union's float4 words span the whole union: a member beyond them would be copied
// without its tail, the driver bug the words guard against
TEST_P(LayoutTest, BsdfLobeWordsSpanEveryMember) {
  auto out = rig().output<cl_uint>(16);
  rig().run("test_bsdf_lobe_layout", 1, out);
  std::vector<cl_uint> got = out.read();
  cl_uint count = got[0], lobe = got[1], words = got[2], bytes = got[3];
  ASSERT_GE(count, 2u) << "the gltf and conductor members";
  ASSERT_LE(4u + count, got.size());
  std::vector<cl_uint> members(got.begin() + 4, got.begin() + 4 + count);
  cl_uint largest = *std::max_element(members.begin(), members.end());
  EXPECT_GE(bytes, largest) << "BSDF_LOBE_BYTES covers the largest member";
  EXPECT_LT(bytes - largest, 16u) << "up to the union's alignment";
  EXPECT_EQ(words, lobe) << "the words span the whole union";
  EXPECT_EQ(words % 16u, 0u);
  EXPECT_LT(words - largest, 16u) << "no more words than the largest member needs";
  for (size_t i = 0; i < members.size(); ++i) EXPECT_LE(members[i], words) << "member " << i;
}

INSTANTIATE_TEST_SUITE_P(Devices, LayoutTest, kernel_devices(), DeviceParamName());

}  // namespace candela::test
