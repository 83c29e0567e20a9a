// Lambertian reflection in the local shading frame (z = shading normal): f = albedo / pi,
// cosine-weighted sampling. The albedo is the base colour (Bsdf.base_color).

void bsdf_diffuse_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {}

uint bsdf_diffuse_flags(const Bsdf* b) { return BSDF_REFLECTION | BSDF_DIFFUSE; }

float3 bsdf_diffuse_eval(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = sample_cosine_hemisphere_pdf(wi.z);
  return wi.z > 0.0f ? b->base_color * INV_PI_F : (float3)(0.0f);
}

// One cosine lobe about the normal
void bsdf_diffuse_lobes(const Bsdf* b, float3 wo, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, 1.0f), bsdf_lobe_omega_cosine(), 1.0f);
}

bool bsdf_diffuse_sample(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs, BsdfLobes* l) {
  if (l) bsdf_diffuse_lobes(b, wo, l);
  bs->wi = sample_cosine_hemisphere(u.x, u.y);
  bs->f = bsdf_diffuse_eval(b, wo, bs->wi, &bs->pdf);
  bs->flags = BSDF_REFLECTION | BSDF_DIFFUSE;
  bs->eta = 1.0f;
  return bs->pdf > 0.0f;
}

// Energy-preserving Oren-Nayar (EON: Portsmouth, Kutz & Hill 2025, OpenPBR's rough diffuse;
// KHR_materials_diffuse_roughness), in the local frame, wi and wo above the surface. Fujii's
// single scattering f_ss = rho / pi A (1 + r s / t), A = 1 / (1 + c1 r), s = wi.wo - mu_i mu_o,
// t = max(mu_i, mu_o) where s > 0 (else 1), c1 = 1/2 - 2 / (3 pi), plus the multiple scattering
// f_ms = rho_ms / pi (1 - E(mu_o)) (1 - E(mu_i)) / (1 - E_avg), with E the single scattering's
// directional albedo (closed form), E_avg = A (1 + c2 r) its cosine-weighted mean, c2 = 2/3 -
// 28 / (15 pi), and rho_ms = rho^2 E_avg / (1 - rho (1 - E_avg)): a white surface reflects
// exactly 1 at every angle. Sampled as Lambert (cosine-weighted).
#define EON_C1 (0.5f - 2.0f / (3.0f * PI_F))
#define EON_C2 (2.0f / 3.0f - 28.0f / (15.0f * PI_F))

// E(mu) = A (1 + r G(mu) / pi), G(mu) = S (acos mu - S mu) + 2/3 (S / mu (1 - S^3) - S),
// S = sin theta; S / mu (1 - S^3) is written as S mu (1 + S + S^2) / (1 + S), which has no
// cancellation at grazing angles
float diffuse_eon_albedo(float mu, float r) {
  mu = clamp(mu, 0.0f, 1.0f);
  float sn = sqrt(fmax(1.0f - mu * mu, 0.0f));
  float g = sn * (acos(mu) - sn * mu) + (2.0f / 3.0f) * (sn * mu * (1.0f + sn + sn * sn) / (1.0f + sn) - sn);
  return (1.0f + r * INV_PI_F * g) / (1.0f + EON_C1 * r);
}

// pi (f_ss + f_ms) of albedo rho at roughness r in (0, 1]; 0 below the surface. e_o:
// diffuse_eon_albedo(wo.z, r), which the caller computes once per wo
float3 diffuse_eon_eval_pi(float3 rho, float r, float e_o, float3 wo, float3 wi) {
  if (!(wi.z > 0.0f)) return (float3)(0.0f);
  float mu_i = fmin(wi.z, 1.0f), mu_o = clamp(wo.z, 0.0f, 1.0f);
  float s = dot(wi, wo) - mu_i * mu_o;
  float s_over_t = s > 0.0f ? s / fmax(mu_i, mu_o) : s;
  float a = 1.0f / (1.0f + EON_C1 * r);
  float e_avg = a * (1.0f + EON_C2 * r);
  float3 rho_ms = rho * rho * e_avg / ((float3)(1.0f) - rho * (1.0f - e_avg));
  float ms = (1.0f - e_o) * (1.0f - diffuse_eon_albedo(mu_i, r)) / (1.0f - e_avg);
  return rho * (a * (1.0f + r * s_over_t)) + rho_ms * ms;
}
