// The plastic's specular layer: (1 - metallic)(1 - transmission) * F_d * GGX, F_d =
// Schlick(F0 from ior and KHR_materials_specular, f90 = specular) (gltf_fresnel), over the
// diffuse base (diffuse.cl, difftrans.cl), which gets what it does not reflect (the
// layering in mixture.cl).

// The plastic's specular layer over its diffuse base, normalized where the table is bound
GltfLayer gltf_spec_layer(const Bsdf* b, const GgxEnergy* e, EnergyDir wo) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float3 f_ms = energy_ms_fresnel(e, energy_schlick_average(lobe->spec_f0, (float3)(lobe->spec_f90)));
  GltfLayer l = gltf_layer(*e, lobe->spec_f0, lobe->spec_f90, f_ms, b->ggx_albedo != 0);
  // A(wo) from E(wo) and E5(wo) as energy_ggx looked them up (Schlick's F without the table)
  l.a_o = gltf_layer_albedo_of(&l, e->table ? e->e_o : 1.0f, e->table ? e->e5_o : schlick_weight(energy_dir_mu(wo)));
  return l;
}

float gltf_spec_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float fs = luminance(g->f_spec_o);
  return g->outer * (1.0f - lobe->metallic) * (1.0f - lobe->transmission) * fs * g->e.e_o;
}

// A mirror reflection crosses the layers over it twice
int gltf_spec_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (ggx_is_delta(lobe->ggx)) {
    float3 weight = gltf_mirror_below_sheen(g, (1.0f - lobe->metallic) * (1.0f - lobe->transmission) * g->f_spec_o);
    return gltf_mirror(wo, gltf_coat_below(g, (float3)(-wo.x, -wo.y, wo.z)) * weight, g->w[GLTF_SPEC], bs);
  }
  return gltf_ggx_direction(lobe->ggx, wo, u, bs);
}

void gltf_spec_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  gltf_ggx_lobe(b->lobe.gltf.ggx, wo, w, l);
}

// The metal's and the plastic's specular GGX lobes, from the one microfacet evaluation
// (acc->d, acc->p); both sample it, so their weights add in its pdf
void gltf_spec_eval(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, GltfEval* acc) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  float m = lobe->metallic, t = lobe->transmission;
  if (acc->glossy && !ggx_is_delta(lobe->ggx)) {
    float3 fm, fd;
    gltf_fresnel(b, acc->cos_h, &fm, &fd);
    acc->under += (m * fm + (1.0f - m) * (1.0f - t) * fd) * acc->d;
    acc->pdf += (g->w[GLTF_METAL] + g->w[GLTF_SPEC]) * acc->p;
  }
}

// Its F0 and F90 are the base's (bsdf_gltf_params: they follow the index of refraction)
bool gltf_spec_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
  return b->lobe.gltf.spec_f90 != 0.0f;
}

// Its layer at wo (after the base's table lookup)
void gltf_spec_at_wo(const Bsdf* b, float3 wo, GltfAtWo* g) { g->spec = gltf_spec_layer(b, &g->e, energy_at(wo)); }

uint gltf_spec_flags(const Bsdf* b) { return b->lobe.gltf.spec_f90 > 0.0f ? gltf_ggx_flags(b->lobe.gltf.ggx) : 0u; }
