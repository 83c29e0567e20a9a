// render_paths' launch order (pixel_of_launch_index in cl/integrator/render_paths.cl),
// as the kernel computes it on PoCL:
//  - it equals the order written out here by enumeration (bands of 8 rows from the top,
//    8x8 tiles from the left, Z-order inside a whole tile, row-major inside a cut one), and
//    is a bijection onto the pixels, for images whose sides are and are not multiples of 8,
//    and the host's launch_order (adaptive sampling's first active list) equals it;
//  - a whole tile is 64 consecutive launch indices and its Z-order keeps every aligned run
//    of 4 (16) indices inside a 2x2 (4x4) block;
//  - renders of an odd-sized image give every pixel its samples, and launches of one
//    work-group each give the image of one whole-image launch bit for bit.
#include <gtest/gtest.h>

#include <algorithm>

#include "gltf/gltf_loader.hpp"
#include "render/adaptive.hpp"
#include "render/renderer.hpp"
#include "support/kernels.hpp"
#include "support/scenes.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

std::vector<cl_uint> kernel_order(cl_uint width, cl_uint height) {
  const KernelRig& rig = kernel_rig("pocl");
  auto out = rig.output<cl_uint>(size_t(width) * height);
  rig.run("test_pixel_of_launch_index", size_t(width) * height, width, height, out);
  return out.read();
}

// The order by enumeration: the pixels in the order the launches take them
std::vector<cl_uint> enumerated_order(cl_uint width, cl_uint height) {
  std::vector<cl_uint> order;
  for (cl_uint y0 = 0; y0 < height; y0 += 8)
    for (cl_uint x0 = 0; x0 < width; x0 += 8) {
      cl_uint tw = std::min(8u, width - x0), th = std::min(8u, height - y0);
      if (tw == 8 && th == 8) {
        // Z-order: x from bits 0, 2, 4 of the index, y from bits 1, 3, 5
        for (cl_uint k = 0; k < 64; ++k) {
          cl_uint x = 0, y = 0;
          for (int b = 0; b < 3; ++b) {
            x |= ((k >> (2 * b)) & 1u) << b;
            y |= ((k >> (2 * b + 1)) & 1u) << b;
          }
          order.push_back((y0 + y) * width + x0 + x);
        }
      } else {
        for (cl_uint y = 0; y < th; ++y)
          for (cl_uint x = 0; x < tw; ++x) order.push_back((y0 + y) * width + x0 + x);
      }
    }
  return order;
}

TEST(PixelOrder, KernelOrderIsTheTiledZOrderAndABijection) {
  const cl_uint sizes[][2] = {{1, 1}, {7, 5}, {8, 8}, {9, 17}, {97, 61}, {64, 48}, {256, 3}, {3, 256}, {129, 130}};
  for (const auto& s : sizes) {
    SCOPED_TRACE(std::to_string(s[0]) + "x" + std::to_string(s[1]));
    std::vector<cl_uint> got = kernel_order(s[0], s[1]);
    EXPECT_EQ(got, enumerated_order(s[0], s[1]));
    std::vector<uint32_t> host = launch_order(int(s[0]), int(s[1]));  // adaptive sampling's active list
    EXPECT_EQ(std::vector<cl_uint>(host.begin(), host.end()), got);
    std::vector<cl_uint> sorted = got;
    std::sort(sorted.begin(), sorted.end());
    for (size_t p = 0; p < sorted.size(); ++p) ASSERT_EQ(sorted[p], p) << "pixel " << p << " missing or repeated";
  }
}

TEST(PixelOrder, WholeTilesAreRunsOf64WithNestedBlocks) {
  const cl_uint width = 64, height = 48;  // 8 x 6 whole tiles
  std::vector<cl_uint> got = kernel_order(width, height);
  for (cl_uint run : {4u, 16u, 64u}) {
    cl_uint side = run == 4 ? 2 : run == 16 ? 4 : 8;
    for (size_t i0 = 0; i0 < got.size(); i0 += run) {
      cl_uint x_lo = width, x_hi = 0, y_lo = height, y_hi = 0;
      for (size_t i = i0; i < i0 + run; ++i) {
        x_lo = std::min(x_lo, got[i] % width), x_hi = std::max(x_hi, got[i] % width);
        y_lo = std::min(y_lo, got[i] / width), y_hi = std::max(y_hi, got[i] / width);
      }
      ASSERT_EQ(x_hi - x_lo + 1, side) << "run of " << run << " at " << i0;
      ASSERT_EQ(y_hi - y_lo + 1, side) << "run of " << run << " at " << i0;
      ASSERT_EQ(x_lo % side, 0u);
      ASSERT_EQ(y_lo % side, 0u);
    }
  }
}

TEST(PixelOrder, OddSizedRenderSamplesEveryPixelWhateverTheLaunches) {
  DeviceEntry device = pocl_device();
  Scene scene = load_gltf(scene_path("cornell-box/cornell-box.gltf"));
  RenderSettings settings;
  settings.width = 37;
  settings.height = 21;
  settings.seed = 7;
  Film whole = scene_renderer(device, scene, settings).render(0, 3).film;
  for (size_t i = 0; i < whole.pixels(); ++i)  // kept and dropped (non-finite) samples
    ASSERT_EQ(whole.samples(i) + whole.m2[4 * i + 3], 3.0f) << "pixel " << i;
  RenderSettings tiny = settings;
  tiny.launch_seconds = 1e-9;  // one work-group of launch indices per launch
  Film split = scene_renderer(device, scene, tiny).render(0, 3).film;
  EXPECT_EQ(whole.mean, split.mean);
  EXPECT_EQ(whole.m2, split.m2);
}

}  // namespace
}  // namespace candela::test
