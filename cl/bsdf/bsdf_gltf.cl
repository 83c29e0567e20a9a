// glTF metallic-roughness BSDF (glTF 2.0 Appendix B, KHR_materials_* extensions) in the
// local frame, as a mixture of components:
//   coat:    clearcoat * F_c * GGX(coat roughness), F_c = Schlick(0.04, 1), about the coat's
//            own normal n_c (clearcoatNormalTexture; without it the unmapped normal, even where
//            the base is normal-mapped); it attenuates reflections below by
//            (1 - A_c(mu_o)) (1 - A_c(mu_i)) and transmissions by 1 - A_c at the outside
//            direction's angle, A_c = the coat's albedo, mu the cosines to n_c. Where n_c is
//            not the shading normal n, its lobe is f_c (wi.n_c) / (wi.n): the integrator weighs
//            by wi.n, the coat reflects by the projected solid angle about n_c
//   sheen:   (CD_FEATURE_SHEEN) sheen colour * Charlie sheen (sheen.cl) / max(1, E(mu_o),
//            E(mu_i)), below the coat; it scales reflections below by min(1 - c E(mu_o),
//            1 - c E(mu_i)) (the extension's albedo scaling, c = max3(sheen colour), E its
//            albedo table, taken at most 1) and transmissions by 1 - c E at the outside
//            direction's angle
//   metal:   metallic * F_m * GGX, F_m = Schlick(base color, 1)
//   plastic: (1 - metallic)(1 - transmission) * [F_d * GGX + (1 - d) W(mu_o, mu_i) * base / pi],
//            F_d = Schlick(F0 from ior and KHR_materials_specular, f90 = specular)
//   film:    (CD_FEATURE_IRIDESCENCE) KHR_materials_iridescence mixes a thin film's reflectance
//            (iridescence.cl) into F_m and F_d: F = mix(F, film over that base, factor), the
//            dielectric's film scaled by its specular factor (gltf_fresnel), and into the
//            glass's split between reflection and transmission (gltf_glass_eval), for every
//            base index, 1 included. The layering (W, the albedo weights) and the multiple
//            scattering keep the base's own Fresnel terms
//   difftrans: (CD_FEATURE_DIFFUSE_TRANSMISSION) (1 - metallic)(1 - transmission) *
//            d W(mu_o, |mu_i|) * colour / pi into the other hemisphere
//            (KHR_materials_diffuse_transmission: the factor d takes that share of the
//            plastic's diffuse base and transmits it, Lambertian, tinted by its colour). It
//            passes the specular layer, the sheen and the coat as a reflection does (a sheet
//            with the layers on both faces), so that a white base with colour 1 returns
//            exactly the light a white plastic reflects, split (1 - d) : d
//   glass:   (1 - metallic) * transmission * dielectric(ior), base-tinted transmission,
//            thin-walled or refracting (bsdf_dielectric.cl, exact Fresnel)
//   ms:      with the GGX albedo table, the multiple scattering of the metal and plastic
//            GGX lobes (energy.cl, Kulla & Conty 2017), each coloured by its Schlick
//            term's average. The glass has its own (energy_dielectric.cl); the coat has
//            none (F_avg ~ 0.09: under 1 %).
// Layering (albedo scaling, Kelemen & Szirmay-Kalos 2001; Kulla & Conty 2017): what lies
// below a layer gets the light the layer does not reflect. With A(mu) the layer's
// directional albedo (the largest channel), the diffuse base is weighted by
//   W = (1 - A(mu_o)) (1 - A(mu_i)) / (1 - A_avg),  A_avg = 2 integral of A mu dmu,
// which is reciprocal and returns exactly 1 - A(mu_o) of a white base: a white plastic
// reflects 1 at every angle. A comes from the GGX albedo table (E, E5 and the multiple-
// scattering term); without the table (no compensation) A = Schlick's F(mu), exact only for
// smooth layers, and the division is left out so that no rough layer can create energy.
// The coat's attenuation of specular lobes has no division: one that is not Lambertian would
// gain energy from it. The diffuse base under the coat is normalized by the coat's and the
// specular layer's joint transmittance (gltf_coat_base_norm), so a white Lambert base under a
// clear coat returns the light trapped under the coat.
// Sampling picks a component with a probability from its estimated weight at wo (a
// mixture of BSDFs, PBRT 4th ed. sec. 9.1); eval and pdf sum every non-delta component, so sampling and
// evaluation describe the same mixture.
//
// GLTF_COMPONENTS: X(id, name, kind), the components in sampling order, kind the BSDF_*
// flag of a direction the component samples. Each has
//   float gltf_NAME_weight(const Bsdf*, const GltfAtWo*, float cos_o): its weight at wo
//   int gltf_NAME_sample(const Bsdf*, const GltfAtWo*, float3 wo, float uc, float2 u, BsdfSample*)
//   void gltf_NAME_lobes(const Bsdf*, const GltfAtWo*, float3 wo, float w, BsdfLobes*): the
//        lobe(s) it samples, of total weight w (none if delta), for the strategy choice
// and a term of f and pdf in gltf_eval_at, which adds the components in its own order: the
// metal and plastic specular lobes share one microfacet evaluation, and the coat is a layer
// over the others rather than a term beside them.
// A component compiled out by its feature has weight 0; the last component (glass) is
// always compiled in, so a zero-width one is never chosen.
#define GLTF_COAT 0u
#define GLTF_SHEEN 1u
#define GLTF_METAL 2u
#define GLTF_SPEC 3u
#define GLTF_DIFFUSE 4u
#define GLTF_DIFFTRANS 5u
#define GLTF_MS 6u
#define GLTF_GLASS 7u
// One entry per line, columns aligned:
// clang-format off
#define GLTF_COMPONENTS(X)                   \
  X(GLTF_COAT, coat, BSDF_GLOSSY)            \
  X(GLTF_SHEEN, sheen, BSDF_GLOSSY)          \
  X(GLTF_METAL, metal, BSDF_GLOSSY)          \
  X(GLTF_SPEC, spec, BSDF_GLOSSY)            \
  X(GLTF_DIFFUSE, diffuse, BSDF_DIFFUSE)     \
  X(GLTF_DIFFTRANS, difftrans, BSDF_DIFFUSE) \
  X(GLTF_MS, ms, BSDF_GLOSSY)                \
  X(GLTF_GLASS, glass, BSDF_GLOSSY)
