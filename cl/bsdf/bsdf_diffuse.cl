// Lambertian reflection in the local shading frame (z = shading normal): f = albedo / pi,
// cosine-weighted sampling.

float3 bsdf_diffuse_eval(float3 albedo, float3 wo, float3 wi) {
  return wi.z > 0.0f ? albedo * INV_PI_F : (float3)(0.0f);
}

float bsdf_diffuse_pdf(float3 wo, float3 wi) { return sample_cosine_hemisphere_pdf(wi.z); }

bool bsdf_diffuse_sample(float3 albedo, float3 wo, float2 u, BsdfSample* bs) {
  bs->wi = sample_cosine_hemisphere(u.x, u.y);
  bs->pdf = sample_cosine_hemisphere_pdf(bs->wi.z);
  bs->f = bsdf_diffuse_eval(albedo, wo, bs->wi);
  bs->flags = BSDF_REFLECTION | BSDF_DIFFUSE;
  bs->eta = 1.0f;
  return bs->pdf > 0.0f;
}
