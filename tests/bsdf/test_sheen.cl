// Sheen test kernels (KHR_materials_sheen): the Charlie lobe alone, lookups of its albedo
// table, and bsdf_at / bsdf_sample / bsdf_eval of material 0 through the real dispatch with
// the GGX and sheen albedo tables bound as asked.

// Material 0 at a point of normal +z and tangent +x seen from wo (above); tables: bit 0 binds
// the GGX albedo table, bit 1 the sheen albedo table
Bsdf test_sheen_bsdf(__global const Material* materials, __global const float* ggx, __global const float* sheen,
                     uint tables, float3 wo) {
  SceneData sc = test_bsdf_scene(materials);
  if (tables & 1u) sc.ggx_albedo = ggx;
  if (tables & 2u) sc.sheen_albedo = sheen;
  return test_bsdf_flat_at(&sc, true, (float4)(0.0f));
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
  Bsdf b = test_sheen_bsdf(materials, ggx, sheen, tables, wo.xyz);
  BsdfSample bs;
  test_bsdf_sample_record(&b, wo.xyz, get_global_id(0), seed, out, &bs);
}

// (bsdf_eval, bsdf_pdf) for the pairs (wo, wi) = (pairs[2i], pairs[2i + 1])
__kernel void test_sheen_eval(__global const Material* materials, __global const float* ggx,
                              __global const float* sheen, uint tables, __global const float4* pairs,
                              __global float4* out) {
  uint i = get_global_id(0);
  float3 wo = pairs[2 * i].xyz, wi = pairs[2 * i + 1].xyz;
  Bsdf b = test_sheen_bsdf(materials, ggx, sheen, tables, wo);
  out[i] = test_bsdf_eval_pdf(&b, wo, wi);
}