// clang-format on
#define GLTF_COUNT_COMPONENT(id, name, kind) +1
#define GLTF_COMPONENT_COUNT (0 GLTF_COMPONENTS(GLTF_COUNT_COMPONENT))

// What a component's sample did
#define GLTF_SAMPLE_FAILED 0     // nothing: the path ends
#define GLTF_SAMPLE_DIRECTION 1  // chose bs->wi, which the whole mixture weighs
#define GLTF_SAMPLE_DONE 2       // a complete sample of a delta component

// The material at the hit: factors times textures; KHR_materials_specular gives
// F0 = min(F0(ior) x colour, 1) x specular and F90 = specular. Where the textures put no
// specular layer, metal, glass or coat the BSDF is exactly Lambertian: MATERIAL_DIFFUSE
// takes the short path.
void bsdf_gltf_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
  __global const GltfMaterial* g = &m->params.gltf;
  GltfBsdf* lobe = &b->lobe.gltf;
  lobe->metallic = g->metallic * bsdf_texture(sc, m, TEX_METALLIC_ROUGHNESS, s).z;
  lobe->ggx = bsdf_microfacet_at(sc, m, s, g->roughness, g->anisotropy_strength, g->anisotropy_rotation, &b->frame);
  lobe->transmission = g->transmission * bsdf_texture(sc, m, TEX_TRANSMISSION, s).x;
  lobe->thin = (m->flags & MATERIAL_THIN_WALLED) != 0u;
  float spec = g->specular_color[3] * bsdf_texture(sc, m, TEX_SPECULAR, s).w;
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
  lobe->coat = g->clearcoat * bsdf_texture(sc, m, TEX_CLEARCOAT, s).x;
  float coat_rough = g->clearcoat_roughness * bsdf_texture(sc, m, TEX_CLEARCOAT_ROUGHNESS, s).y;
  lobe->coat_ggx = ggx_from_roughness(coat_rough, 0.0f);
  // The coat's normal: its own normal map, else the interpolated normal
  Frame geo = bsdf_geometry_frame(s);
  lobe->coat_n = geo.n;
  lobe->coat_own_normal = false;
  if (lobe->coat > 0.0f) {
    bsdf_mapped_normal(sc, m, s, &geo, TEX_CLEARCOAT_NORMAL, g->clearcoat_normal_scale, &lobe->coat_n);
    lobe->coat_own_normal =
        m->textures[TEX_CLEARCOAT_NORMAL].index != NO_TEXTURE || m->textures[TEX_NORMAL].index != NO_TEXTURE;
  }
  bool layered = false;  // an extension's layer or lobe at this point
#if CD_FEATURE_SHEEN
  lobe->sheen = load3(g->sheen) * bsdf_texture(sc, m, TEX_SHEEN_COLOR, s).xyz;
  lobe->sheen_roughness = g->sheen[3] * bsdf_texture(sc, m, TEX_SHEEN_ROUGHNESS, s).w;
  lobe->sheen_albedo = sc->sheen_albedo;
  layered = layered || max_component(lobe->sheen) > 0.0f;
#endif
#if CD_FEATURE_DIFFUSE_TRANSMISSION
  lobe->diffuse_transmission = g->diffuse_transmission[3] * bsdf_texture(sc, m, TEX_DIFFUSE_TRANSMISSION, s).w;
  lobe->diffuse_transmission_color =
      load3(g->diffuse_transmission) * bsdf_texture(sc, m, TEX_DIFFUSE_TRANSMISSION_COLOR, s).xyz;
  layered = layered || lobe->diffuse_transmission > 0.0f;
#endif
#if CD_FEATURE_DIFFUSE_ROUGHNESS
  lobe->diffuse_roughness = clamp(g->diffuse_roughness * bsdf_texture(sc, m, TEX_DIFFUSE_ROUGHNESS, s).x, 0.0f, 1.0f);
  layered = layered || lobe->diffuse_roughness > 0.0f;
#endif
#if CD_FEATURE_IRIDESCENCE
  // The film's factor (texture R) and thickness, from minimum to maximum by texture G; a
  // film of thickness 0 is none
  lobe->iridescence = g->iridescence[0] * bsdf_texture(sc, m, TEX_IRIDESCENCE, s).x;
  lobe->iridescence_ior = g->iridescence[1];
  lobe->iridescence_thickness =
      mix(g->iridescence[2], g->iridescence[3], bsdf_texture(sc, m, TEX_IRIDESCENCE_THICKNESS, s).y);
  if (!(lobe->iridescence_thickness > 0.0f)) lobe->iridescence = 0.0f;
