// Test kernels for the camera: pixel-filter offsets and lens samples, one per work-item.

// Offset from the pixel centre of the film sample that render_paths would draw
__kernel void test_filter_offsets(uint filter, uint seed, __global float2* out) {
  uint i = (uint)get_global_id(0);
  Rng rng = rng_init(i, 0u, seed);
  float u = rng_next(&rng), v = rng_next(&rng);
  out[i] = filter_sample(filter, u, v) - (float2)(0.5f);
}

// Points of the unit disk from the concentric mapping
__kernel void test_concentric_disk(uint seed, __global float2* out) {
  uint i = (uint)get_global_id(0);
  Rng rng = rng_init(i, 1u, seed);
  float u = rng_next(&rng), v = rng_next(&rng);
  out[i] = sample_concentric_disk(u, v);
}
