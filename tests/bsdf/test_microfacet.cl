// Fresnel (cl/bsdf/fresnel.cl) and GGX (cl/bsdf/microfacet.cl) test kernels: each evaluates one
// routine on inputs from the host, one work-item per input.

// in[i] = (cos_i, eta) -> fresnel_dielectric
__kernel void test_fresnel_dielectric(__global const float2* in, __global float* out) {
  uint i = get_global_id(0);
  out[i] = fresnel_dielectric(in[i].x, in[i].y);
}

// in[i] = (w, eta), n = +z -> (wt, 1) or (0, 0, 0, 0) on total internal reflection
__kernel void test_fresnel_refract(__global const float4* in, __global float4* out) {
  uint i = get_global_id(0);
  float3 wt;
  bool ok = fresnel_refract(in[i].xyz, (float3)(0.0f, 0.0f, 1.0f), in[i].w, &wt);
  out[i] = ok ? (float4)(wt, 1.0f) : (float4)(0.0f);
}

// cos_i[i] -> fresnel_conductor(cos_i, eta, k) per channel
__kernel void test_fresnel_conductor(float4 eta, float4 k, __global const float* cos_i, __global float4* out) {
  uint i = get_global_id(0);
  out[i] = (float4)(fresnel_conductor(cos_i[i], eta.xyz, k.xyz), 0.0f);
}

// (w, m) = (in[2i], in[2i+1]) -> out[2i] = (D(m), Lambda(w), G1(w), D_w(m)),
// out[2i+1] = (G(w, m) with m taken as the second direction, Lambda(m), 0, 0)
__kernel void test_ggx_eval(float2 alpha, __global const float4* in, __global float4* out) {
  uint i = get_global_id(0);
  Ggx g = {alpha.x, alpha.y};
  float3 w = in[2 * i].xyz, m = in[2 * i + 1].xyz;
  out[2 * i] = (float4)(ggx_d(g, m), ggx_lambda(g, w), ggx_g1(g, w), ggx_visible_d(g, w, m));
  out[2 * i + 1] = (float4)(ggx_g(g, w, m), ggx_lambda(g, m), 0.0f, 0.0f);
}

// ggx_sample_visible from w, u = two draws of rng_init(i, 0, seed)
__kernel void test_ggx_sample_visible(float2 alpha, float4 w, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  Ggx g = {alpha.x, alpha.y};
  Rng rng = rng_init(i, 0u, seed);
  float2 u;
  u.x = rng_next(&rng);
  u.y = rng_next(&rng);
  out[i] = (float4)(ggx_sample_visible(g, w.xyz, u), 0.0f);
}