#endif
  if (lobe->metallic == 0.0f && lobe->spec_f90 == 0.0f && lobe->transmission == 0.0f && lobe->coat == 0.0f && !layered)
    b->type = MATERIAL_DIFFUSE;
}

float schlick_weight(float cos_i) {
  float m = clamp(1.0f - cos_i, 0.0f, 1.0f);
  float m2 = m * m;
  return m2 * m2 * m;
}

// KHR_materials_diffuse_transmission's factor at the hit (0 where compiled out)
float gltf_diffuse_transmission(const Bsdf* b) {
#if CD_FEATURE_DIFFUSE_TRANSMISSION
  return b->lobe.gltf.diffuse_transmission;
#else
  return 0.0f;
#endif
}

// The GGX albedo table looked up for the metal and plastic specular lobes, if any
GgxEnergy gltf_energy(const Bsdf* b, EnergyDir wo) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  bool specular = lobe->metallic > 0.0f || (lobe->transmission < 1.0f && lobe->spec_f90 > 0.0f);
  return energy_ggx(specular ? b->ggx_albedo : 0, lobe->ggx, wo);
}

// A dielectric GGX layer with Schlick's Fresnel term (f0, f90) above something else
typedef struct {
  GgxEnergy e;  // its table lookup (table 0: a delta lobe, or no compensation)
  float3 f0;
  float f90;
  float3 f_ms;      // colour of its multiple-scattering term; 0 without one
  float a_o;        // its albedo A(mu_o), largest channel
  float a_avg;      // 2 integral of A mu dmu, largest channel
  bool normalized;  // weight what lies below by W / (1 - a_avg)
} GltfLayer;

// A(w) = f0 E(w) + (f90 - f0) E5(w) + (1 - E(w)) F_ms, largest channel, from E and E5
float gltf_layer_albedo_of(const GltfLayer* l, float e, float e5) {
  return max_component(l->f0 * e + (l->f90 - l->f0) * e5 + (1.0f - e) * l->f_ms);
}

// A(w); a delta lobe (or one without table) has E = 1 and E5 = (1 - mu)^5, so A = Schlick's
// F(mu). Only w.z counts for isotropic lobes.
float gltf_layer_albedo(const GltfLayer* l, EnergyDir w) {
  if (!l->e.table) return gltf_layer_albedo_of(l, 1.0f, schlick_weight(energy_dir_mu(w)));
  return gltf_layer_albedo_of(l, energy_lookup(&l->e, 0, w), energy_lookup(&l->e, 1, w));
}

// A(mu) of the clear coat, an isotropic layer: lookups by mu alone, so that kernels with
// CD_FEATURE_ANISOTROPY do not compile the anisotropic lookup at each of the coat's
float gltf_coat_albedo(const GltfLayer* l, float mu) {
  if (!l->e.table) return gltf_layer_albedo_of(l, 1.0f, schlick_weight(mu));
  return gltf_layer_albedo_of(l, energy_lookup_mu(&l->e, 0, mu), energy_lookup_mu(&l->e, 1, mu));
}

// The layer without its albedo at wo, a_o (the caller's)
GltfLayer gltf_layer(GgxEnergy e, float3 f0, float f90, float3 f_ms, bool normalized) {
  GltfLayer l;
  l.e = e;
  l.f0 = f0;
  l.f90 = f90;
  l.f_ms = e.table ? f_ms : (float3)(0.0f);
  float3 avg = e.table ? f0 * e.e_avg + (f90 - f0) * e.e5_avg + (1.0f - e.e_avg) * l.f_ms
                       : energy_schlick_average(f0, (float3)(f90));
  l.a_avg = max_component(avg);
  l.normalized = normalized && l.a_avg < 1.0f;
  return l;
}

// The plastic's specular layer over its diffuse base, normalized where the table is bound
GltfLayer gltf_spec_layer(const Bsdf* b, const GgxEnergy* e, EnergyDir wo) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float3 f_ms = energy_ms_fresnel(e, energy_schlick_average(lobe->spec_f0, (float3)(lobe->spec_f90)));
  GltfLayer l = gltf_layer(*e, lobe->spec_f0, lobe->spec_f90, f_ms, b->ggx_albedo != 0);
  // A(wo) from E(wo) and E5(wo) as energy_ggx looked them up (Schlick's F without the table)
  l.a_o = gltf_layer_albedo_of(&l, e->table ? e->e_o : 1.0f, e->table ? e->e5_o : schlick_weight(energy_dir_mu(wo)));
  return l;
}

// The clearcoat: Schlick(0.04, 1) weighted by the coat factor, never normalized
GltfLayer gltf_coat_layer(const Bsdf* b, float cos_o) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  GgxEnergy e = energy_ggx_mu(lobe->coat > 0.0f ? b->ggx_albedo : 0, lobe->coat_ggx, cos_o);
  GltfLayer l = gltf_layer(e, (float3)(0.04f * lobe->coat), lobe->coat, (float3)(0.0f), false);
  l.a_o = gltf_coat_albedo(&l, cos_o);
  return l;
}

// W(wo, wi) of what lies below the layer, both directions above, from its albedo a_i at wi
float gltf_below_of(const GltfLayer* l, float a_i) {
  float w = (1.0f - l->a_o) * (1.0f - a_i);
  return fmax(l->normalized ? w / (1.0f - l->a_avg) : w, 0.0f);
}

float gltf_below(const GltfLayer* l, EnergyDir wi) { return gltf_below_of(l, gltf_layer_albedo(l, wi)); }

