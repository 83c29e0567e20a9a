// The glass: (1 - metallic) * transmission * dielectric(ior), base-tinted transmission,
// thin-walled or refracting (bsdf_dielectric.cl, exact Fresnel, or under KHR_materials_iridescence
// the film's reflectance, for every base index; its multiple scattering in energy_dielectric.cl).
// The last component, always compiled in.

float gltf_glass_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  return g->outer * (1.0f - lobe->metallic) * lobe->transmission;
}

// The interface (bsdf_dielectric.cl with energy_dielectric.cl's multiple-scattering
// compensation). Under KHR_materials_iridescence the film's reflectance replaces the Fresnel
// term of the split between reflection and transmission, as it does the metal's and the
// plastic's (gltf_fresnel), for every index of the base, 1 included; the compensation lobe
// stays the bare interface's.
#if CD_FEATURE_IRIDESCENCE
DielectricFilm gltf_film(const Bsdf* b) {
  DielectricFilm film = {b->lobe.gltf.iridescence, b->lobe.gltf.iridescence_ior, b->lobe.gltf.iridescence_thickness};
  return film;
}
#endif

float3 gltf_glass_interface_eval(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
  const GltfBsdf* lobe = &b->lobe.gltf;
#if CD_FEATURE_IRIDESCENCE
  if (lobe->iridescence > 0.0f) {
    float3 f = bsdf_dielectric_film_eval(lobe->ggx, lobe->eta, lobe->thin, b->base_color, gltf_film(b), wo, wi, pdf);
    DielectricMs ms = energy_dielectric_at(b->ggx_albedo, lobe->ggx, lobe->eta, lobe->thin, energy_at(wo));
    if (!ms.on) return f;
    float ms_pdf;
    f += energy_dielectric_ms(&ms, b->base_color, wi, &ms_pdf);
    *pdf = (1.0f - ms.q) * *pdf + ms.q * ms_pdf;
    return f;
  }
#endif
  return energy_dielectric_eval(b->ggx_albedo, lobe->ggx, lobe->eta, lobe->thin, b->base_color, wo, wi, pdf);
}

// A sample of the interface: the compensation lobe with probability q (as
// energy_dielectric_sample), else the interface
bool gltf_glass_interface_sample(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs) {
  const GltfBsdf* lobe = &b->lobe.gltf;
#if CD_FEATURE_IRIDESCENCE
  if (lobe->iridescence > 0.0f) {
    DielectricMs ms = energy_dielectric_at(b->ggx_albedo, lobe->ggx, lobe->eta, lobe->thin, energy_at(wo));
    if (ms.on && uc < ms.q) {
      bs->wi = sample_cosine_hemisphere(u.x, u.y);
      if (uc / ms.q >= ms.p_refl) bs->wi.z = -bs->wi.z;
    } else if (!bsdf_dielectric_film_sample(lobe->ggx, lobe->eta, lobe->thin, b->base_color, gltf_film(b), wo,
                                            ms.on ? fmin((uc - ms.q) / (1.0f - ms.q), 0x1.fffffep-1f) : uc, u, bs)) {
      return false;
    }
    if (!ms.on) return true;
    bool transmits = bs->wi.z < 0.0f;
    bs->f = gltf_glass_interface_eval(b, wo, bs->wi, &bs->pdf);
    bs->flags = (transmits ? BSDF_TRANSMISSION : BSDF_REFLECTION) | BSDF_GLOSSY;
    bs->eta = transmits && !lobe->thin ? lobe->eta : 1.0f;
    return bs->pdf > 0.0f;
  }
#endif
  return energy_dielectric_sample(b->ggx_albedo, lobe->ggx, lobe->eta, lobe->thin, b->base_color, wo, uc, u, bs);
}

// A delta transmission crosses the coat once, at the angle of the direction outside
int gltf_glass_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (!gltf_glass_interface_sample(b, wo, uc, u, bs)) return GLTF_SAMPLE_FAILED;
  if (!(bs->flags & BSDF_DELTA)) return GLTF_SAMPLE_DIRECTION;
  float att = bs->wi.z > 0.0f ? gltf_coat_below(g, bs->wi) : gltf_coat_across(b, g, bs->wi);
#if CD_FEATURE_SHEEN
  if (max_component(lobe->sheen_color) > 0.0f)
    att *= bs->wi.z > 0.0f || b->entering ? g->sheen_o : gltf_sheen_below(b, gltf_sheen_e(b, -bs->wi.z));
#endif
  bs->f *= att * (1.0f - lobe->metallic) * lobe->transmission;
  bs->pdf *= g->w[GLTF_GLASS];
  return bs->pdf > 0.0f ? GLTF_SAMPLE_DONE : GLTF_SAMPLE_FAILED;
}

// Its weight split by the Fresnel reflectance at wo between its reflection and its
// transmission, about the refracted direction, or straight through a thin sheet
void gltf_glass_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (ggx_is_delta(lobe->ggx)) return;
  float r = fresnel_dielectric(wo.z, lobe->eta);
#if CD_FEATURE_IRIDESCENCE
  if (lobe->iridescence > 0.0f)
    r = dielectric_film_share(dielectric_film_fresnel(gltf_film(b), wo.z, lobe->eta, false));
#endif
  float3 t = -wo;
  if (lobe->thin) {
    r = dielectric_sheet_reflectance(r);
  } else if (!fresnel_refract(wo, (float3)(0.0f, 0.0f, 1.0f), lobe->eta, &t)) {
    r = 1.0f;  // total internal reflection
  }
  gltf_ggx_lobe(lobe->ggx, wo, w * r, l);
  float omega = lobe->thin ? bsdf_lobe_omega_ggx(lobe->ggx) : bsdf_lobe_omega_ggx_refraction(lobe->ggx, lobe->eta);
  bsdf_lobes_add(l, t, omega, w * (1.0f - r));
}

void gltf_glass_eval(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, GltfEval* acc) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float m = lobe->metallic, t = lobe->transmission;
  if (t > 0.0f) {
    float glass_p;
    acc->under += (1.0f - m) * t * gltf_glass_interface_eval(b, wo, wi, &glass_p);
    acc->pdf += g->w[GLTF_GLASS] * glass_p;
  }
}

// Its factor, index and thin-walledness are the base's (bsdf_gltf_params)
bool gltf_glass_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
  return b->lobe.gltf.transmission != 0.0f;
}

void gltf_glass_at_wo(const Bsdf* b, float3 wo, GltfAtWo* g) {}

uint gltf_glass_flags(const Bsdf* b) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (!(lobe->transmission > 0.0f)) return 0u;
  return gltf_ggx_flags(lobe->ggx) | (lobe->metallic < 1.0f ? BSDF_TRANSMISSION : 0u);
}
