// glTF metallic-roughness BSDF (glTF 2.0 Appendix B, KHR_materials_* extensions) in the
// local frame, as a mixture of components:
//   coat:    clearcoat * F_c * GGX(coat roughness), F_c = Schlick(0.04, 1); it attenuates
//            everything below by (1 - clearcoat * F_c)
//   metal:   metallic * Schlick(base color, 1) * GGX
//   plastic: (1 - metallic)(1 - transmission) * [F_d * GGX + (1 - max F_d) * base / pi],
//            F_d = Schlick(F0 from ior and KHR_materials_specular, f90 = specular)
//   glass:   (1 - metallic) * transmission * dielectric(ior), base-tinted transmission,
//            thin-walled or refracting (bsdf_dielectric.cl, exact Fresnel)
//   ms:      with the GGX albedo table, the multiple scattering of the metal and plastic
//            GGX lobes (energy.cl, Kulla & Conty 2017), each coloured by its Schlick
//            term's average; the plastic's diffuse weighting stays 1 - max F_d (energy-
//            correct layering is not attempted). Neither the coat nor the glass has one.
// Sampling picks a component with a probability from its estimated weight at wo (the
// lecture's combined BSDF); eval and pdf sum every non-delta component, so sampling and
// evaluation describe the same mixture.

typedef struct {
  float coat, metal, spec, diffuse, ms, glass;  // selection probabilities, summing to 1
} GltfLobes;

float schlick_weight(float cos_i) {
  float m = clamp(1.0f - cos_i, 0.0f, 1.0f);
  float m2 = m * m;
  return m2 * m2 * m;
}

// The GGX albedo table looked up for the metal and plastic specular lobes, if any
GgxEnergy gltf_energy(const Bsdf* b, float cos_o) {
  bool specular = b->metallic > 0.0f || (b->transmission < 1.0f && b->spec_f90 > 0.0f);
  return energy_ggx(specular ? b->ggx_albedo : 0, b->ggx, cos_o);
}

// Colour of the multiple-scattering lobe: each lobe's weight times its F_ms
float3 gltf_ms_fresnel(const Bsdf* b, const GgxEnergy* e) {
  float m = b->metallic, t = b->transmission;
  float3 metal = energy_ms_fresnel(e, energy_schlick_average(b->base_color, (float3)(1.0f)));
  float3 spec = energy_ms_fresnel(e, energy_schlick_average(b->spec_f0, (float3)(b->spec_f90)));
  return m * metal + (1.0f - m) * (1.0f - t) * spec;
}

GltfLobes gltf_lobes(const Bsdf* b, float cos_o, const GgxEnergy* e) {
  float m = b->metallic, t = b->transmission;
  float fc = b->coat * (0.04f + 0.96f * schlick_weight(cos_o));
  float fs = luminance(fresnel_schlick(b->spec_f0, (float3)(b->spec_f90), cos_o));
  float rest = 1.0f - fc;
  GltfLobes w;
  w.coat = fc;
  w.metal = rest * m * e->e_o;
  w.spec = rest * (1.0f - m) * (1.0f - t) * fs * e->e_o;
  w.diffuse = rest * (1.0f - m) * (1.0f - t) * (1.0f - fs) * luminance(b->base_color);
  w.ms = e->table ? rest * energy_ms_albedo(e) * luminance(gltf_ms_fresnel(b, e)) : 0.0f;
  w.glass = rest * (1.0f - m) * t;
  float sum = w.coat + w.metal + w.spec + w.diffuse + w.ms + w.glass;
  float inv = sum > 0.0f ? 1.0f / sum : 0.0f;
  w.coat *= inv;
  w.metal *= inv;
  w.spec *= inv;
  w.diffuse *= inv;
  w.ms *= inv;
  w.glass *= inv;
  return w;
}

// Clearcoat reflectance Schlick(0.04, 1) weighted by the coat factor
float gltf_coat_fresnel(const Bsdf* b, float cos_i) { return b->coat * (0.04f + 0.96f * schlick_weight(cos_i)); }

// Everything but delta components: f(wo, wi) and the mixture pdf of bsdf_gltf_sample
float3 bsdf_gltf_eval(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f) return (float3)(0.0f);
  GgxEnergy e = gltf_energy(b, wo.z);
  GltfLobes w = gltf_lobes(b, wo.z, &e);
  float m = b->metallic, t = b->transmission;
  float3 under = (float3)(0.0f);  // all components below the coat
  float cos_h = wo.z;  // wo.h of reflections; the coat's attenuation uses it
  float d = 0.0f, p = 0.0f;
  if (wi.z > 0.0f) {
    // The microfacet terms only where a specular layer exists (not for pure Lambert)
    bool glossy = m > 0.0f || b->spec_f90 > 0.0f || b->coat > 0.0f;
    if (glossy) d = ggx_reflection_eval(b->ggx, wo, wi, &p, &cos_h);
    float3 fd = glossy ? fresnel_schlick(b->spec_f0, (float3)(b->spec_f90), cos_h) : (float3)(0.0f);
    under = (1.0f - m) * (1.0f - t) * (1.0f - max_component(fd)) * b->base_color * INV_PI_F;
    *pdf += w.diffuse * sample_cosine_hemisphere_pdf(wi.z);
    if (glossy && !ggx_is_delta(b->ggx)) {
      under += (m * fresnel_schlick(b->base_color, (float3)(1.0f), cos_h) + (1.0f - m) * (1.0f - t) * fd) * d;
      *pdf += (w.metal + w.spec) * p;
    }
    if (e.table) {
      under += gltf_ms_fresnel(b, &e) * energy_ms(&e, wi.z);
      *pdf += w.ms * sample_cosine_hemisphere_pdf(wi.z);
    }
  }
  if (t > 0.0f) {
    float glass_p;
    under += (1.0f - m) * t * bsdf_dielectric_eval(b->ggx, b->eta, b->thin, b->base_color, wo, wi, &glass_p);
    *pdf += w.glass * glass_p;
  }
  // Transmitted light crosses the coat once, at the angle of the direction outside
  if (wi.z < 0.0f) cos_h = b->entering ? wo.z : -wi.z;
  float3 f = (1.0f - gltf_coat_fresnel(b, cos_h)) * under;
  if (wi.z > 0.0f && b->coat > 0.0f && !ggx_is_delta(b->coat_ggx)) {
    float coat_p, coat_h;
    float coat_d = ggx_reflection_eval(b->coat_ggx, wo, wi, &coat_p, &coat_h);
    f += gltf_coat_fresnel(b, coat_h) * coat_d;
    *pdf += w.coat * coat_p;
  }
  return f;
}

