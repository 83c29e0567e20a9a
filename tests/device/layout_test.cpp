// The device compiler lays out every shared struct exactly as the host does: the test
// kernel reports the sizes and offsets of CD_LAYOUT (cl/shared/device_types.h), the same list
// the host's static_asserts come from.
#include <gtest/gtest.h>

#include "base/device_types.hpp"
#include "support/test_support.hpp"

namespace candela::test {

class LayoutTest : public ::testing::TestWithParam<std::string> {};

TEST_P(LayoutTest, DeviceStructLayoutMatchesHost) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
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
  KernelRig rig(device);
  cl::Buffer out(rig.context, CL_MEM_WRITE_ONLY, want.size() * sizeof(cl_uint));
  cl::Kernel k(rig.program, "test_struct_layout");
  k.setArg(0, out);
  rig.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1));
  std::vector<cl_uint> got(want.size());
  rig.queue.enqueueReadBuffer(out, CL_TRUE, 0, got.size() * sizeof(cl_uint), got.data());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(got[i], want[i]) << names[i];
  EXPECT_GE(want.size(), 30u) << "every shared struct is listed";
}

INSTANTIATE_TEST_SUITE_P(Devices, LayoutTest, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace candela::test