// The diffuse base under the coat and the specular layer gets their transmittance
// T = (1 - A_c)(1 - A_s) at both directions, normalized by T_avg = 2 integral of T mu dmu
// (as gltf_below does for one layer): a white base returns exactly T(mu_o), and the light
// trapped under the coat is not lost. Returns the factor (1 - A_s,avg) / T_avg that turns the
// specular layer's own normalization into this one; 1 without the table or the coat.
// T_avg by 8-point Gauss-Legendre quadrature on [0, 1/4] and [1/4, 1] (A is steep at grazing);
// under an anisotropic specular layer also over four azimuths (midpoints in [0, pi / 2]).
float gltf_coat_base_norm(const Bsdf* b, const GltfLayer* coat, const GltfLayer* spec) {
  if (b->lobe.gltf.coat <= 0.0f || !spec->normalized || !b->ggx_albedo) return 1.0f;
  const float x[4] = ENERGY_GL_X;
  const float w[4] = ENERGY_GL_W;
#if CD_FEATURE_ANISOTROPY
  int azimuths = spec->e.aniso ? 4 : 1;
#else
  const int azimuths = 1;
#endif
  // One loop over (azimuth, interval, node, sign), so that its body (the anisotropic lookup
  // with CD_FEATURE_ANISOTROPY) is compiled once, not once per unrolled point
  float sum = 0.0f;
  for (int n = 0; n < 16 * azimuths; ++n) {
    int a = n >> 4, part = (n >> 3) & 1, k = (n >> 1) & 3;
    float phi = ((float)a + 0.5f) * (0.5f * PI_F) / (float)azimuths, c_phi = azimuths > 1 ? cos(phi) : 1.0f,
          s_phi = azimuths > 1 ? sin(phi) : 0.0f;
    float c = part ? 0.625f : 0.125f, h = part ? 0.375f : 0.125f;
    float mu = c + (n & 1 ? h : -h) * x[k], st = sqrt(fmax(0.0f, 1.0f - mu * mu));
    EnergyDir d = energy_at((float3)(st * c_phi, st * s_phi, mu));
    float t = (1.0f - gltf_coat_albedo(coat, mu)) * (1.0f - gltf_layer_albedo(spec, d));
    sum += 2.0f * h * w[k] * mu * t;
  }
  sum /= (float)azimuths;
  return sum > 0.0f ? (1.0f - spec->a_avg) / sum : 1.0f;
}

// Colour of the multiple-scattering lobe: each lobe's weight times its F_ms
float3 gltf_ms_fresnel(const Bsdf* b, const GgxEnergy* e) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float m = lobe->metallic, t = lobe->transmission;
  float3 metal = energy_ms_fresnel(e, energy_schlick_average(b->base_color, (float3)(1.0f)));
  float3 spec = energy_ms_fresnel(e, energy_schlick_average(lobe->spec_f0, (float3)(lobe->spec_f90)));
  return m * metal + (1.0f - m) * (1.0f - t) * spec;
}

// Clearcoat reflectance Schlick(0.04, 1) weighted by the coat factor, at the coat lobe's wo.h
float gltf_coat_fresnel(const Bsdf* b, float cos_i) {
  return b->lobe.gltf.coat * (0.04f + 0.96f * schlick_weight(cos_i));
}

// The metal's and the plastic's specular Fresnel terms F_m and F_d at cosine cos_h (wo.h);
// with KHR_materials_iridescence each is mixed with the film over its base, for the bases
// present (the one place the film is evaluated: eval, sample and the weights at wo share it)
void gltf_fresnel(const Bsdf* b, float cos_h, float3* metal, float3* spec) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  *metal = fresnel_schlick(b->base_color, (float3)(1.0f), cos_h);
  *spec = fresnel_schlick(lobe->spec_f0, (float3)(lobe->spec_f90), cos_h);
#if CD_FEATURE_IRIDESCENCE
  if (lobe->iridescence > 0.0f) {
    // The dielectric's F0 before the specular factor, which scales its film as it does F_d
    float3 f0 = lobe->spec_f90 > 0.0f ? lobe->spec_f0 / lobe->spec_f90 : (float3)(0.0f);
    bool dielectric = lobe->metallic < 1.0f && lobe->transmission < 1.0f && lobe->spec_f90 > 0.0f;
    uint last = dielectric ? 2u : 1u;
    for (uint k = lobe->metallic > 0.0f ? 0u : 1u; k < last; ++k) {  // 0: the metal, 1: the dielectric
      float3 film =
          iridescence_fresnel(lobe->iridescence_ior, lobe->iridescence_thickness, k ? f0 : b->base_color, cos_h);
      if (k == 0u)
        *metal = mix(*metal, film, lobe->iridescence);
      else
        *spec = mix(*spec, lobe->spec_f90 * film, lobe->iridescence);
    }
  }
#endif
}

#if CD_FEATURE_SHEEN
// The sheen's albedo E(mu) with colour 1 (0 without the table)
float gltf_sheen_e(const Bsdf* b, float mu) {
  return sheen_albedo(b->lobe.gltf.sheen_albedo, mu, b->lobe.gltf.sheen_roughness);
}

// What the sheen leaves to the layers below it where its albedo is e: 1 - max3(colour) min(e, 1)
float gltf_sheen_below(const Bsdf* b, float e) {
  float c = max_component(b->lobe.gltf.sheen);
  return c > 0.0f ? fmax(1.0f - c * fmin(e, 1.0f), 0.0f) : 1.0f;
}

