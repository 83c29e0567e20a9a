// Lambertian reflection in the local shading frame (z = shading normal): f = albedo / pi,
// cosine-weighted sampling. The albedo is the base colour (Bsdf.base_color).

void bsdf_diffuse_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {}

uint bsdf_diffuse_flags(const Bsdf* b) { return BSDF_REFLECTION | BSDF_DIFFUSE; }

float3 bsdf_diffuse_eval(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = sample_cosine_hemisphere_pdf(wi.z);
  return wi.z > 0.0f ? b->base_color * INV_PI_F : (float3)(0.0f);
}

bool bsdf_diffuse_sample(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs) {
  bs->wi = sample_cosine_hemisphere(u.x, u.y);
  bs->f = bsdf_diffuse_eval(b, wo, bs->wi, &bs->pdf);
  bs->flags = BSDF_REFLECTION | BSDF_DIFFUSE;
  bs->eta = 1.0f;
  return bs->pdf > 0.0f;
}

// One cosine lobe about the normal
void bsdf_diffuse_lobes(const Bsdf* b, float3 wo, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, 1.0f), bsdf_lobe_omega_cosine(), 1.0f);
}
