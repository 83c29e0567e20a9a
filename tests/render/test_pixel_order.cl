// Test kernel for render_paths' launch order: the pixel of each launch index
__kernel void test_pixel_of_launch_index(uint width, uint height, __global uint* out) {
  uint i = (uint)get_global_id(0);
  out[i] = pixel_of_launch_index(i, width, height);
}
