// Test kernels of the rough dielectric's compensation (cl/bsdf/energy_dielectric.cl): the
// table as looked up, its quadrature anywhere, and bsdf_sample / bsdf_eval of material 0
// seen from either side of the surface.

// (E_s(mu), E_s,avg) for queries (mu, glTF roughness, eta seen from wo, 0)
__kernel void test_energy_dielectric_lookup(__global const float* table, __global const float4* queries,
                                            __global float2* out) {
  uint i = get_global_id(0);
  float4 q = queries[i];
  DielectricEnergy d = energy_dielectric_cells(table, ggx_from_roughness(q.y, 0.0f), q.z);
  out[i] = (float2)(energy_dielectric_lookup(&d, d.side, energy_dir(q.x)), energy_dielectric_average(&d, d.side));
}

#if CD_FEATURE_ANISOTROPY
// The anisotropic table: (E_s(wo), E_s,avg) for queries (wo, eta seen from wo) and
// (glTF roughness, anisotropy strength) in params: the lobe KHR_materials_anisotropy makes
__kernel void test_energy_dielectric_aniso_lookup(__global const float* table, __global const float4* queries,
                                                  float2 params, __global float2* out) {
  uint i = get_global_id(0);
  float4 q = queries[i];
  DielectricEnergy d = energy_dielectric_cells(table, ggx_from_roughness(params.x, params.y), q.w);
  out[i] = (float2)(energy_dielectric_lookup(&d, d.side, q.xyz), energy_dielectric_average(&d, d.side));
}

// E_s(wo) of the same lobes by quadrature with n x n points
__kernel void test_energy_dielectric_aniso_quadrature(__global const float4* queries, float2 params, uint n,
                                                      __global float* out) {
  uint i = get_global_id(0);
  float4 q = queries[i];
  out[i] = energy_dielectric_quadrature_wo(ggx_from_roughness(params.x, params.y), q.w, q.xyz, n);
}
#endif

// E_s(mu) by the table's quadrature with n x n points, for the same queries
__kernel void test_energy_dielectric_quadrature(__global const float4* queries, uint n, __global float* out) {
  uint i = get_global_id(0);
  float4 q = queries[i];
  out[i] = energy_dielectric_quadrature(ggx_from_roughness(q.y, 0.0f), q.z, q.x, n);
}

// Material 0 at a point of normal +z and tangent +x, hit from its front (entering) or back
Bsdf test_energy_dielectric_bsdf(__global const Material* materials, __global const float* table, uint with_table,
                                 uint front) {
  SceneData sc = test_bsdf_scene(materials);
  if (with_table) sc.ggx_albedo = table;
  return test_bsdf_flat_at(&sc, front != 0u, (float4)(0.0f));
}

// Sample i from wo: out[2i] = (X |cos_i| / pdf, 1 if f and pdf are bsdf_eval's and
// bsdf_pdf's), X = f (n_i / n_o)^2 = f bs.eta^2; out[2i + 1] = (wi, pdf); zeros on failure
__kernel void test_energy_dielectric_sample(__global const Material* materials, __global const float* table,
                                            uint with_table, uint front, float4 wo, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  Bsdf b = test_energy_dielectric_bsdf(materials, table, with_table, front);
  BsdfSample bs;
  out[2 * i] = out[2 * i + 1] = (float4)(0.0f);
  if (!test_bsdf_sample_i(&b, wo.xyz, i, seed, &bs)) return;
  float pdf;
  float3 f = bsdf_eval_pdf(&b, wo.xyz, bs.wi, &pdf);
  bool same = fabs(pdf - bs.pdf) <= 1e-4f * pdf;
  for (int c = 0; c < 3; ++c) same = same && fabs(f[c] - bs.f[c]) <= 1e-4f * fmax(f[c], bs.f[c]) + 1e-12f;
  if (bs.flags & BSDF_DELTA) same = true;
  out[2 * i] = (float4)(bs.f * bs.eta * bs.eta * fabs(bs.wi.z) / bs.pdf, same ? 1.0f : 0.0f);
  out[2 * i + 1] = (float4)(bs.wi, bs.pdf);
}

// (X(wo, wi), Y(wo, wi)) for pairs (wo, wi, front) = (pairs[2i].xyz, pairs[2i + 1].xyz,
// pairs[2i].w): X = f (n_i / n_o)^2 with the lobe's eta on transmission, Y = f / n_o^2 (the
// reciprocal quantity; green channel), the outside's index 1
__kernel void test_energy_dielectric_eval(__global const Material* materials, __global const float* table,
                                          __global const float4* pairs, __global float4* out) {
  uint i = get_global_id(0);
  float3 wo = pairs[2 * i].xyz, wi = pairs[2 * i + 1].xyz;
  Bsdf b = test_energy_dielectric_bsdf(materials, table, 1u, pairs[2 * i].w != 0.0f ? 1u : 0u);
  float pdf;
  float3 f = bsdf_eval_pdf(&b, wo, wi, &pdf);
  bool volume = b.type == MATERIAL_GLTF && !b.lobe.gltf.thin;
  float eta = volume && wi.z < 0.0f ? b.lobe.gltf.eta : 1.0f;
  float n_o = volume && !b.entering ? b.lobe.gltf.eta : 1.0f;  // 1 / n_o inside
  out[i] = (float4)(f * eta * eta, f.y * n_o * n_o);
}
