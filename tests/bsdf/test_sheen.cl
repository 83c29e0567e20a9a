// Sheen test kernels (KHR_materials_sheen): the Charlie lobe alone, lookups of its albedo
// table, and bsdf_at / bsdf_sample / bsdf_eval of material 0 through the real dispatch with
// the GGX and sheen albedo tables bound as asked.

#define TEST_SHEEN_NO_BUFFER(type, name) 0,

// Material 0 at a point of normal +z and tangent +x seen from wo (above); tables: bit 0 binds
// the GGX albedo table, bit 1 the sheen albedo table
Bsdf test_sheen_bsdf(__global const Material* materials, __global const float* ggx, __global const float* sheen,
                     uint tables, float3 wo) {
  SceneData sc = {CD_SCENE_BUFFERS(TEST_SHEEN_NO_BUFFER) 0};
  sc.materials = materials;
  if (tables & 1u) sc.ggx_albedo = ggx;
  if (tables & 2u) sc.sheen_albedo = sheen;
  SurfaceHit s = test_bsdf_flat_hit(true, (float4)(0.0f));
  return bsdf_at(&sc, &s);
}

// sheen_eval(alpha, wo, wi) for the pairs (wo, wi) = (pairs[2i], pairs[2i + 1]), alpha = pairs[2i].w
__kernel void test_sheen_lobe(__global const float4* pairs, __global float* out) {
  uint i = get_global_id(0);
  out[i] = sheen_eval(pairs[2 * i].w, pairs[2 * i].xyz, pairs[2 * i + 1].xyz);
}

// sheen_albedo(table, mu, roughness) at queries[i] = (mu, roughness)
__kernel void test_sheen_albedo_lookup(__global const float* table, __global const float2* queries,
                                       __global float* out) {
  uint i = get_global_id(0);
  out[i] = sheen_albedo(table, queries[i].x, queries[i].y);
}

// Sample i of bsdf_sample from wo, (uc, u.x, u.y) from rng_init(i, 0, seed): out[3i..3i+2] =
// (wi, pdf), (f, 1 for a delta sample, else 0), (bsdf_eval, bsdf_pdf) at wi; all zero where
// sampling fails
__kernel void test_sheen_sample(__global const Material* materials, __global const float* ggx,
                                __global const float* sheen, uint tables, float4 wo, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  Bsdf b = test_sheen_bsdf(materials, ggx, sheen, tables, wo.xyz);
  BsdfSample bs;
  if (!test_bsdf_sample_i(&b, wo.xyz, i, seed, &bs)) {
    out[3 * i] = out[3 * i + 1] = out[3 * i + 2] = (float4)(0.0f);
    return;
  }
  float pdf;
  float3 f = bsdf_eval_pdf(&b, wo.xyz, bs.wi, &pdf);
  out[3 * i] = (float4)(bs.wi, bs.pdf);
  out[3 * i + 1] = (float4)(bs.f, (bs.flags & BSDF_DELTA) ? 1.0f : 0.0f);
  out[3 * i + 2] = (float4)(f, pdf);
}

// (bsdf_eval, bsdf_pdf) for the pairs (wo, wi) = (pairs[2i], pairs[2i + 1])
__kernel void test_sheen_eval(__global const Material* materials, __global const float* ggx,
                              __global const float* sheen, uint tables, __global const float4* pairs,
                              __global float4* out) {
  uint i = get_global_id(0);
  float3 wo = pairs[2 * i].xyz, wi = pairs[2 * i + 1].xyz;
  Bsdf b = test_sheen_bsdf(materials, ggx, sheen, tables, wo);
  float pdf;
  float3 f = bsdf_eval_pdf(&b, wo, wi, &pdf);
  out[i] = (float4)(f, pdf);
}
