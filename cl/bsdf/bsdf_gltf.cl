// The glTF metallic-roughness BSDF (glTF 2.0 Appendix B, KHR_materials_* extensions) in the
// local frame: the material's parameters at the hit, and the mixture of the components of
// cl/bsdf/gltf/ composed through their lists (gltf/mixture.cl): the weights at wo, the
// sum of their terms of f and pdf, their lobes, and the choice of one to sample.

// The material at the hit: factors times textures. First the per-hit values of GLTF_PARAMS
// (their lists' loads), then the base's parameters, which the metal, spec and glass share;
// then each component's own (gltf_NAME_params), and the Fresnel terms' modifiers.
// KHR_materials_specular gives F0 = min(F0(ior) x colour, 1) x specular and F90 = specular.
// Where no component but the diffuse base is present (each returns whether it is) the BSDF
// is exactly Lambertian: MATERIAL_DIFFUSE takes the short path.
#define GLTF_LOAD_x(name, slot) lobe->name = g->name * bsdf_texture(sc, m, slot, s).x;
#define GLTF_LOAD_y(name, slot) lobe->name = g->name * bsdf_texture(sc, m, slot, s).y;
#define GLTF_LOAD_z(name, slot) lobe->name = g->name * bsdf_texture(sc, m, slot, s).z;
#define GLTF_LOAD_w(name, slot) lobe->name = g->name * bsdf_texture(sc, m, slot, s).w;
#define GLTF_LOAD_xyz(name, slot) lobe->name = load3(g->name) * bsdf_texture(sc, m, slot, s).xyz;
#define GLTF_LOAD_factor(name, slot) lobe->name = g->name;
#define GLTF_LOAD__(name, slot)
#define GLTF_LOAD(_, name, n, def, lo, hi, ext, key, slot, load, feature, role) \
  CD_IF(feature)(GLTF_LOAD_##load(name, slot))
void bsdf_gltf_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
  __global const GltfMaterial* g = &m->params.gltf;
  GltfBsdf* lobe = &b->lobe.gltf;
  GLTF_PARAMS(GLTF_LOAD)
  lobe->ggx = bsdf_microfacet_at(sc, m, s, g->roughness, g->anisotropy_strength, g->anisotropy_rotation, &b->frame);
  lobe->thin = (m->flags & MATERIAL_THIN_WALLED) != 0u;
  float spec = g->specular * bsdf_texture(sc, m, TEX_SPECULAR, s).w;
  float ior = g->ior;
#if CD_FEATURE_DISPERSION
  if (b->channel >= 0 && g->dispersion > 0.0f)
    ior = dispersion_ior(ior, g->dispersion, dispersion_wavelength(b->channel));
#endif
  float r = (ior - 1.0f) / (ior + 1.0f);
  float3 tint = load3(g->specular_color) * bsdf_texture(sc, m, TEX_SPECULAR_COLOR, s).xyz;
  lobe->spec_f0 = fmin(r * r * tint, (float3)(1.0f)) * spec;
  lobe->spec_f90 = spec;
  // A thin sheet has air on both sides: light meets air -> glass from either face
  lobe->eta = b->entering || lobe->thin ? ior : 1.0f / ior;
  bool present = false;  // a component beyond the Lambertian base at this point
#define GLTF_COMPONENT_PARAMS(id, name, kind) present = gltf_##name##_params(sc, m, s, b) || present;
  GLTF_COMPONENTS(GLTF_COMPONENT_PARAMS)
#undef GLTF_COMPONENT_PARAMS
  gltf_fresnel_params(sc, m, s, b);
  if (!present) b->type = MATERIAL_DIFFUSE;
}

// The state at wo: the base's table lookup and Fresnel terms, each component's
// (gltf_NAME_at_wo, in list order: a layer's before what lies below it), then the weights,
// normalized to probabilities
GltfAtWo gltf_at_wo(const Bsdf* b, float3 wo) {
  GltfAtWo g;
  float cos_o = wo.z;
  g.e = gltf_energy(b, energy_at(wo));
  gltf_fresnel(b, cos_o, &g.f_metal_o, &g.f_spec_o);
#define GLTF_AT_WO(id, name, kind) gltf_##name##_at_wo(b, wo, &g);
  GLTF_COMPONENTS(GLTF_AT_WO)
#undef GLTF_AT_WO
#define GLTF_WEIGHT(id, name, kind) g.w[id] = gltf_##name##_weight(b, &g, cos_o);
  GLTF_COMPONENTS(GLTF_WEIGHT)
#undef GLTF_WEIGHT
  float sum = g.w[0];
  for (uint k = 1u; k < GLTF_COMPONENT_COUNT; ++k) sum += g.w[k];
  float inv = sum > 0.0f ? 1.0f / sum : 0.0f;
  for (uint k = 0u; k < GLTF_COMPONENT_COUNT; ++k) g.w[k] *= inv;
  return g;
}

