// Measured conductor (complex index eta + i k per channel) with a Trowbridge-Reitz
// microfacet surface, in the local frame; a perfect mirror below GGX_DELTA_ALPHA.

float3 bsdf_conductor_eval(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (ggx_is_delta(b->ggx)) return (float3)(0.0f);
  float cos_oh;
  float f = ggx_reflection_eval(b->ggx, wo, wi, pdf, &cos_oh);
  return f * fresnel_conductor(cos_oh, b->cond_eta, b->cond_k);
}

bool bsdf_conductor_sample(const Bsdf* b, float3 wo, float2 u, BsdfSample* bs) {
  bs->eta = 1.0f;
  if (ggx_is_delta(b->ggx)) {
    if (wo.z <= 0.0f) return false;
    bs->wi = (float3)(-wo.x, -wo.y, wo.z);
    bs->f = fresnel_conductor(wo.z, b->cond_eta, b->cond_k) / wo.z;
    bs->pdf = 1.0f;
    bs->flags = BSDF_REFLECTION | BSDF_DELTA;
    return true;
  }
  if (!ggx_reflection_sample(b->ggx, wo, u, &bs->wi)) return false;
  bs->f = bsdf_conductor_eval(b, wo, bs->wi, &bs->pdf);
  bs->flags = BSDF_REFLECTION | BSDF_GLOSSY;
  return bs->pdf > 0.0f;
}
