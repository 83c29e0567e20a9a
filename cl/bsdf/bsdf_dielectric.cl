// Dielectric interface in the local frame (wo.z > 0), eta = eta_t / eta_i seen from wo:
// reflection and refraction chosen by the exact Fresnel term, Snell's law, total internal
// reflection, radiance scaled by 1 / eta^2 on refraction, transmitted light tinted. Rough
// surfaces follow Walter et al. 2007 (Microfacet Models for Refraction through Rough
// Surfaces) with visible-normal sampling; below GGX_DELTA_ALPHA the lobes are Dirac.
// `thin`: a thin-walled sheet, whose transmission leaves straight through (mirrored
// reflection lobe) without bending.

// Reflectance of a thin sheet from the interface's R, inter-reflections inside included:
// R' = R + T^2 R / (1 - R^2) = 2R / (1 + R) (pbrt-v4's ThinDielectricBxDF)
float dielectric_sheet_reflectance(float r) { return 2.0f * r / (1.0f + r); }

// The non-delta part: f(wo, wi) and the pdf of bsdf_dielectric_sample
float3 bsdf_dielectric_eval(Ggx g, float eta, bool thin, float3 tint, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (ggx_is_delta(g) || wo.z <= 0.0f || wi.z == 0.0f) return (float3)(0.0f);
  if (wi.z > 0.0f || thin) {
    // Reflection, or a thin sheet's transmission as the reflection mirrored through the sheet
    float3 wr = (float3)(wi.x, wi.y, fabs(wi.z));
    float cos_oh;
    float f = ggx_reflection_eval(g, wo, wr, pdf, &cos_oh);
    float r = fresnel_dielectric(cos_oh, eta);
    if (thin) r = dielectric_sheet_reflectance(r);
    float share = wi.z > 0.0f ? r : 1.0f - r;
    *pdf *= share;
    return (wi.z > 0.0f ? (float3)(1.0f) : tint) * (f * share);
  }
  // Refraction: generalized half vector h ~ wo + eta wi, turned up
  float3 h = wo + eta * wi;
  if (dot(h, h) == 0.0f) return (float3)(0.0f);
  h = normalize(h);
  if (h.z < 0.0f) h = -h;
  float cos_oh = dot(wo, h), cos_ih = dot(wi, h);
  if (cos_oh <= 0.0f || cos_ih >= 0.0f) return (float3)(0.0f);
  float t = 1.0f - fresnel_dielectric(cos_oh, eta);
  float denom = cos_ih + cos_oh / eta;
  denom *= denom;
  *pdf = t * ggx_visible_d(g, wo, h) * fabs(cos_ih) / denom;  // dh/dwi = |wi.h| / denom
  float f = t * ggx_d(g, h) * ggx_g(g, wo, wi) * fabs(cos_ih * cos_oh / (wi.z * wo.z * denom));
  return tint * (f / (eta * eta));
}

// Smooth interface: reflect with probability R, else refract (or pass a thin sheet)
bool bsdf_dielectric_sample_smooth(float eta, bool thin, float3 tint, float3 wo, float uc, BsdfSample* bs) {
  float r = fresnel_dielectric(wo.z, eta);
  if (thin) r = dielectric_sheet_reflectance(r);
  bs->eta = 1.0f;
  if (uc < r) {
    bs->wi = (float3)(-wo.x, -wo.y, wo.z);
    bs->f = (float3)(r / wo.z);
    bs->pdf = r;
    bs->flags = BSDF_REFLECTION | BSDF_DELTA;
    return r > 0.0f;
  }
  if (thin) {
    bs->wi = -wo;
    bs->f = tint * ((1.0f - r) / wo.z);
  } else {
    if (!fresnel_refract(wo, (float3)(0.0f, 0.0f, 1.0f), eta, &bs->wi)) return false;
    bs->f = tint * ((1.0f - r) / (fabs(bs->wi.z) * eta * eta));
    bs->eta = eta;
  }
  bs->pdf = 1.0f - r;
  bs->flags = BSDF_TRANSMISSION | BSDF_DELTA;
  return true;
}

// The rough lobe's direction about the microfacet normal h: reflection with probability p,
// else refraction; a thin sheet's transmission is the reflection mirrored through the sheet
bool dielectric_sample_direction(float3 wo, float3 h, float eta, bool thin, float p, float uc, float3* wi) {
  if (uc < p || thin) {
    *wi = fresnel_reflect(wo, h);
    if (wi->z <= 0.0f) return false;
    if (uc >= p) wi->z = -wi->z;  // thin sheet: straight through
    return true;
  }
  return fresnel_refract(wo, h, eta, wi) && wi->z < 0.0f;
}

// The rough lobe's flags and relative index once bs->wi, f and pdf are set
bool dielectric_sample_finish(float eta, bool thin, BsdfSample* bs) {
  bool transmits = bs->wi.z < 0.0f;
  bs->flags = (transmits ? BSDF_TRANSMISSION : BSDF_REFLECTION) | BSDF_GLOSSY;
  bs->eta = transmits && !thin ? eta : 1.0f;
  return bs->pdf > 0.0f;
}

bool bsdf_dielectric_sample(Ggx g, float eta, bool thin, float3 tint, float3 wo, float uc, float2 u, BsdfSample* bs) {
  if (wo.z <= 0.0f) return false;
  if (ggx_is_delta(g)) return bsdf_dielectric_sample_smooth(eta, thin, tint, wo, uc, bs);
  float3 h = ggx_sample_visible(g, wo, u);
  float r = fresnel_dielectric(dot(wo, h), eta);
  if (thin) r = dielectric_sheet_reflectance(r);
  if (!dielectric_sample_direction(wo, h, eta, thin, r, uc, &bs->wi)) return false;
  bs->f = bsdf_dielectric_eval(g, eta, thin, tint, wo, bs->wi, &bs->pdf);
  return dielectric_sample_finish(eta, thin, bs);
}

