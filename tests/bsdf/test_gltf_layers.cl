// glTF layer test kernels (KHR_materials_clearcoat's clearcoatNormalTexture,
// KHR_materials_diffuse_transmission): bsdf_at / bsdf_sample / bsdf_eval_pdf of material 0
// through the real dispatch, at a point of normal +z and tangent +x whose material may
// read textures (RGBA8 texels) and the GGX albedo table (use_ggx != 0).

Bsdf test_layers_bsdf(__global const Material* materials, __global const TextureInfo* textures,
                      __global const Texel8* texels, __global const float* ggx, uint use_ggx, float3 wo) {
  SceneData sc = test_bsdf_scene(materials);
  sc.textures = textures;
  sc.texels8 = texels;
  if (use_ggx) sc.ggx_albedo = ggx;
  return test_bsdf_flat_at(&sc, true, (float4)(0.5f));
}

// Sample i of bsdf_sample from wo, (uc, u.x, u.y) from rng_init(i, 0, seed): out[3i..3i+2] =
// (wi, pdf), (f, 1 for a delta sample, else 0), (bsdf_eval, bsdf_pdf) at wi; all zero where
// sampling fails
__kernel void test_layers_sample(__global const Material* materials, __global const TextureInfo* textures,
                                 __global const Texel8* texels, __global const float* ggx, uint use_ggx, float4 wo,
                                 uint seed, __global float4* out) {
  Bsdf b = test_layers_bsdf(materials, textures, texels, ggx, use_ggx, wo.xyz);
  BsdfSample bs;
  test_bsdf_sample_record(&b, wo.xyz, get_global_id(0), seed, out, &bs);
}

// (bsdf_eval, bsdf_pdf) for the pairs (wo, wi) = (pairs[2i], pairs[2i + 1])
__kernel void test_layers_eval(__global const Material* materials, __global const TextureInfo* textures,
                               __global const Texel8* texels, __global const float* ggx, uint use_ggx,
                               __global const float4* pairs, __global float4* out) {
  uint i = get_global_id(0);
  float3 wo = pairs[2 * i].xyz, wi = pairs[2 * i + 1].xyz;
  Bsdf b = test_layers_bsdf(materials, textures, texels, ggx, use_ggx, wo);
  out[i] = test_bsdf_eval_pdf(&b, wo, wi);
}
