// BSDF test kernels: the real bsdf_at / bsdf_sample / bsdf_eval / bsdf_pdf at a made-up
// shading point of material 0, so that every lobe is tested through the same dispatch the
// integrator uses. Normals and the tangent come from the host unoriented, as a mesh has them.

#define TEST_BSDF_NO_BUFFER(type, name) 0,

// A scene that holds only a material table; every other buffer is null
SceneData test_bsdf_scene(__global const Material* materials) {
  SceneData sc = {CD_SCENE_BUFFERS(TEST_BSDF_NO_BUFFER) 0};
  sc.materials = materials;
  return sc;
}

// A hit of `material` seen from wo (wo = -ray direction), oriented as surface_at does:
// ng turned to wo's side, ns turned to ng's side
SurfaceHit test_bsdf_hit(float3 ng, float3 ns, float3 tangent, float3 wo, uint material) {
  SurfaceHit s;
  s.p = (float3)(0.0f);
  s.ng = normalize(ng);
  s.front = dot(s.ng, wo) > 0.0f;
  if (!s.front) s.ng = -s.ng;
  s.ns = normalize(ns);
  if (dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
  s.tangent = tangent;
  s.tangent_sign = 1.0f;
  s.uvs = (float4)(0.0f);
  s.vertex_color = (float3)(1.0f);
  s.prim = 0u;
  s.material = material;
  return s;
}

// A hit of material 0 at the origin with normal +z (geometric and shading) and tangent +x,
// on the side `front` says, at texture coordinates `uvs`: the flat point of the energy,
// dielectric-energy, sheen and glTF-layer test kernels
SurfaceHit test_bsdf_flat_hit(bool front, float4 uvs) {
  SurfaceHit s;
  s.p = (float3)(0.0f);
  s.ng = s.ns = (float3)(0.0f, 0.0f, 1.0f);
  s.tangent = (float3)(1.0f, 0.0f, 0.0f);
  s.tangent_sign = 1.0f;
  s.uvs = uvs;
  s.vertex_color = (float3)(1.0f);
  s.prim = s.material = 0u;
  s.front = front;
  return s;
}

// bsdf_sample of b from wo with (uc, u.x, u.y) drawn in that order from rng_init(i, 0, seed)
bool test_bsdf_sample_i(const Bsdf* b, float3 wo, uint i, uint seed, BsdfSample* bs) {
  Rng rng = rng_init(i, 0u, seed);
  float uc = rng_next(&rng);
  float2 u;
  u.x = rng_next(&rng);
  u.y = rng_next(&rng);
  return bsdf_sample(b, wo, uc, u, bs);
}

// bsdf_at of material 0 at the flat point (test_bsdf_flat_hit) of scene sc
Bsdf test_bsdf_flat_at(const SceneData* sc, bool front, float4 uvs) {
  SurfaceHit s = test_bsdf_flat_hit(front, uvs);
  return bsdf_at(sc, &s);
}

// (bsdf_eval, bsdf_pdf) at (wo, wi), from one bsdf_eval_pdf
float4 test_bsdf_eval_pdf(const Bsdf* b, float3 wo, float3 wi) {
  float pdf;
  float3 f = bsdf_eval_pdf(b, wo, wi, &pdf);
  return (float4)(f, pdf);
}

// Sample i of bsdf_sample (test_bsdf_sample_i) into out[3i..3i+2] = (wi, pdf), (f, 1 for a
// delta sample, else 0), (bsdf_eval, bsdf_pdf) at wi, as the flat-point test kernels write
// it; all zero, and false, where sampling fails
bool test_bsdf_sample_record(const Bsdf* b, float3 wo, uint i, uint seed, __global float4* out, BsdfSample* bs) {
  if (!test_bsdf_sample_i(b, wo, i, seed, bs)) {
    out[3 * i] = out[3 * i + 1] = out[3 * i + 2] = (float4)(0.0f);
    return false;
  }
  out[3 * i] = (float4)(bs->wi, bs->pdf);
  out[3 * i + 1] = (float4)(bs->f, (bs->flags & BSDF_DELTA) ? 1.0f : 0.0f);
  out[3 * i + 2] = test_bsdf_eval_pdf(b, wo, bs->wi);
  return true;
}

// Sample i of bsdf_sample of material 0 of sc with (uc, u.x, u.y) drawn in that order from
// rng_init(i, 0, seed). out[3i..3i+2]: (wi, pdf), (f, eta), (bsdf_eval, bsdf_pdf) at the
// sampled wi, all zero when sampling fails; info[i]: (returned, BSDF_DELTA set,
// BSDF_REFLECTION set, flags valid: within bsdf_flags and exactly one of reflection and
// transmission), 0 where not returned
void test_bsdf_sample_at(const SceneData* sc, float4 ng, float4 ns, float4 tangent, float4 wo, uint seed,
                         __global float4* out, __global uint4* info) {
  uint i = get_global_id(0);
  SurfaceHit s = test_bsdf_hit(ng.xyz, ns.xyz, tangent.xyz, wo.xyz, 0u);
  Bsdf b = bsdf_at(sc, &s);
  BsdfSample bs;
  bool ok = test_bsdf_sample_i(&b, wo.xyz, i, seed, &bs);
  if (!ok) {
    out[3 * i] = out[3 * i + 1] = out[3 * i + 2] = (float4)(0.0f);
    info[i] = (uint4)(0u);
    return;
  }
  out[3 * i] = (float4)(bs.wi, bs.pdf);
  out[3 * i + 1] = (float4)(bs.f, bs.eta);
  out[3 * i + 2] = (float4)(bsdf_eval(&b, wo.xyz, bs.wi), bsdf_pdf(&b, wo.xyz, bs.wi));
  uint side = bs.flags & (BSDF_REFLECTION | BSDF_TRANSMISSION);
  bool valid = (bs.flags & ~bsdf_flags(&b)) == 0u && (side == BSDF_REFLECTION || side == BSDF_TRANSMISSION);
  info[i] = (uint4)(1u, (bs.flags & BSDF_DELTA) != 0u ? 1u : 0u, side == BSDF_REFLECTION ? 1u : 0u, valid ? 1u : 0u);
}

// f and pdf of material 0 of sc for the pair (wo, wi) = (pairs[2i], pairs[2i+1]) at a hit
// oriented by that wo; out[i] = (f, pdf), from one bsdf_eval_pdf (test_bsdf_sample covers
// bsdf_eval and bsdf_pdf)
void test_bsdf_eval_at(const SceneData* sc, float4 ng, float4 ns, float4 tangent, __global const float4* pairs,
                       __global float4* out) {
  uint i = get_global_id(0);
  float3 wo = pairs[2 * i].xyz, wi = pairs[2 * i + 1].xyz;
  SurfaceHit s = test_bsdf_hit(ng.xyz, ns.xyz, tangent.xyz, wo, 0u);
  Bsdf b = bsdf_at(sc, &s);
  out[i] = test_bsdf_eval_pdf(&b, wo, wi);
}

// test_bsdf_sample_at in a scene of the material table alone (no energy compensation)
__kernel void test_bsdf_sample(__global const Material* materials, float4 ng, float4 ns, float4 tangent, float4 wo,
                               uint seed, __global float4* out, __global uint4* info) {
  SceneData sc = test_bsdf_scene(materials);
  test_bsdf_sample_at(&sc, ng, ns, tangent, wo, seed, out, info);
}

// Bit-for-bit equality (a NaN equals itself, 0 and -0 differ)
bool test_same_bits(float a, float b) { return as_uint(a) == as_uint(b); }
bool test_same_bits3(float3 a, float3 b) {
  return test_same_bits(a.x, b.x) && test_same_bits(a.y, b.y) && test_same_bits(a.z, b.z);
}

// Sample i of material 0 seen from wo, (uc, u) drawn from rng_init(i, 0, seed), through
// bsdf_sample_lobes (the integrator's call: the sample and the lobes at wo together) against
// bsdf_sample and bsdf_lobes called apart: out[i] = (1 when the lobes are the same bit for
// bit, their count, 1 when bsdf_sample_lobes returned a sample, 1 when both calls returned
// the same answer and, if a sample, the same one bit for bit)
__kernel void test_bsdf_lobes(__global const Material* materials, float4 ng, float4 ns, float4 tangent, float4 wo,
                              uint seed, __global uint4* out) {
  uint i = get_global_id(0);
  SceneData sc = test_bsdf_scene(materials);
  SurfaceHit s = test_bsdf_hit(ng.xyz, ns.xyz, tangent.xyz, wo.xyz, 0u);
  Bsdf b = bsdf_at(&sc, &s);
  Rng rng = rng_init(i, 0u, seed);
  float uc = rng_next(&rng);
  float2 u = rng_next_2d(&rng);
  BsdfSample with, apart;
  BsdfLobes lobes;
  bool ok = bsdf_sample_lobes(&b, wo.xyz, uc, u, &with, &lobes);
  bool ok_apart = bsdf_sample(&b, wo.xyz, uc, u, &apart);
  BsdfLobes alone = bsdf_lobes(&b, wo.xyz);
  bool same_lobes = lobes.count == alone.count;
  for (uint k = 0u; same_lobes && k < alone.count; ++k)
    same_lobes = test_same_bits3(lobes.dir[k], alone.dir[k]) && test_same_bits(lobes.omega[k], alone.omega[k]) &&
                 test_same_bits(lobes.weight[k], alone.weight[k]);
  bool same_sample = ok == ok_apart;
  if (same_sample && ok)
    same_sample = test_same_bits3(with.wi, apart.wi) && test_same_bits3(with.f, apart.f) &&
                  test_same_bits(with.pdf, apart.pdf) && test_same_bits(with.eta, apart.eta) &&
                  with.flags == apart.flags;
  out[i] = (uint4)(same_lobes ? 1u : 0u, alone.count, ok ? 1u : 0u, same_sample ? 1u : 0u);
}

// test_bsdf_eval_at in a scene of the material table alone
__kernel void test_bsdf_eval(__global const Material* materials, float4 ng, float4 ns, float4 tangent,
                             __global const float4* pairs, __global float4* out) {
  SceneData sc = test_bsdf_scene(materials);
  test_bsdf_eval_at(&sc, ng, ns, tangent, pairs, out);
}

// test_bsdf_sample_at with the GGX albedo table bound (cl/bsdf/energy.cl,
// energy_dielectric.cl: the lobes' energy compensation on)
__kernel void test_bsdf_sample_ggx(__global const Material* materials, __global const float* ggx_albedo, float4 ng,
                                   float4 ns, float4 tangent, float4 wo, uint seed, __global float4* out,
                                   __global uint4* info) {
  SceneData sc = test_bsdf_scene(materials);
  sc.ggx_albedo = ggx_albedo;
  test_bsdf_sample_at(&sc, ng, ns, tangent, wo, seed, out, info);
}

// test_bsdf_eval_at with the GGX albedo table bound
__kernel void test_bsdf_eval_ggx(__global const Material* materials, __global const float* ggx_albedo, float4 ng,
                                 float4 ns, float4 tangent, __global const float4* pairs, __global float4* out) {
  SceneData sc = test_bsdf_scene(materials);
  sc.ggx_albedo = ggx_albedo;
  test_bsdf_eval_at(&sc, ng, ns, tangent, pairs, out);
}

// Albedo samples: work-item i estimates configuration c = i / per_config, material
// c / n_wo seen from wos[c % n_wo]. out[i] = (f |cos| / pdf * eta^2, returned), where
// eta = bs.eta (eta_wi / eta_wo) undoes the 1 / eta^2 radiance scaling of refraction
__kernel void test_bsdf_albedo(__global const Material* materials, float4 ng, float4 ns, float4 tangent,
                               __global const float4* wos, uint n_wo, uint per_config, uint seed,
                               __global float4* out) {
  uint i = get_global_id(0), c = i / per_config;
  SceneData sc = test_bsdf_scene(materials);
  float3 wo = wos[c % n_wo].xyz;
  SurfaceHit s = test_bsdf_hit(ng.xyz, ns.xyz, tangent.xyz, wo, c / n_wo);
  Bsdf b = bsdf_at(&sc, &s);
  BsdfSample bs;
  out[i] = (float4)(0.0f);
  if (!test_bsdf_sample_i(&b, wo, i, seed, &bs)) return;
  float w = fabs(dot(bs.wi, b.frame.n)) / bs.pdf * bs.eta * bs.eta;
  out[i] = (float4)(bs.f * w, 1.0f);
}
