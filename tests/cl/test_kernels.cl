// Test kernels: thin wrappers that run the real cl/ routines on inputs from the host.

// Sizes and offsets of the shared structs as the device compiler lays them out, in the
// order of CD_LAYOUT (device_types.h), the list the host's static_asserts come from
#define TEST_LAYOUT_SIZE(type, bytes) out[n++] = (uint)sizeof(type);
#define TEST_LAYOUT_FIELD(type, field, offset) \
  {                                            \
    type object;                               \
    out[n++] = (uint)((char*)&object.field - (char*)&object); \
  }
__kernel void test_struct_layout(__global uint* out) {
  if (get_global_id(0) != 0) return;
  uint n = 0u;
  CD_LAYOUT(TEST_LAYOUT_SIZE, TEST_LAYOUT_FIELD)
}

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
__kernel void test_sample_triangle(uint seed, float4 v1, float4 v2, float4 v3,
                                   __global float4* out) {
  uint i = get_global_id(0);
  Rng rng = rng_init(i, 0u, seed);
  float u = rng_next(&rng), v = rng_next(&rng);
  float2 b = sample_triangle(u, v);
  out[i] = (1.0f - b.x - b.y) * v1 + b.x * v2 + b.y * v3;
}

// rays: (org, tmax) then (dir, 0); out: (t, b1, b2, tri) closest hit, occluded flag
__kernel void test_trace_bvh(__global const BvhNode* nodes, __global const BvhTriangle* tris,
                             __global const float4* rays, __global float4* out,
                             __global int* occluded) {
  uint i = get_global_id(0);
  Ray r;
  r.org = rays[2 * i].xyz;
  r.dir = rays[2 * i + 1].xyz;
  float tmax = rays[2 * i].w;
  // No triangle is flagged for the alpha test: no scene is needed
  Hit h = bvh_intersect(0, nodes, tris, r, tmax, false);
  out[i] = (float4)(h.t, h.b1, h.b2, (float)h.prim);
  occluded[i] = bvh_occluded(0, nodes, tris, r, tmax) ? 1 : 0;
}

// The same rays against every triangle, without the BVH
__kernel void test_trace_brute(__global const BvhTriangle* tris, uint num_tris,
                               __global const float4* rays, __global float4* out) {
  uint i = get_global_id(0);
  Ray r;
  r.org = rays[2 * i].xyz;
  r.dir = rays[2 * i + 1].xyz;
  WatertightRay wr = watertight_ray(r);
  float best = rays[2 * i].w;
  float4 result = (float4)(best, 0.0f, 0.0f, -1.0f);
  for (uint k = 0; k < num_tris; ++k) {
    float t, b1, b2;
    if (bvh_leaf_triangle_hit(&wr, &tris[k], best, &t, &b1, &b2)) {
      best = t;
      result = (float4)(t, b1, b2, (float)tris[k].prim);
    }
  }
  out[i] = result;
}

// Light selection by the alias table: the index chosen for each of many uniform 32-bit
// integers, from the random stream (mode 0) or x = i * stride (mode 1, an even sweep)
__kernel void test_light_select(__global const AliasBin* bins, uint n, uint seed, uint mode, uint stride,
                                __global uint* out) {
  uint i = get_global_id(0);
  Rng rng = rng_init(i, 0u, seed);
  out[i] = sample_discrete_alias(bins, n, mode ? i * stride : rng_next_uint(&rng));
}
