// Energy compensation test kernels (cl/bsdf/energy.cl): the table as the lobes look it up, its
// quadrature off the nodes, an independent Monte Carlo estimate of the GGX albedo, and
// bsdf_sample / bsdf_eval of material 0 with or without the table.

// (E(mu), E_avg, E5(mu), E5_avg) for queries (mu, glTF roughness) of an isotropic lobe
__kernel void test_energy_lookup(__global const float* table, __global const float2* queries, __global float4* out) {
  uint i = get_global_id(0);
  GgxEnergy e = energy_ggx(table, ggx_from_roughness(queries[i].y, 0.0f), energy_dir(queries[i].x));
  out[i] = (float4)(e.e_o, e.e_avg, e.e5_o, e.e5_avg);
}

// E(mu) by the table's quadrature with n x n points, at any (mu, roughness)
__kernel void test_energy_quadrature(__global const float2* queries, uint n, __global float* out) {
  uint i = get_global_id(0);
  out[i] = energy_ggx_albedo_quadrature(ggx_from_roughness(queries[i].y, 0.0f), queries[i].x, n).x;
}

// Monte Carlo weights f cos_i / pdf of E(mu) with F = 1 (fresnel5 = 0) or of E5(mu) with
// F = (1 - wo.h)^5 (fresnel5 = 1) from half vectors distributed as D(h) cos theta_h (Walter
// et al. 2007), not the visible normals the table integrates over: work-item i draws n of
// them and writes their sum and sum of squares
__kernel void test_energy_albedo_mc(float mu, float roughness, uint fresnel5, uint seed, uint n, __global float2* out) {
  uint i = get_global_id(0);
  Rng rng = rng_init(i, 0u, seed);
  Ggx g = ggx_from_roughness(roughness, 0.0f);
  float3 wo = (float3)(sqrt(1.0f - mu * mu), 0.0f, mu);
  float2 sums = (float2)(0.0f);
  for (uint k = 0u; k < n; ++k) {
    float u1 = rng_next(&rng), u2 = rng_next(&rng);
    float cos_h = rsqrt(1.0f + g.ax * g.ax * u1 / (1.0f - u1));
    float sin_h = sqrt(fmax(0.0f, 1.0f - cos_h * cos_h));
    float cos_phi, sin_phi = sincos(2.0f * PI_F * u2, &cos_phi);
    float3 h = (float3)(sin_h * cos_phi, sin_h * sin_phi, cos_h);
    float3 wi = fresnel_reflect(wo, h);
    if (wi.z <= 0.0f || dot(wo, h) <= 0.0f) continue;
    float pdf, cos_oh;
    float f = ggx_reflection_eval(g, wo, wi, &pdf, &cos_oh);
    float w = f * wi.z / (ggx_d(g, h) * cos_h / (4.0f * cos_oh));
    if (fresnel5) w *= pown(1.0f - cos_oh, 5);
    sums += (float2)(w, w * w);
  }
  out[i] = sums;
}

// Material 0 at a point of normal +z and tangent +x seen from wo (above), with the table
// if asked: a scene of the material table alone
Bsdf test_energy_bsdf(__global const Material* materials, __global const float* table, uint with_table, float3 wo) {
  SceneData sc = test_bsdf_scene(materials);
  if (with_table) sc.ggx_albedo = table;
  return test_bsdf_flat_at(&sc, true, (float4)(0.0f));
}

// Sample i of bsdf_sample from wo, (uc, u.x, u.y) from rng_init(i, 0, seed): out[3i..3i+2] =
// (wi, pdf), (f, 1 for a non-delta reflection within bsdf_flags, else 0), (bsdf_eval,
// bsdf_pdf) at wi; all zero where sampling fails
__kernel void test_energy_sample(__global const Material* materials, __global const float* table, uint with_table,
                                 float4 wo, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  Bsdf b = test_energy_bsdf(materials, table, with_table, wo.xyz);
  BsdfSample bs;
  if (!test_bsdf_sample_record(&b, wo.xyz, i, seed, out, &bs)) return;
  bool valid = (bs.flags & ~bsdf_flags(&b)) == 0u && (bs.flags & BSDF_REFLECTION) && !(bs.flags & BSDF_DELTA);
  out[3 * i + 1].w = valid ? 1.0f : 0.0f;
}

// The weight f |cos| / pdf of sample i of bsdf_sample from wo (0 where sampling fails)
__kernel void test_energy_albedo(__global const Material* materials, __global const float* table, uint with_table,
                                 float4 wo, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  Bsdf b = test_energy_bsdf(materials, table, with_table, wo.xyz);
  BsdfSample bs;
  bool ok = test_bsdf_sample_i(&b, wo.xyz, i, seed, &bs);
  out[i] = ok ? (float4)(bs.f * fabs(bs.wi.z) / bs.pdf, 0.0f) : (float4)(0.0f);
}

// (bsdf_eval, bsdf_pdf) for the pairs (wo, wi) = (pairs[2i], pairs[2i + 1])
__kernel void test_energy_eval(__global const Material* materials, __global const float* table, uint with_table,
                               __global const float4* pairs, __global float4* out) {
  uint i = get_global_id(0);
  float3 wo = pairs[2 * i].xyz, wi = pairs[2 * i + 1].xyz;
  Bsdf b = test_energy_bsdf(materials, table, with_table, wo);
  out[i] = test_bsdf_eval_pdf(&b, wo, wi);
}