// The sheen lobe; where the Charlie lobe's albedo exceeds 1 (grazing angles at low sheen
// roughness) it is divided by max(1, E(mu_o), E(mu_i)), which keeps it reciprocal and its
// albedo at most 1
float3 gltf_sheen_f(const Bsdf* b, float e_o, float3 wo, float3 wi) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float norm = fmax(1.0f, fmax(e_o, gltf_sheen_e(b, wi.z)));
  return lobe->sheen * (sheen_eval(sheen_alpha(lobe->sheen_roughness), wo, wi) / norm);
}
#endif

// What depends on wo alone: the albedo-table lookups, the layers and the mixture weights
// (computed once per sample: bsdf_gltf_sample evaluates with the ones it sampled with)
typedef struct {
  GgxEnergy e;
  GltfLayer spec, coat;
  float base_norm;             // gltf_coat_base_norm
  bool coat_tilted;            // the coat has its own normal: its lobe works in coat_frame
  Frame coat_frame;            // the coat's frame in the local (shading) frame, z = n_c
  float coat_o;                // wo.n_c (wo.z when not tilted)
  float outer;                 // what the layers over the base (coat, sheen) leave it at wo
  float3 f_metal_o, f_spec_o;  // gltf_fresnel at wo.z: the weights and the mirror reflections
#if CD_FEATURE_SHEEN
  float sheen_e_o, sheen_o;  // gltf_sheen_e and gltf_sheen_below at wo
#endif
#if CD_FEATURE_DIFFUSE_ROUGHNESS
  float eon_e_o;  // diffuse_eon_albedo at wo of a base with diffuse roughness (else unused)
#endif
  float w[GLTF_COMPONENT_COUNT];  // selection probabilities by GLTF_* id, summing to 1 (or all 0)
} GltfAtWo;

// Each component's weight at wo before normalization: its albedo estimate, below the layers
// over it
float gltf_coat_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) { return g->coat.a_o; }

float gltf_sheen_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
#if CD_FEATURE_SHEEN
  const GltfBsdf* lobe = &b->lobe.gltf;
  float e = lobe->sheen_albedo ? fmin(g->sheen_e_o, 1.0f) : 1.0f;
  return (1.0f - g->coat.a_o) * luminance(lobe->sheen) * fmax(e, 0.01f);
#else
  return 0.0f;
#endif
}

float gltf_metal_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  return g->outer * b->lobe.gltf.metallic * g->e.e_o;
}

float gltf_spec_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float fs = luminance(g->f_spec_o);
  return g->outer * (1.0f - lobe->metallic) * (1.0f - lobe->transmission) * fs * g->e.e_o;
}

float gltf_diffuse_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  return g->outer * (1.0f - lobe->metallic) * (1.0f - lobe->transmission) * (1.0f - g->spec.a_o) *
         (1.0f - gltf_diffuse_transmission(b)) * luminance(b->base_color);
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

float gltf_ms_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  return g->e.table ? g->outer * energy_ms_albedo(&g->e) * luminance(gltf_ms_fresnel(b, &g->e)) : 0.0f;
}

float gltf_glass_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  return g->outer * (1.0f - lobe->metallic) * lobe->transmission;
}

GltfAtWo gltf_at_wo(const Bsdf* b, float3 wo) {
  GltfAtWo g;
  float cos_o = wo.z;
  g.e = gltf_energy(b, energy_at(wo));
  gltf_fresnel(b, cos_o, &g.f_metal_o, &g.f_spec_o);
  g.spec = gltf_spec_layer(b, &g.e, energy_at(wo));
  g.coat_tilted = b->lobe.gltf.coat_own_normal;
  g.coat_o = cos_o;
  if (g.coat_tilted) {
    g.coat_frame = frame_from_z(frame_to_local(&b->frame, b->lobe.gltf.coat_n));
    g.coat_o = dot(wo, g.coat_frame.n);
  }
  g.coat = gltf_coat_layer(b, clamp(g.coat_o, 0.0f, 1.0f));
  g.base_norm = gltf_coat_base_norm(b, &g.coat, &g.spec);
  g.outer = 1.0f - g.coat.a_o;
#if CD_FEATURE_SHEEN
  g.sheen_e_o = gltf_sheen_e(b, cos_o);
  g.sheen_o = gltf_sheen_below(b, g.sheen_e_o);
  g.outer *= g.sheen_o;
#endif
#if CD_FEATURE_DIFFUSE_ROUGHNESS
  float r = b->lobe.gltf.diffuse_roughness;
  g.eon_e_o = r > 0.0f ? diffuse_eon_albedo(cos_o, r) : 1.0f;
#endif
#define GLTF_WEIGHT(id, name, kind) g.w[id] = gltf_##name##_weight(b, &g, cos_o);
  GLTF_COMPONENTS(GLTF_WEIGHT)
#undef GLTF_WEIGHT
  float sum = g.w[0];
  for (uint k = 1u; k < GLTF_COMPONENT_COUNT; ++k) sum += g.w[k];
  float inv = sum > 0.0f ? 1.0f / sum : 0.0f;
  for (uint k = 0u; k < GLTF_COMPONENT_COUNT; ++k) g.w[k] *= inv;
  return g;
}

// pi x the diffuse base's BRDF: the base colour (Lambert), or pi x EON where
// KHR_materials_diffuse_roughness roughens it
float3 gltf_base_diffuse_pi(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi) {
#if CD_FEATURE_DIFFUSE_ROUGHNESS
  float r = b->lobe.gltf.diffuse_roughness;
  if (r > 0.0f) return diffuse_eon_eval_pi(b->base_color, r, g->eon_e_o, wo, wi);
#endif
  return b->base_color;
}

