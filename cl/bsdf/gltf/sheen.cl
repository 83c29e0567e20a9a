// The sheen (CD_FEATURE_SHEEN, KHR_materials_sheen), below the coat: sheen colour * Charlie
// sheen (cl/bsdf/sheen.cl) / max(1, E(mu_o), E(mu_i)). It scales reflections below by
// min(1 - c E(mu_o), 1 - c E(mu_i)) (the extension's albedo scaling, c = max3(sheen colour),
// E its albedo table, taken at most 1) and transmissions by 1 - c E at the outside
// direction's angle.

#if CD_FEATURE_SHEEN
// The sheen's albedo E(mu) with colour 1 (0 without the table)
float gltf_sheen_e(const Bsdf* b, float mu) {
  return sheen_albedo(b->lobe.gltf.sheen_albedo, mu, b->lobe.gltf.sheen_roughness);
}

// What the sheen leaves to the layers below it where its albedo is e: 1 - max3(colour) min(e, 1)
float gltf_sheen_below(const Bsdf* b, float e) {
  float c = max_component(b->lobe.gltf.sheen_color);
  return c > 0.0f ? fmax(1.0f - c * fmin(e, 1.0f), 0.0f) : 1.0f;
}

// The sheen lobe; where the Charlie lobe's albedo exceeds 1 (grazing angles at low sheen
// roughness) it is divided by max(1, E(mu_o), E(mu_i)), which keeps it reciprocal and its
// albedo at most 1
float3 gltf_sheen_f(const Bsdf* b, float e_o, float3 wo, float3 wi) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float norm = fmax(1.0f, fmax(e_o, gltf_sheen_e(b, wi.z)));
  return lobe->sheen_color * (sheen_eval(sheen_alpha(lobe->sheen_roughness), wo, wi) / norm);
}
#endif

// The layers between the coat and a mirror reflection of the base (the sheen, at mu_i = mu_o)
float3 gltf_mirror_below_sheen(const GltfAtWo* g, float3 weight) {
#if CD_FEATURE_SHEEN
  weight *= g->sheen_o;
#endif
  return weight;
}

float gltf_sheen_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
#if CD_FEATURE_SHEEN
  const GltfBsdf* lobe = &b->lobe.gltf;
  float e = lobe->sheen_albedo ? fmin(g->sheen_e_o, 1.0f) : 1.0f;
  return (1.0f - g->coat.a_o) * luminance(lobe->sheen_color) * fmax(e, 0.01f);
#else
  return 0.0f;
#endif
}

int gltf_sheen_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  bs->wi = sheen_sample(u);
  return GLTF_SAMPLE_DIRECTION;
}

// The sheen spreads over the hemisphere whatever its roughness: a cosine lobe's support
void gltf_sheen_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, 1.0f), bsdf_lobe_omega_cosine(), w);
}

// The sheen over the base's terms: albedo scaling, then its own lobe
void gltf_sheen_eval(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, GltfEval* acc) {
#if CD_FEATURE_SHEEN
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (max_component(lobe->sheen_color) > 0.0f) {
    if (wi.z > 0.0f) {
      acc->under = acc->under * fmin(g->sheen_o, gltf_sheen_below(b, gltf_sheen_e(b, wi.z))) +
                   gltf_sheen_f(b, g->sheen_e_o, wo, wi);
      acc->pdf += g->w[GLTF_SHEEN] * sheen_sample_pdf(wi);
    } else {
      float e_i = gltf_sheen_e(b, -wi.z);
      acc->under *= b->entering ? g->sheen_o : gltf_sheen_below(b, e_i);
      acc->dtrans *= fmin(g->sheen_o, gltf_sheen_below(b, e_i));
    }
  }
#endif
}

// Its albedo table (its colour and roughness are GLTF_PARAMS values); present where coloured
bool gltf_sheen_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
#if CD_FEATURE_SHEEN
  GltfBsdf* lobe = &b->lobe.gltf;
  lobe->sheen_albedo = sc->sheen_albedo;
  return max_component(lobe->sheen_color) > 0.0f;
#else
  return false;
#endif
}

// Its albedo at wo and what it leaves the layers below (after the coat's: g->outer)
void gltf_sheen_at_wo(const Bsdf* b, float3 wo, GltfAtWo* g) {
#if CD_FEATURE_SHEEN
  g->sheen_e_o = gltf_sheen_e(b, wo.z);
  g->sheen_o = gltf_sheen_below(b, g->sheen_e_o);
  g->outer *= g->sheen_o;
#endif
}

uint gltf_sheen_flags(const Bsdf* b) {
#if CD_FEATURE_SHEEN
  if (max_component(b->lobe.gltf.sheen_color) > 0.0f) return BSDF_GLOSSY;
#endif
  return 0u;
}
