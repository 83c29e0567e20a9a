// The plastic's diffuse base: (1 - metallic)(1 - transmission)(1 - diffuse transmission) *
// W(mu_o, mu_i) * base / pi below the specular layer (spec.cl; W the layering in
// mixture.cl), Lambertian, or EON where KHR_materials_diffuse_roughness
// (CD_FEATURE_DIFFUSE_ROUGHNESS) roughens it.

// pi x the diffuse base's BRDF: the base colour (Lambert), or pi x EON where
// KHR_materials_diffuse_roughness roughens it
float3 gltf_base_diffuse_pi(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi) {
#if CD_FEATURE_DIFFUSE_ROUGHNESS
  float r = b->lobe.gltf.diffuse_roughness;
  if (r > 0.0f) return diffuse_eon_eval_pi(b->base_color, r, g->eon_e_o, wo, wi);
#endif
  return b->base_color;
}

float gltf_diffuse_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  return g->outer * (1.0f - lobe->metallic) * (1.0f - lobe->transmission) * (1.0f - g->spec.a_o) *
         (1.0f - gltf_diffuse_transmission(b)) * luminance(b->base_color);
}

int gltf_diffuse_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  bs->wi = sample_cosine_hemisphere(u.x, u.y);
  return GLTF_SAMPLE_DIRECTION;
}

void gltf_diffuse_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, 1.0f), bsdf_lobe_omega_cosine(), w);
}

// The first term of f in evaluation order: it sets acc->under
void gltf_diffuse_eval(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, GltfEval* acc) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float m = lobe->metallic, t = lobe->transmission;
  if (wi.z > 0.0f) {
    acc->under = (1.0f - m) * (1.0f - t) * (1.0f - gltf_diffuse_transmission(b)) *
                 gltf_below_of(&g->spec, gltf_layer_albedo_of(&g->spec, acc->e_i, acc->e5_i)) * g->base_norm *
                 gltf_base_diffuse_pi(b, g, wo, wi) * INV_PI_F;
    acc->pdf += g->w[GLTF_DIFFUSE] * sample_cosine_hemisphere_pdf(wi.z);
  }
}

// Its roughness (KHR_materials_diffuse_roughness, a GLTF_PARAMS value) within [0, 1]; the
// colour is the base colour
bool gltf_diffuse_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
#if CD_FEATURE_DIFFUSE_ROUGHNESS
  GltfBsdf* lobe = &b->lobe.gltf;
  lobe->diffuse_roughness = clamp(lobe->diffuse_roughness, 0.0f, 1.0f);
  return lobe->diffuse_roughness > 0.0f;
#else
  return false;
#endif
}

// The base's normalization under the coat and the specular layer (after both: their layers
// at wo), and the EON albedo at wo of a rough base
void gltf_diffuse_at_wo(const Bsdf* b, float3 wo, GltfAtWo* g) {
  g->base_norm = gltf_coat_base_norm(b, &g->coat, &g->spec);
#if CD_FEATURE_DIFFUSE_ROUGHNESS
  float r = b->lobe.gltf.diffuse_roughness;
  g->eon_e_o = r > 0.0f ? diffuse_eon_albedo(wo.z, r) : 1.0f;
#endif
}

uint gltf_diffuse_flags(const Bsdf* b) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  bool plastic = lobe->metallic < 1.0f && lobe->transmission < 1.0f;
  return plastic && max_component(b->base_color) > 0.0f ? BSDF_DIFFUSE : 0u;
}