// A direction in the coat's frame, and |w.n_c|: the cosine the coat's albedo is taken at
float3 gltf_coat_local(const GltfAtWo* g, float3 w) { return g->coat_tilted ? frame_to_local(&g->coat_frame, w) : w; }
float gltf_coat_mu(const GltfAtWo* g, float3 w) {
  return fmin(fabs(g->coat_tilted ? dot(w, g->coat_frame.n) : w.z), 1.0f);
}

// What the coat leaves of light reflected below it into wi (both crossings)
float gltf_coat_below(const GltfAtWo* g, float3 wi) {
  return gltf_below_of(&g->coat, gltf_coat_albedo(&g->coat, gltf_coat_mu(g, wi)));
}

// What the coat leaves of light transmitted into wi: one crossing, at the outside direction's angle
float gltf_coat_across(const Bsdf* b, const GltfAtWo* g, float3 wi) {
  return 1.0f - gltf_coat_albedo(&g->coat, b->entering ? clamp(g->coat_o, 0.0f, 1.0f) : gltf_coat_mu(g, wi));
}

// The glass component's interface (bsdf_dielectric.cl with energy_dielectric.cl's
// multiple-scattering compensation). Under KHR_materials_iridescence the film's reflectance
// replaces the Fresnel term of the split between reflection and transmission, as it does
// the metal's and the plastic's (gltf_fresnel), for every index of the base, 1 included;
// the compensation lobe stays the bare interface's.
#if CD_FEATURE_IRIDESCENCE
DielectricFilm gltf_film(const Bsdf* b) {
  DielectricFilm film = {b->lobe.gltf.iridescence, b->lobe.gltf.iridescence_ior, b->lobe.gltf.iridescence_thickness};
  return film;
}
#endif

float3 gltf_glass_eval(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
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

// A sample of the glass's interface: the compensation lobe with probability q (as
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
    bs->f = gltf_glass_eval(b, wo, bs->wi, &bs->pdf);
    bs->flags = (transmits ? BSDF_TRANSMISSION : BSDF_REFLECTION) | BSDF_GLOSSY;
    bs->eta = transmits && !lobe->thin ? lobe->eta : 1.0f;
    return bs->pdf > 0.0f;
  }
#endif
  return energy_dielectric_sample(b->ggx_albedo, lobe->ggx, lobe->eta, lobe->thin, b->base_color, wo, uc, u, bs);
}

// Everything but delta components: f(wo, wi) and the mixture pdf of bsdf_gltf_sample, wo.z > 0
float3 gltf_eval_at(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, float* pdf) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  *pdf = 0.0f;
  GgxEnergy e = g->e;
  GltfLayer spec = g->spec;
  const float* w = g->w;
  float m = lobe->metallic, t = lobe->transmission;
  float3 under = (float3)(0.0f);  // all components below the coat
  float cos_h = wo.z;             // wo.h of reflections
  float d = 0.0f, p = 0.0f;
  if (wi.z > 0.0f) {
    // The microfacet terms only where a specular layer exists (not for pure Lambert)
    bool glossy = m > 0.0f || lobe->spec_f90 > 0.0f || lobe->coat > 0.0f;
    if (glossy) d = ggx_reflection_eval(lobe->ggx, wo, wi, &p, &cos_h);
    // E(wi) and E5(wi) of the specular lobe, looked up once for the layering and f_ms
    float e_i = 1.0f, e5_i = schlick_weight(wi.z);
    if (e.table) {
      e_i = energy_lookup(&e, 0, energy_at(wi));
      e5_i = energy_lookup(&e, 1, energy_at(wi));
    }
    under = (1.0f - m) * (1.0f - t) * (1.0f - gltf_diffuse_transmission(b)) *
            gltf_below_of(&spec, gltf_layer_albedo_of(&spec, e_i, e5_i)) * g->base_norm *
            gltf_base_diffuse_pi(b, g, wo, wi) * INV_PI_F;
    *pdf += w[GLTF_DIFFUSE] * sample_cosine_hemisphere_pdf(wi.z);
    if (glossy && !ggx_is_delta(lobe->ggx)) {
      float3 fm, fd;
      gltf_fresnel(b, cos_h, &fm, &fd);
      under += (m * fm + (1.0f - m) * (1.0f - t) * fd) * d;
      *pdf += (w[GLTF_METAL] + w[GLTF_SPEC]) * p;
    }
    if (e.table) {
      if (e.e_avg < 1.0f) under += gltf_ms_fresnel(b, &e) * energy_ms_of(&e, e_i);
      *pdf += w[GLTF_MS] * sample_cosine_hemisphere_pdf(wi.z);
    }
  }
  float3 dtrans = (float3)(0.0f);  // the diffuse transmission, layered as a reflection
#if CD_FEATURE_DIFFUSE_TRANSMISSION
  if (wi.z < 0.0f && lobe->diffuse_transmission > 0.0f) {
    dtrans = (1.0f - m) * (1.0f - t) * lobe->diffuse_transmission *
             gltf_below(&spec, energy_at((float3)(wi.x, wi.y, -wi.z))) * g->base_norm *
             lobe->diffuse_transmission_color * INV_PI_F;
    *pdf += w[GLTF_DIFFTRANS] * sample_cosine_hemisphere_pdf(-wi.z);
  }
#endif
  if (t > 0.0f) {
    float glass_p;
    under += (1.0f - m) * t * gltf_glass_eval(b, wo, wi, &glass_p);
    *pdf += w[GLTF_GLASS] * glass_p;
  }
