// The multiple scattering of the metal and plastic GGX lobes (with the GGX albedo table:
// energy.cl, Kulla & Conty 2017), each coloured by its Schlick term's average, as a cosine
// lobe. The glass has its own (energy_dielectric.cl); the coat has none.

// Colour of the multiple-scattering lobe: each lobe's weight times its F_ms
float3 gltf_ms_fresnel(const Bsdf* b, const GgxEnergy* e) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float m = lobe->metallic, t = lobe->transmission;
  float3 metal = energy_ms_fresnel(e, energy_schlick_average(b->base_color, (float3)(1.0f)));
  float3 spec = energy_ms_fresnel(e, energy_schlick_average(lobe->spec_f0, (float3)(lobe->spec_f90)));
  return m * metal + (1.0f - m) * (1.0f - t) * spec;
}

float gltf_ms_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  return g->e.table ? g->outer * energy_ms_albedo(&g->e) * luminance(gltf_ms_fresnel(b, &g->e)) : 0.0f;
}

int gltf_ms_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  bs->wi = sample_cosine_hemisphere(u.x, u.y);
  return GLTF_SAMPLE_DIRECTION;
}

void gltf_ms_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, 1.0f), bsdf_lobe_omega_cosine(), w);
}

void gltf_ms_eval(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, GltfEval* acc) {
  if (wi.z > 0.0f && g->e.table) {
    if (g->e.e_avg < 1.0f) acc->under += gltf_ms_fresnel(b, &g->e) * energy_ms_of(&g->e, acc->e_i);
    acc->pdf += g->w[GLTF_MS] * sample_cosine_hemisphere_pdf(wi.z);
  }
}

// It has no parameters of its own (its colour follows the metal's and spec's)
bool gltf_ms_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) { return false; }

void gltf_ms_at_wo(const Bsdf* b, float3 wo, GltfAtWo* g) {}

// (glossy where the metal or spec is)
uint gltf_ms_flags(const Bsdf* b) { return 0u; }