#if CD_FEATURE_IRIDESCENCE
// The interface under a thin film (KHR_materials_iridescence): the film's reflectance F
// (iridescence.cl, mixed with the interface's own by the film's factor) replaces the exact
// Fresnel term in the split between reflection and transmission, per channel: reflection
// F, transmission (1 - F) x tint, whatever the base's index (a base of index 1 under a
// film of index 2 is a coloured mirror). The film lies on the outside face: from the denser
// side (eta < 1) it is seen at the outside angle by Snell's law (a lossless stack reflects
// alike from either side), past the critical angle everything reflects. A choice between
// reflection and transmission is made with the channels' mean.
typedef struct {
  float factor, ior, thickness;  // the film's share, index and thickness (nm)
} DielectricFilm;

float3 dielectric_film_fresnel(DielectricFilm film, float cos_i, float eta, bool thin) {
  float c = clamp(cos_i, 0.0f, 1.0f), f = fresnel_dielectric(c, eta);
  if (eta < 1.0f) {
    float sin2 = (1.0f - c * c) / (eta * eta);
    if (sin2 >= 1.0f) return (float3)(1.0f);
    c = sqrt(1.0f - sin2);
  }
  float n = eta < 1.0f ? 1.0f / eta : eta, r0 = (n - 1.0f) / (n + 1.0f);
  float3 r = mix((float3)(f), iridescence_fresnel(film.ior, film.thickness, (float3)(r0 * r0), c), film.factor);
  return thin ? 2.0f * r / (1.0f + r) : r;
}

float dielectric_film_share(float3 r) { return (r.x + r.y + r.z) * (1.0f / 3.0f); }

// bsdf_dielectric_eval with the film's F
float3 bsdf_dielectric_film_eval(Ggx g, float eta, bool thin, float3 tint, DielectricFilm film, float3 wo, float3 wi,
                                 float* pdf) {
  *pdf = 0.0f;
  if (ggx_is_delta(g) || wo.z <= 0.0f || wi.z == 0.0f) return (float3)(0.0f);
  if (wi.z > 0.0f || thin) {
    float3 wr = (float3)(wi.x, wi.y, fabs(wi.z));
    float cos_oh;
    float f = ggx_reflection_eval(g, wo, wr, pdf, &cos_oh);
    float3 r = dielectric_film_fresnel(film, cos_oh, eta, thin);
    float p = dielectric_film_share(r);
    *pdf *= wi.z > 0.0f ? p : 1.0f - p;
    return wi.z > 0.0f ? r * f : tint * (1.0f - r) * f;
  }
  float3 h = wo + eta * wi;
  if (dot(h, h) == 0.0f) return (float3)(0.0f);
  h = normalize(h);
  if (h.z < 0.0f) h = -h;
  float cos_oh = dot(wo, h), cos_ih = dot(wi, h);
  if (cos_oh <= 0.0f || cos_ih >= 0.0f) return (float3)(0.0f);
  float3 t = 1.0f - dielectric_film_fresnel(film, cos_oh, eta, false);
  float denom = cos_ih + cos_oh / eta;
  denom *= denom;
  *pdf = dielectric_film_share(t) * ggx_visible_d(g, wo, h) * fabs(cos_ih) / denom;
  float f = ggx_d(g, h) * ggx_g(g, wo, wi) * fabs(cos_ih * cos_oh / (wi.z * wo.z * denom));
  return tint * t * (f / (eta * eta));
}

// bsdf_dielectric_sample with the film's F: reflection with probability mean(F), weighed by F
bool bsdf_dielectric_film_sample(Ggx g, float eta, bool thin, float3 tint, DielectricFilm film, float3 wo, float uc,
                                 float2 u, BsdfSample* bs) {
  if (wo.z <= 0.0f) return false;
  if (ggx_is_delta(g)) {
    float3 r = dielectric_film_fresnel(film, wo.z, eta, thin);
    float p = dielectric_film_share(r);
    bs->eta = 1.0f;
    if (uc < p) {
      bs->wi = (float3)(-wo.x, -wo.y, wo.z);
      bs->f = r / wo.z;
      bs->pdf = p;
      bs->flags = BSDF_REFLECTION | BSDF_DELTA;
      return true;
    }
    if (thin) {
      bs->wi = -wo;
      bs->f = tint * (1.0f - r) / wo.z;
    } else {
      if (!fresnel_refract(wo, (float3)(0.0f, 0.0f, 1.0f), eta, &bs->wi)) return false;
      bs->f = tint * (1.0f - r) / (fabs(bs->wi.z) * eta * eta);
      bs->eta = eta;
    }
    bs->pdf = 1.0f - p;
    bs->flags = BSDF_TRANSMISSION | BSDF_DELTA;
    return bs->pdf > 0.0f;
  }
  float3 h = ggx_sample_visible(g, wo, u);
  float p = dielectric_film_share(dielectric_film_fresnel(film, dot(wo, h), eta, thin));
  if (!dielectric_sample_direction(wo, h, eta, thin, p, uc, &bs->wi)) return false;
  bs->f = bsdf_dielectric_film_eval(g, eta, thin, tint, film, wo, bs->wi, &bs->pdf);
  return dielectric_sample_finish(eta, thin, bs);
}
#endif
