// The diffuse transmission (CD_FEATURE_DIFFUSE_TRANSMISSION): (1 - metallic)(1 - transmission)
// * d W(mu_o, |mu_i|) * colour / pi into the other hemisphere (KHR_materials_diffuse_transmission:
// the factor d takes that share of the plastic's diffuse base and transmits it, Lambertian,
// tinted by its colour). It passes the specular layer, the sheen and the coat as a reflection
// does (a sheet with the layers on both faces), so that a white base with colour 1 returns
// exactly the light a white plastic reflects, split (1 - d) : d.

// KHR_materials_diffuse_transmission's factor at the hit (0 where compiled out)
float gltf_diffuse_transmission(const Bsdf* b) {
#if CD_FEATURE_DIFFUSE_TRANSMISSION
  return b->lobe.gltf.diffuse_transmission;
#else
  return 0.0f;
#endif
}

float gltf_difftrans_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
#if CD_FEATURE_DIFFUSE_TRANSMISSION
  const GltfBsdf* lobe = &b->lobe.gltf;
  return g->outer * (1.0f - lobe->metallic) * (1.0f - lobe->transmission) * (1.0f - g->spec.a_o) *
         lobe->diffuse_transmission * luminance(lobe->diffuse_transmission_color);
#else
  return 0.0f;
#endif
}

int gltf_difftrans_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  float3 d = sample_cosine_hemisphere(u.x, u.y);
  bs->wi = (float3)(d.x, d.y, -d.z);
  return GLTF_SAMPLE_DIRECTION;
}

void gltf_difftrans_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, -1.0f), bsdf_lobe_omega_cosine(), w);
}

// Beside the base's other terms (the layers over it scale it as a reflection)
void gltf_difftrans_eval(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, GltfEval* acc) {
#if CD_FEATURE_DIFFUSE_TRANSMISSION
  const GltfBsdf* lobe = &b->lobe.gltf;
  float m = lobe->metallic, t = lobe->transmission;
  if (wi.z < 0.0f && lobe->diffuse_transmission > 0.0f) {
    acc->dtrans = (1.0f - m) * (1.0f - t) * lobe->diffuse_transmission *
                  gltf_below(&g->spec, energy_at((float3)(wi.x, wi.y, -wi.z))) * g->base_norm *
                  lobe->diffuse_transmission_color * INV_PI_F;
    acc->pdf += g->w[GLTF_DIFFTRANS] * sample_cosine_hemisphere_pdf(-wi.z);
  }
#endif
}

// Present where its factor (a GLTF_PARAMS value, as its colour) is
bool gltf_difftrans_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
#if CD_FEATURE_DIFFUSE_TRANSMISSION
  return b->lobe.gltf.diffuse_transmission > 0.0f;
#else
  return false;
#endif
}

// (the base's normalization under the coat is diffuse's: g->base_norm)
void gltf_difftrans_at_wo(const Bsdf* b, float3 wo, GltfAtWo* g) {}

uint gltf_difftrans_flags(const Bsdf* b) {
#if CD_FEATURE_DIFFUSE_TRANSMISSION
  const GltfBsdf* lobe = &b->lobe.gltf;
  bool plastic = lobe->metallic < 1.0f && lobe->transmission < 1.0f;
  if (plastic && lobe->diffuse_transmission > 0.0f && max_component(lobe->diffuse_transmission_color) > 0.0f)
    return BSDF_DIFFUSE | BSDF_TRANSMISSION;
#endif
  return 0u;
}
