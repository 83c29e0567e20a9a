// The glTF metallic-roughness BSDF (glTF 2.0 Appendix B, KHR_materials_* extensions) in the
// local frame is a mixture of components, one file each in cl/bsdf/gltf/ (coat, sheen, metal,
// spec, difftrans, diffuse, ms, glass; fresnel.cl holds the metal's and the dielectric's
// Fresnel terms with their modifiers), which cl/bsdf/bsdf_gltf.cl composes through the lists
// below. This file holds the lists and what the components share: the layers' albedo
// scaling, the state at wo and the evaluation's accumulator.
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
// flag of a direction the component samples. Each has, in cl/bsdf/gltf/NAME.cl,
//   bool gltf_NAME_params(const SceneData*, __global const Material*, const SurfaceHit*, Bsdf*):
//        reads its parameters at the hit (after the base's); whether it is present there
//   void gltf_NAME_at_wo(const Bsdf*, float3 wo, GltfAtWo*): its state at wo, in list
//        order (a layer's before what lies below it)
//   uint gltf_NAME_flags(const Bsdf*): the BSDF_* kinds of lobe it adds
//   float gltf_NAME_weight(const Bsdf*, const GltfAtWo*, float cos_o): its weight at wo
//   int gltf_NAME_sample(const Bsdf*, const GltfAtWo*, float3 wo, float uc, float2 u, BsdfSample*)
//   void gltf_NAME_lobes(const Bsdf*, const GltfAtWo*, float3 wo, float w, BsdfLobes*): the
//        lobe(s) it samples, of total weight w (none if delta), for the strategy choice
//   void gltf_NAME_eval(const Bsdf*, const GltfAtWo*, float3 wo, float3 wi, GltfEval*): its
//        term of f and pdf, added to the accumulator
// GLTF_EVAL_ORDER: X(name), the same components in the order gltf_eval_at adds their terms,
// bottom up: the base's terms, then the layers over them (the sheen scales what lies below
// it and adds its lobe; the coat scales everything below and adds its own). The metal and
// the plastic's specular lobe share one microfacet evaluation, spec's term. Sums add their
// terms in this order, which fixes every image to the bit.
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
#define GLTF_EVAL_ORDER(X) \
  X(diffuse)               \
  X(metal)                 \
  X(spec)                  \
  X(ms)                    \
  X(difftrans)             \
  X(glass)                 \
  X(sheen)                 \
  X(coat)
// clang-format on
#define GLTF_COUNT_COMPONENT(id, name, kind) +1
#define GLTF_COMPONENT_COUNT (0 GLTF_COMPONENTS(GLTF_COUNT_COMPONENT))

// What a component's sample did
#define GLTF_SAMPLE_FAILED 0     // nothing: the path ends
#define GLTF_SAMPLE_DIRECTION 1  // chose bs->wi, which the whole mixture weighs
#define GLTF_SAMPLE_DONE 2       // a complete sample of a delta component

float schlick_weight(float cos_i) {
  float m = clamp(1.0f - cos_i, 0.0f, 1.0f);
  float m2 = m * m;
  return m2 * m2 * m;
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

// W(wo, wi) of what lies below the layer, both directions above, from its albedo a_i at wi
float gltf_below_of(const GltfLayer* l, float a_i) {
  float w = (1.0f - l->a_o) * (1.0f - a_i);
  return fmax(l->normalized ? w / (1.0f - l->a_avg) : w, 0.0f);
}

float gltf_below(const GltfLayer* l, EnergyDir wi) { return gltf_below_of(l, gltf_layer_albedo(l, wi)); }

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

// f(wo, wi) and the mixture pdf as gltf_eval_at sums them, component by component
typedef struct {
  float3 under;   // all components below the coat
  float3 dtrans;  // the diffuse transmission, layered as a reflection
  float3 f;       // the whole BSDF: the coat's term sets it from under and dtrans
  float pdf;
  // Shared by the base's terms where wi.z > 0: the GGX reflection's value d, pdf p and wo.h
  // (where a specular layer exists: glossy), and E(wi), E5(wi) of the specular lobe
  bool glossy;
  float d, p, cos_h;
  float e_i, e5_i;
} GltfEval;

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

// A GGX reflection's lobe about the mirror direction (none if delta)
void gltf_ggx_lobe(Ggx g, float3 wo, float w, BsdfLobes* l) {
  if (!ggx_is_delta(g)) bsdf_lobes_add(l, (float3)(-wo.x, -wo.y, wo.z), bsdf_lobe_omega_ggx(g), w);
}

// The kind of a GGX lobe
uint gltf_ggx_flags(Ggx g) { return ggx_is_delta(g) ? BSDF_DELTA : BSDF_GLOSSY; }
