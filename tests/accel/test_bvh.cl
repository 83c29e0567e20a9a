// BVH test kernels (tests/accel/bvh_test.cpp): closest-hit and occlusion queries through
// the BVH, and the same rays against every triangle.

// rays: (org, tmax) then (dir, 0); out: (t, b1, b2, tri) closest hit, occluded flag
__kernel void test_trace_bvh(__global const BvhNode* nodes, __global const BvhTriangle* tris,
                             __global const float4* rays, __global float4* out, __global int* occluded) {
  uint i = get_global_id(0);
  Ray r;
  r.org = rays[2 * i].xyz;
  r.dir = rays[2 * i + 1].xyz;
  float tmax = rays[2 * i].w;
  // No triangle is flagged for the alpha test: no scene is needed
  Hit h = bvh_intersect(0, nodes, tris, r, tmax);
  out[i] = (float4)(h.t, h.b1, h.b2, (float)h.prim);
  occluded[i] = bvh_occluded(0, nodes, tris, r, tmax) ? 1 : 0;
}

// The same rays against every triangle, without the BVH
__kernel void test_trace_brute(__global const BvhTriangle* tris, uint num_tris, __global const float4* rays,
                               __global float4* out) {
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

// The same rays eight at a time through bvh_intersect8 (the packets of CD_PACKETS); rays past
// the end (num_rays) pad the last packet with tmax 0 and are not written
__kernel void test_trace_bvh8(__global const BvhNode* nodes, __global const BvhTriangle* tris,
                              __global const float4* rays, uint num_rays, __global float4* out) {
  uint first = 8u * (uint)get_global_id(0);
  Ray r[8];
  float tmax[8];
  for (uint l = 0u; l < 8u; ++l) {
    uint i = first + l < num_rays ? first + l : num_rays - 1u;
    r[l].org = rays[2u * i].xyz;
    r[l].dir = rays[2u * i + 1u].xyz;
    tmax[l] = first + l < num_rays ? rays[2u * i].w : 0.0f;
  }
  Hit h[8];
  bvh_intersect8(0, nodes, tris, r, tmax, h);
  for (uint l = 0u; l < 8u; ++l)
    if (first + l < num_rays) out[first + l] = (float4)(h[l].t, h[l].b1, h[l].b2, (float)h[l].prim);
}
