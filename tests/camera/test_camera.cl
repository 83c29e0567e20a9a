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

// camera_rays8 against camera_ray (no lens): work-item i makes the rays through the eight
// film positions film[8i .. 8i + 8) both ways; out[i] = 1 when all eight agree bit for bit
__kernel void test_camera_rays8(__global const RenderParams* params, __global const float2* film, __global uint* out) {
  uint i = (uint)get_global_id(0);
  float fx[8], fy[8];
  for (int l = 0; l < 8; ++l) {
    float2 f = film[8u * i + (uint)l];
    fx[l] = f.x;
    fy[l] = f.y;
  }
  Ray rays[8];
  camera_rays8(params, vload8(0, fx), vload8(0, fy), rays);
  uint same = 1u;
  for (int l = 0; l < 8; ++l) {
    Ray r = camera_ray(params, fx[l], fy[l], (float2)(0.0f));
    same &= (uint)(all(as_uint3(r.org) == as_uint3(rays[l].org)) && all(as_uint3(r.dir) == as_uint3(rays[l].dir)));
  }
  out[i] = same;
}
