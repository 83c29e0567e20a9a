// Measured conductor (complex index eta + i k per channel) with a Trowbridge-Reitz
// microfacet surface, in the local frame; a perfect mirror below GGX_DELTA_ALPHA. With the
// GGX albedo table, the multiple scattering of energy.cl (Kulla & Conty 2017) is added
// and sampled by the cosine with probability ms_share, so that eval and pdf stay one mixture.

void bsdf_conductor_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
  __global const ConductorMaterial* c = &m->params.conductor;
  ConductorBsdf* p = &b->lobe.conductor;
  p->ggx = bsdf_microfacet_at(sc, m, s, c->roughness, c->anisotropy_strength, c->anisotropy_rotation, &b->frame);
  p->eta = load3(c->eta);
  p->k = load3(c->k);
  p->f_avg = (float3)(1.0f);
  if (b->ggx_albedo && !ggx_is_delta(p->ggx)) p->f_avg = energy_conductor_average(p->eta, p->k);
}

uint bsdf_conductor_flags(const Bsdf* b) {
  return BSDF_REFLECTION | (ggx_is_delta(b->lobe.conductor.ggx) ? BSDF_DELTA : BSDF_GLOSSY);
}

// Probability of sampling the multiple-scattering lobe: its share of the albedo at wo
float bsdf_conductor_ms_share(const ConductorBsdf* p, const GgxEnergy* e, float3 f_ms) {
  float ms = energy_ms_albedo(e) * luminance(f_ms);
  float total = e->e_o * luminance(p->f_avg) + ms;
  return total > 0.0f ? ms / total : 0.0f;
}

float3 bsdf_conductor_eval(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
  const ConductorBsdf* p = &b->lobe.conductor;
  *pdf = 0.0f;
  if (ggx_is_delta(p->ggx)) return (float3)(0.0f);
  float cos_oh;
  float f = ggx_reflection_eval(p->ggx, wo, wi, pdf, &cos_oh);
  float3 single = f * fresnel_conductor(cos_oh, p->eta, p->k);
  GgxEnergy e = energy_ggx(b->ggx_albedo, p->ggx, energy_at(wo));
  if (!e.table || wo.z <= 0.0f || wi.z <= 0.0f) return single;
  float3 f_ms = energy_ms_fresnel(&e, p->f_avg);
  float q = bsdf_conductor_ms_share(p, &e, f_ms);
  *pdf = (1.0f - q) * *pdf + q * sample_cosine_hemisphere_pdf(wi.z);
  return single + f_ms * energy_ms(&e, energy_at(wi));
}

// The GGX reflection about the mirror direction, and the multiple-scattering cosine lobe
void bsdf_conductor_lobes(const Bsdf* b, float3 wo, BsdfLobes* l) {
  const ConductorBsdf* p = &b->lobe.conductor;
  if (ggx_is_delta(p->ggx) || wo.z <= 0.0f) return;
  GgxEnergy e = energy_ggx(b->ggx_albedo, p->ggx, energy_at(wo));
  float q = e.table ? bsdf_conductor_ms_share(p, &e, energy_ms_fresnel(&e, p->f_avg)) : 0.0f;
  bsdf_lobes_add(l, (float3)(-wo.x, -wo.y, wo.z), bsdf_lobe_omega_ggx(p->ggx), 1.0f - q);
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, 1.0f), bsdf_lobe_omega_cosine(), q);
}

bool bsdf_conductor_sample(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs, BsdfLobes* l) {
  if (l) bsdf_conductor_lobes(b, wo, l);
  const ConductorBsdf* p = &b->lobe.conductor;
  bs->eta = 1.0f;
  if (ggx_is_delta(p->ggx)) {
    if (wo.z <= 0.0f) return false;
    bs->wi = (float3)(-wo.x, -wo.y, wo.z);
    bs->f = fresnel_conductor(wo.z, p->eta, p->k) / wo.z;
    bs->pdf = 1.0f;
    bs->flags = BSDF_REFLECTION | BSDF_DELTA;
    return true;
  }
  if (wo.z <= 0.0f) return false;
  GgxEnergy e = energy_ggx(b->ggx_albedo, p->ggx, energy_at(wo));
  float q = e.table ? bsdf_conductor_ms_share(p, &e, energy_ms_fresnel(&e, p->f_avg)) : 0.0f;
  if (uc < q)
    bs->wi = sample_cosine_hemisphere(u.x, u.y);
  else if (!ggx_reflection_sample(p->ggx, wo, u, &bs->wi))
    return false;
  bs->f = bsdf_conductor_eval(b, wo, bs->wi, &bs->pdf);
  bs->flags = BSDF_REFLECTION | BSDF_GLOSSY;
  return bs->pdf > 0.0f;
}