// A mirror reflection (a delta component) of weight `weight`, chosen with probability p
bool gltf_mirror(float3 wo, float3 weight, float p, BsdfSample* bs) {
  bs->wi = (float3)(-wo.x, -wo.y, wo.z);
  bs->f = weight / wo.z;
  bs->pdf = p;
  bs->flags = BSDF_REFLECTION | BSDF_DELTA;
  bs->eta = 1.0f;
  return p > 0.0f;
}

bool bsdf_gltf_sample(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs) {
  if (wo.z <= 0.0f) return false;
  GgxEnergy e = gltf_energy(b, wo.z);
  GltfLobes w = gltf_lobes(b, wo.z, &e);
  float m = b->metallic, t = b->transmission;
  // Component by uc (coat, metal, spec, diffuse, ms, glass); uc is then rescaled to [0, 1)
  // within the component for reuse
  float cdf[5] = {w.coat, w.coat + w.metal, w.coat + w.metal + w.spec, w.coat + w.metal + w.spec + w.diffuse,
                  w.coat + w.metal + w.spec + w.diffuse + w.ms};
  int c = 0;
  while (c < 5 && uc >= cdf[c]) ++c;
  float lo = c == 0 ? 0.0f : cdf[c - 1], width = (c == 5 ? 1.0f : cdf[c]) - lo;
  float uc2 = width > 0.0f ? clamp((uc - lo) / width, 0.0f, 0x1.fffffep-1f) : 0.0f;
  float coat_att = 1.0f - gltf_coat_fresnel(b, wo.z);
  if (c == 0) {
    if (ggx_is_delta(b->coat_ggx)) return gltf_mirror(wo, (float3)(gltf_coat_fresnel(b, wo.z)), w.coat, bs);
    if (!ggx_reflection_sample(b->coat_ggx, wo, u, &bs->wi)) return false;
  } else if (c == 1 || c == 2) {
    if (ggx_is_delta(b->ggx)) {
      float3 fd = fresnel_schlick(b->spec_f0, (float3)(b->spec_f90), wo.z);
      float3 weight = c == 1 ? m * fresnel_schlick(b->base_color, (float3)(1.0f), wo.z) : (1.0f - m) * (1.0f - t) * fd;
      return gltf_mirror(wo, coat_att * weight, c == 1 ? w.metal : w.spec, bs);
    }
    if (!ggx_reflection_sample(b->ggx, wo, u, &bs->wi)) return false;
  } else if (c == 3 || c == 4) {
    bs->wi = sample_cosine_hemisphere(u.x, u.y);
  } else {
    if (!bsdf_dielectric_sample(b->ggx, b->eta, b->thin, b->base_color, wo, uc2, u, bs)) return false;
    if (bs->flags & BSDF_DELTA) {
      float att = bs->wi.z > 0.0f || b->entering ? coat_att : 1.0f - gltf_coat_fresnel(b, -bs->wi.z);
      bs->f *= att * (1.0f - m) * t;
      bs->pdf *= w.glass;
      return bs->pdf > 0.0f;
    }
  }
  bool transmits = bs->wi.z < 0.0f;
  bs->f = bsdf_gltf_eval(b, wo, bs->wi, &bs->pdf);
  bs->flags = (transmits ? BSDF_TRANSMISSION : BSDF_REFLECTION) | (c == 3 ? BSDF_DIFFUSE : BSDF_GLOSSY);
  bs->eta = transmits && !b->thin ? b->eta : 1.0f;
  return bs->pdf > 0.0f;
}

// The kinds of lobe present
uint bsdf_gltf_flags(const Bsdf* b) {
  uint flags = BSDF_REFLECTION;
  bool plastic = b->metallic < 1.0f && b->transmission < 1.0f;
  if (plastic && max_component(b->base_color) > 0.0f) flags |= BSDF_DIFFUSE;
  bool spec_delta = ggx_is_delta(b->ggx), coat_delta = b->coat > 0.0f && ggx_is_delta(b->coat_ggx);
  if (b->metallic > 0.0f || b->spec_f90 > 0.0f || b->transmission > 0.0f) flags |= spec_delta ? BSDF_DELTA : BSDF_GLOSSY;
  if (b->coat > 0.0f) flags |= coat_delta ? BSDF_DELTA : BSDF_GLOSSY;
  if (b->transmission > 0.0f && b->metallic < 1.0f) flags |= BSDF_TRANSMISSION;
  return flags;
}
