// Anisotropy test kernels: bsdf_at / bsdf_sample / bsdf_eval of material 0 through the real
// dispatch at shading points a mesh can produce (any tangent, any TANGENT.w, an anisotropy
// texture), with the textures of a small scene bound.

#define TEST_ANISOTROPY_NO_BUFFER(type, name) 0,

// A hit of material 0 seen from wo with the given tangent and TANGENT.w, at texture
// coordinates uv; ng = ns = +z
SurfaceHit test_anisotropy_hit(float4 tangent, float2 uv, float3 wo) {
  SurfaceHit s;
  s.p = (float3)(0.0f);
  s.ng = (float3)(0.0f, 0.0f, 1.0f);
  s.front = wo.z > 0.0f;
  if (!s.front) s.ng = -s.ng;
  s.ns = s.ng;
  s.tangent = tangent.xyz;
  s.tangent_sign = tangent.w;
  s.uvs = (float4)(uv, uv);
  s.vertex_color = (float3)(1.0f);
  s.prim = 0u;
  s.material = 0u;
  return s;
}

// Work-item i: wo = wos[i % n_wo]; a bsdf_sample from rng_init(i, 0, seed), its weight
// f |cos| / pdf, and bsdf_eval_pdf at the sampled wi and at the mirror of wo raised to
// wi_z = grazing[i % 4]. out[2i] = (weight, finite flags of sample: 1 all finite),
// out[2i + 1] = (eval f at the raised mirror, 1 when the evals were all finite)
__kernel void test_anisotropy_weights(__global const Material* materials, __global const TextureInfo* textures,
                                      __global const Texel8* texels8, __global const float* srgb, float4 tangent,
                                      float2 uv, __global const float4* wos, uint n_wo, float4 grazing, uint seed,
                                      __global float4* out) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(TEST_ANISOTROPY_NO_BUFFER) 0};
  sc.materials = materials;
  sc.textures = textures;
  sc.texels8 = texels8;
  sc.srgb_to_linear = srgb;
  float3 wo = wos[i % n_wo].xyz;
  SurfaceHit s = test_anisotropy_hit(tangent, uv, wo);
  Bsdf b = bsdf_at(&sc, &s);
  bsdf_face_wo(&b, wo);
  Rng rng = rng_init(i, 0u, seed);
  float uc = rng_next(&rng);
  float2 u = rng_next_2d(&rng);
  BsdfSample bs;
  float3 weight = (float3)(0.0f);
  bool finite = true;
  if (bsdf_sample(&b, wo, uc, u, &bs)) {
    weight = bs.f * (fabs(dot(bs.wi, b.frame.n)) / bs.pdf);
    finite = all_finite(weight) && all_finite(bs.wi) && isfinite(bs.pdf);
    float pdf;
    float3 f = bsdf_eval_pdf(&b, wo, bs.wi, &pdf);
    finite = finite && all_finite(f) && isfinite(pdf);
  }
  float gz = grazing[i % 4u];
  float3 wi = (float3)(-wo.x, -wo.y, 0.0f);
  float len = length(wi);
  wi = len > 0.0f ? wi * (sqrt(1.0f - gz * gz) / len) : (float3)(sqrt(1.0f - gz * gz), 0.0f, 0.0f);
  wi.z = wo.z > 0.0f ? gz : -gz;
  float pdf;
  float3 f = bsdf_eval_pdf(&b, wo, wi, &pdf);
  bool eval_finite = all_finite(f) && isfinite(pdf);
  out[2 * i] = (float4)(weight, finite ? 1.0f : 0.0f);
  out[2 * i + 1] = (float4)(f, eval_finite ? 1.0f : 0.0f);
}