#if CD_FEATURE_SHEEN
  // The sheen over them: albedo scaling, then its own lobe
  if (max_component(lobe->sheen) > 0.0f) {
    if (wi.z > 0.0f) {
      under =
          under * fmin(g->sheen_o, gltf_sheen_below(b, gltf_sheen_e(b, wi.z))) + gltf_sheen_f(b, g->sheen_e_o, wo, wi);
      *pdf += w[GLTF_SHEEN] * sheen_sample_pdf(wi);
    } else {
      float e_i = gltf_sheen_e(b, -wi.z);
      under *= b->entering ? g->sheen_o : gltf_sheen_below(b, e_i);
      dtrans *= fmin(g->sheen_o, gltf_sheen_below(b, e_i));
    }
  }
#endif
  // Reflected light crosses the coat twice; transmitted light once, at the angle of the
  // direction outside (the diffuse transmission twice, as a reflection)
  float3 f = under * (wi.z > 0.0f ? gltf_coat_below(g, wi) : gltf_coat_across(b, g, wi));
  if (wi.z < 0.0f) f += dtrans * gltf_coat_below(g, wi);
  if (wi.z > 0.0f && lobe->coat > 0.0f && !ggx_is_delta(lobe->coat_ggx)) {
    float coat_p, coat_h;
    float3 wi_c = gltf_coat_local(g, wi);
    float coat_d = ggx_reflection_eval(lobe->coat_ggx, gltf_coat_local(g, wo), wi_c, &coat_p, &coat_h);
    // About a normal of its own, the coat's projected solid angle is wi.n_c, not wi.z
    if (g->coat_tilted) coat_d *= wi_c.z / wi.z;
    f += gltf_coat_fresnel(b, coat_h) * coat_d;
    *pdf += w[GLTF_COAT] * coat_p;
  }
  return f;
}

// Everything but delta components: f(wo, wi) and the mixture pdf of bsdf_gltf_sample
float3 bsdf_gltf_eval(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (wo.z <= 0.0f) return (float3)(0.0f);
  GltfAtWo g = gltf_at_wo(b, wo);
  return gltf_eval_at(b, &g, wo, wi, pdf);
}

// A mirror reflection (a delta component) of weight `weight`, chosen with probability p
int gltf_mirror(float3 wo, float3 weight, float p, BsdfSample* bs) {
  bs->wi = (float3)(-wo.x, -wo.y, wo.z);
  bs->f = weight / wo.z;
  bs->pdf = p;
  bs->flags = BSDF_REFLECTION | BSDF_DELTA;
  bs->eta = 1.0f;
  return p > 0.0f ? GLTF_SAMPLE_DONE : GLTF_SAMPLE_FAILED;
}

// A direction from a GGX lobe's visible normals
int gltf_ggx_direction(Ggx g, float3 wo, float2 u, BsdfSample* bs) {
  return ggx_reflection_sample(g, wo, u, &bs->wi) ? GLTF_SAMPLE_DIRECTION : GLTF_SAMPLE_FAILED;
}

// Each component's sample from wo (wo.z > 0); a mirror reflection crosses the coat twice
// (in the coat's frame where it has its own normal: a mirror about n_c, a GGX sample about it)
int gltf_coat_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (!g->coat_tilted) {
    if (ggx_is_delta(lobe->coat_ggx)) return gltf_mirror(wo, (float3)(gltf_coat_fresnel(b, wo.z)), g->w[GLTF_COAT], bs);
    return gltf_ggx_direction(lobe->coat_ggx, wo, u, bs);
  }
  float3 wo_c = gltf_coat_local(g, wo);
  if (ggx_is_delta(lobe->coat_ggx)) {
    if (gltf_mirror(wo_c, (float3)(gltf_coat_fresnel(b, wo_c.z)), g->w[GLTF_COAT], bs) != GLTF_SAMPLE_DONE)
      return GLTF_SAMPLE_FAILED;
    bs->wi = frame_from_local(&g->coat_frame, bs->wi);
    if (!(bs->wi.z > 0.0f) || !(wo_c.z > 0.0f)) return GLTF_SAMPLE_FAILED;
    bs->f *= wo_c.z / bs->wi.z;  // weight / wi.z: the integrator weighs by wi.z
    return GLTF_SAMPLE_DONE;
  }
  if (gltf_ggx_direction(lobe->coat_ggx, wo_c, u, bs) != GLTF_SAMPLE_DIRECTION) return GLTF_SAMPLE_FAILED;
  bs->wi = frame_from_local(&g->coat_frame, bs->wi);
  return bs->wi.z > 0.0f ? GLTF_SAMPLE_DIRECTION : GLTF_SAMPLE_FAILED;
}

int gltf_sheen_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  bs->wi = sheen_sample(u);
  return GLTF_SAMPLE_DIRECTION;
}

// The layers between the coat and a mirror reflection of the base (the sheen, at mu_i = mu_o)
float3 gltf_mirror_below_sheen(const GltfAtWo* g, float3 weight) {
#if CD_FEATURE_SHEEN
  weight *= g->sheen_o;
#endif
  return weight;
}

int gltf_metal_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (ggx_is_delta(lobe->ggx)) {
    float3 weight = gltf_mirror_below_sheen(g, lobe->metallic * g->f_metal_o);
    return gltf_mirror(wo, gltf_coat_below(g, (float3)(-wo.x, -wo.y, wo.z)) * weight, g->w[GLTF_METAL], bs);
  }
  return gltf_ggx_direction(lobe->ggx, wo, u, bs);
}

