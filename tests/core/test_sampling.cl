// Sampling test kernels (tests/core/sampling_test.cpp): the random stream, direction and
// triangle sampling, and the alias table of light selection (cl/core/).

__kernel void test_rng_uniform(uint seed, __global float* out) {
  uint i = get_global_id(0);
  Rng rng = rng_init(i, 7u, seed);
  for (int k = 0; k < 4; ++k) out[4 * i + k] = rng_next(&rng);
}

// which: 0 cosine hemisphere, 1 uniform sphere; out: xyz direction, w pdf
__kernel void test_sample_direction(uint which, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  Rng rng = rng_init(i, 0u, seed);
  float u = rng_next(&rng), v = rng_next(&rng);
  float3 d = which == 0u ? sample_cosine_hemisphere(u, v) : sample_uniform_sphere(u, v);
  float pdf = which == 0u ? sample_cosine_hemisphere_pdf(d.z) : sample_uniform_sphere_pdf();
  out[i] = (float4)(d, pdf);
}

// Uniform point on triangle v0 v1 v2, written as a 3D point
__kernel void test_sample_triangle(uint seed, float4 v1, float4 v2, float4 v3, __global float4* out) {
  uint i = get_global_id(0);
  Rng rng = rng_init(i, 0u, seed);
  float u = rng_next(&rng), v = rng_next(&rng);
  float2 b = sample_triangle(u, v);
  out[i] = (1.0f - b.x - b.y) * v1 + b.x * v2 + b.y * v3;
}

// Light selection by the alias table: the index chosen for each of many uniform 32-bit
// integers, from the random stream (mode 0) or x = i * stride (mode 1, an even sweep)
__kernel void test_light_select(__global const AliasBin* bins, uint n, uint seed, uint mode, uint stride,
                                __global uint* out) {
  uint i = get_global_id(0);
  Rng rng = rng_init(i, 0u, seed);
  out[i] = sample_discrete_alias(bins, n, mode ? i * stride : rng_next_uint(&rng));
}

// atan2_fast (cl/core/geometry.cl) of each (y, x) pair: out[i] = atan2_fast(in[i].x, in[i].y)
__kernel void test_atan2_fast(__global const float2* in, __global float* out) {
  uint i = get_global_id(0);
  out[i] = atan2_fast(in[i].x, in[i].y);
}

// acos_fast (cl/core/geometry.cl) of each x
__kernel void test_acos_fast(__global const float* in, __global float* out) {
  uint i = get_global_id(0);
  out[i] = acos_fast(in[i]);
}
