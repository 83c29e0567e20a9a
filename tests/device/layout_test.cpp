// The device compiler lays out every shared struct exactly as the host does: the test
// kernel reports the sizes and offsets of CD_LAYOUT (cl/shared/device_types.h), the same list
// the host's static_asserts come from.
#include <gtest/gtest.h>

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

INSTANTIATE_TEST_SUITE_P(Devices, LayoutTest, kernel_devices(), DeviceParamName());

}  // namespace candela::test