// Everything but delta components: f(wo, wi) and the mixture pdf of bsdf_gltf_sample, wo.z > 0:
// each component's term (gltf_NAME_eval), in GLTF_EVAL_ORDER, after what the base's terms share
float3 gltf_eval_at(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, float* pdf) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  GltfEval acc;
  acc.under = (float3)(0.0f);
  acc.dtrans = (float3)(0.0f);
  acc.f = (float3)(0.0f);
  acc.pdf = 0.0f;
  acc.glossy = false;
  acc.d = 0.0f;
  acc.p = 0.0f;
  acc.cos_h = wo.z;  // wo.h of reflections
  acc.e_i = 1.0f;
  acc.e5_i = 0.0f;
  if (wi.z > 0.0f) {
    // The microfacet terms only where a specular layer exists (not for pure Lambert)
    acc.glossy = lobe->metallic > 0.0f || lobe->spec_f90 > 0.0f || lobe->clearcoat > 0.0f;
    if (acc.glossy) acc.d = ggx_reflection_eval(lobe->ggx, wo, wi, &acc.p, &acc.cos_h);
    // E(wi) and E5(wi) of the specular lobe, looked up once for the layering and f_ms
    acc.e5_i = schlick_weight(wi.z);
    if (g->e.table) {
      acc.e_i = energy_lookup(&g->e, 0, energy_at(wi));
      acc.e5_i = energy_lookup(&g->e, 1, energy_at(wi));
    }
  }
#define GLTF_EVAL(name) gltf_##name##_eval(b, g, wo, wi, &acc);
  GLTF_EVAL_ORDER(GLTF_EVAL)
#undef GLTF_EVAL
  *pdf = acc.pdf;
  return acc.f;
}

// Everything but delta components: f(wo, wi) and the mixture pdf of bsdf_gltf_sample
float3 bsdf_gltf_eval(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f) return (float3)(0.0f);
  GltfAtWo g = gltf_at_wo(b, wo);
  return gltf_eval_at(b, &g, wo, wi, pdf);
}

// The mixture's lobes at wo, from its weights there
void gltf_lobes_at(const Bsdf* b, const GltfAtWo* g, float3 wo, BsdfLobes* l) {
#define GLTF_LOBES(id, name, kind) gltf_##name##_lobes(b, g, wo, g->w[id], l);
  GLTF_COMPONENTS(GLTF_LOBES)
#undef GLTF_LOBES
}

void bsdf_gltf_lobes(const Bsdf* b, float3 wo, BsdfLobes* l) {
  if (wo.z <= 0.0f) return;
  GltfAtWo g = gltf_at_wo(b, wo);
  gltf_lobes_at(b, &g, wo, l);
}

// A component by uc (its CDF over GLTF_COMPONENTS), sampled with uc rescaled to [0, 1)
// within the component; a chosen direction is weighed by the whole mixture
// (with l, its lobes too, from the same mixture at wo)
bool bsdf_gltf_sample(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs, BsdfLobes* l) {
  if (wo.z <= 0.0f) return false;
  GltfAtWo at_wo = gltf_at_wo(b, wo);
  if (l) gltf_lobes_at(b, &at_wo, wo, l);
  const uint last = GLTF_COMPONENT_COUNT - 1u;
  float cdf[GLTF_COMPONENT_COUNT - 1];
  cdf[0] = at_wo.w[0];
  for (uint k = 1u; k < last; ++k) cdf[k] = cdf[k - 1u] + at_wo.w[k];
  uint c = 0u;
  while (c < last && uc >= cdf[c]) ++c;
  float lo = c == 0u ? 0.0f : cdf[c - 1u], width = (c == last ? 1.0f : cdf[c]) - lo;
  float uc2 = width > 0.0f ? clamp((uc - lo) / width, 0.0f, 0x1.fffffep-1f) : 0.0f;
  int done = GLTF_SAMPLE_FAILED;
  uint kind = 0u;
#define GLTF_SAMPLE(id, name, flag)                         \
  if (c == id) {                                            \
    done = gltf_##name##_sample(b, &at_wo, wo, uc2, u, bs); \
    kind = flag;                                            \
  }
  GLTF_COMPONENTS(GLTF_SAMPLE)
#undef GLTF_SAMPLE
  if (done != GLTF_SAMPLE_DIRECTION) return done == GLTF_SAMPLE_DONE;
  bool transmits = bs->wi.z < 0.0f;
  bs->f = gltf_eval_at(b, &at_wo, wo, bs->wi, &bs->pdf);
  bs->flags = (transmits ? BSDF_TRANSMISSION : BSDF_REFLECTION) | kind;
  // A diffuse component's transmission does not refract (the direction, evaluated as the
  // whole mixture, counts as the component that sampled it)
  bs->eta = transmits && !b->lobe.gltf.thin && !(kind & BSDF_DIFFUSE) ? b->lobe.gltf.eta : 1.0f;
  return bs->pdf > 0.0f;
}

// The kinds of lobe present: each component's
uint bsdf_gltf_flags(const Bsdf* b) {
  uint flags = BSDF_REFLECTION;
#define GLTF_FLAGS(id, name, kind) flags |= gltf_##name##_flags(b);
  GLTF_COMPONENTS(GLTF_FLAGS)
#undef GLTF_FLAGS
  return flags;
}
