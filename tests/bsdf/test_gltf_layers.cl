// glTF layer test kernels (KHR_materials_clearcoat's clearcoatNormalTexture,
// KHR_materials_diffuse_transmission): bsdf_at / bsdf_sample / bsdf_eval_pdf of material 0
// through the real dispatch, at a point of normal +z and tangent +x whose material may
// read textures (RGBA8 texels) and the GGX albedo table (use_ggx != 0).

#define TEST_LAYERS_NO_BUFFER(type, name) 0,

Bsdf test_layers_bsdf(__global const Material* materials, __global const TextureInfo* textures,
                      __global const Texel8* texels, __global const float* ggx, uint use_ggx, float3 wo) {
  SceneData sc = {CD_SCENE_BUFFERS(TEST_LAYERS_NO_BUFFER) 0};
  sc.materials = materials;
  sc.textures = textures;
  sc.texels8 = texels;
  if (use_ggx) sc.ggx_albedo = ggx;
  SurfaceHit s = test_bsdf_flat_hit(true, (float4)(0.5f));
  return bsdf_at(&sc, &s);
}

// Sample i of bsdf_sample from wo, (uc, u.x, u.y) from rng_init(i, 0, seed): out[3i..3i+2] =
// (wi, pdf), (f, 1 for a delta sample, else 0), (bsdf_eval, bsdf_pdf) at wi; all zero where
// sampling fails
__kernel void test_layers_sample(__global const Material* materials, __global const TextureInfo* textures,
                                 __global const Texel8* texels, __global const float* ggx, uint use_ggx, float4 wo,
                                 uint seed, __global float4* out) {
  uint i = get_global_id(0);
  Bsdf b = test_layers_bsdf(materials, textures, texels, ggx, use_ggx, wo.xyz);
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
__kernel void test_layers_eval(__global const Material* materials, __global const TextureInfo* textures,
                               __global const Texel8* texels, __global const float* ggx, uint use_ggx,
                               __global const float4* pairs, __global float4* out) {
  uint i = get_global_id(0);
  float3 wo = pairs[2 * i].xyz, wi = pairs[2 * i + 1].xyz;
  Bsdf b = test_layers_bsdf(materials, textures, texels, ggx, use_ggx, wo);
  float pdf;
  float3 f = bsdf_eval_pdf(&b, wo, wi, &pdf);
  out[i] = (float4)(f, pdf);
}
