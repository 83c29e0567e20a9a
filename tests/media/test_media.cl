// Phase function and media test kernels (cl/media/phase.cl, cl/media/media.cl).

// One phase_sample per work-item for (g, wo): out[i] = (wi, pdf), and phase_pdf at the
// sampled wi in evals[i]
__kernel void test_phase_sample(float g, float4 wo, uint seed, __global float4* out, __global float* evals) {
  uint i = get_global_id(0);
  Rng rng = rng_init(i, 0u, seed);
  float2 u = (float2)(rng_next(&rng), rng_next(&rng));
  float pdf;
  float3 wi = phase_sample(g, wo.xyz, u, &pdf);
  out[i] = (float4)(wi, pdf);
  evals[i] = phase_pdf(g, wo.xyz, wi);
}

// phase_eval(g, wo, dirs[i]) for given directions
__kernel void test_phase_eval(float g, float4 wo, __global const float4* dirs, __global float* out) {
  uint i = get_global_id(0);
  out[i] = phase_eval(g, wo.xyz, dirs[i].xyz);
}

// media_shadow_transmittance from org along dir up to tmax (through null boundaries),
// starting in the media org lies in (media_at_origin), one estimate per work-item
__kernel void test_media_transmittance(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params, float4 org,
                                       float4 dir, float tmax, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  Rng rng = rng_init(i, 0u, seed);
  Ray r = {org.xyz, dir.xyz};
  MediumStack st = media_at_origin(&sc, r);
  float3 tr = media_shadow_transmittance(&sc, r, tmax, st, &rng);
  out[i] = (float4)(tr, (float)st.count);
}

// Delta tracking's free flight as the integrator runs it (path_medium_step): from org along
// dir, in the medium org lies in (media_at_origin), up to the first surface or tmax,
// whichever is nearer, media_sample_segment samples where the path scatters next.
// out[i] = (beta, event): event MEDIUM_PASSED (0) means the flight reached the end, and
// beta is the weight it carries there (1 for grey media).
__kernel void test_media_free_flight(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params, float4 org,
                                     float4 dir, float tmax, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  Rng rng = rng_init(i, 0u, seed);
  Ray r = {org.xyz, dir.xyz};
  MediumStack st = media_at_origin(&sc, r);
  Hit hit = scene_intersect(&sc, r, INFINITY);
  float t = hit.prim < 0 ? tmax : fmin(hit.t, tmax);
  float3 beta = (float3)(1.0f), radiance = (float3)(0.0f), p = (float3)(0.0f);
  int event = media_sample_segment(&sc, media_current(&st), r, t, &rng, &beta, &radiance, &p);
  out[i] = (float4)(beta, (float)event);
}
