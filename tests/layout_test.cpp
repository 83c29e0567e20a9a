// The device compiler lays out every shared struct exactly as the host does.
#include <gtest/gtest.h>

#include "device_types.hpp"
#include "test_support.hpp"

namespace candela::test {

class LayoutTest : public ::testing::TestWithParam<std::string> {};

TEST_P(LayoutTest, DeviceStructLayoutMatchesHost) {
  DeviceEntry device;
  CANDELA_DEVICE_OR_SKIP(GetParam(), device);
  KernelRig rig(device);
  cl::Buffer out(rig.context, CL_MEM_WRITE_ONLY, 16 * sizeof(cl_uint));
  cl::Kernel k(rig.program, "test_struct_layout");
  k.setArg(0, out);
  rig.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(1));
  std::vector<cl_uint> got(16);
  rig.queue.enqueueReadBuffer(out, CL_TRUE, 0, 16 * sizeof(cl_uint), got.data());
  using namespace dev;
  std::vector<cl_uint> want = {
      sizeof(BvhNode), sizeof(Triangle), sizeof(TriangleShading), sizeof(Material),
      sizeof(TextureInfo), sizeof(Light), sizeof(Camera), sizeof(RenderParams),
      offsetof(BvhNode, right), offsetof(Triangle, v2), offsetof(TriangleShading, uv2_v),
      offsetof(Material, emission), offsetof(Light, radiance), offsetof(RenderParams, background),
      offsetof(RenderParams, strategy), offsetof(RenderParams, rr_depth)};
  EXPECT_EQ(got, want);
}

INSTANTIATE_TEST_SUITE_P(Devices, LayoutTest, ::testing::Values("pocl", "rusticl"),
                         [](const auto& info) { return std::string(info.param); });

}  // namespace candela::test