int gltf_spec_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (ggx_is_delta(lobe->ggx)) {
    float3 weight = gltf_mirror_below_sheen(g, (1.0f - lobe->metallic) * (1.0f - lobe->transmission) * g->f_spec_o);
    return gltf_mirror(wo, gltf_coat_below(g, (float3)(-wo.x, -wo.y, wo.z)) * weight, g->w[GLTF_SPEC], bs);
  }
  return gltf_ggx_direction(lobe->ggx, wo, u, bs);
}

int gltf_diffuse_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  bs->wi = sample_cosine_hemisphere(u.x, u.y);
  return GLTF_SAMPLE_DIRECTION;
}

int gltf_difftrans_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  float3 d = sample_cosine_hemisphere(u.x, u.y);
  bs->wi = (float3)(d.x, d.y, -d.z);
  return GLTF_SAMPLE_DIRECTION;
}

int gltf_ms_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  bs->wi = sample_cosine_hemisphere(u.x, u.y);
  return GLTF_SAMPLE_DIRECTION;
}

// A delta transmission crosses the coat once, at the angle of the direction outside
int gltf_glass_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (!gltf_glass_interface_sample(b, wo, uc, u, bs)) return GLTF_SAMPLE_FAILED;
  if (!(bs->flags & BSDF_DELTA)) return GLTF_SAMPLE_DIRECTION;
  float att = bs->wi.z > 0.0f ? gltf_coat_below(g, bs->wi) : gltf_coat_across(b, g, bs->wi);
#if CD_FEATURE_SHEEN
  if (max_component(lobe->sheen) > 0.0f)
    att *= bs->wi.z > 0.0f || b->entering ? g->sheen_o : gltf_sheen_below(b, gltf_sheen_e(b, -bs->wi.z));
#endif
  bs->f *= att * (1.0f - lobe->metallic) * lobe->transmission;
  bs->pdf *= g->w[GLTF_GLASS];
  return bs->pdf > 0.0f ? GLTF_SAMPLE_DONE : GLTF_SAMPLE_FAILED;
}

// Each component's lobes (a GGX reflection about the mirror direction, cosine lobes about
// the normal; the glass splits its weight by the Fresnel reflectance at wo between its
// reflection and its transmission, about the refracted direction, or straight through a
// thin sheet)
void gltf_ggx_lobe(Ggx g, float3 wo, float w, BsdfLobes* l) {
  if (!ggx_is_delta(g)) bsdf_lobes_add(l, (float3)(-wo.x, -wo.y, wo.z), bsdf_lobe_omega_ggx(g), w);
}

// (about n_c where the coat has its own normal)
void gltf_coat_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  Ggx c = b->lobe.gltf.coat_ggx;
  if (!g->coat_tilted) {
    gltf_ggx_lobe(c, wo, w, l);
  } else if (!ggx_is_delta(c)) {
    float3 n = g->coat_frame.n;
    bsdf_lobes_add(l, 2.0f * dot(wo, n) * n - wo, bsdf_lobe_omega_ggx(c), w);
  }
}

// The sheen spreads over the hemisphere whatever its roughness: a cosine lobe's support
void gltf_sheen_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, 1.0f), bsdf_lobe_omega_cosine(), w);
}

void gltf_metal_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  gltf_ggx_lobe(b->lobe.gltf.ggx, wo, w, l);
}

void gltf_spec_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  gltf_ggx_lobe(b->lobe.gltf.ggx, wo, w, l);
}

void gltf_diffuse_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, 1.0f), bsdf_lobe_omega_cosine(), w);
}

void gltf_difftrans_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, -1.0f), bsdf_lobe_omega_cosine(), w);
}

void gltf_ms_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  bsdf_lobes_add(l, (float3)(0.0f, 0.0f, 1.0f), bsdf_lobe_omega_cosine(), w);
}

void gltf_glass_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (ggx_is_delta(lobe->ggx)) return;
  float r = fresnel_dielectric(wo.z, lobe->eta);
#if CD_FEATURE_IRIDESCENCE
  if (lobe->iridescence > 0.0f) r = dielectric_film_share(dielectric_film_fresnel(gltf_film(b), wo.z, lobe->eta, false));
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

// The kinds of lobe present
uint bsdf_gltf_flags(const Bsdf* b) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  uint flags = BSDF_REFLECTION;
  bool plastic = lobe->metallic < 1.0f && lobe->transmission < 1.0f;
  if (plastic && max_component(b->base_color) > 0.0f) flags |= BSDF_DIFFUSE;
  bool spec_delta = ggx_is_delta(lobe->ggx), coat_delta = lobe->coat > 0.0f && ggx_is_delta(lobe->coat_ggx);
  if (lobe->metallic > 0.0f || lobe->spec_f90 > 0.0f || lobe->transmission > 0.0f)
    flags |= spec_delta ? BSDF_DELTA : BSDF_GLOSSY;
  if (lobe->coat > 0.0f) flags |= coat_delta ? BSDF_DELTA : BSDF_GLOSSY;
  if (lobe->transmission > 0.0f && lobe->metallic < 1.0f) flags |= BSDF_TRANSMISSION;
#if CD_FEATURE_SHEEN
  if (max_component(lobe->sheen) > 0.0f) flags |= BSDF_GLOSSY;
#endif
#if CD_FEATURE_DIFFUSE_TRANSMISSION
  if (plastic && lobe->diffuse_transmission > 0.0f && max_component(lobe->diffuse_transmission_color) > 0.0f)
    flags |= BSDF_DIFFUSE | BSDF_TRANSMISSION;
#endif
  return flags;
}
