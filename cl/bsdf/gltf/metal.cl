// The metal: metallic * F_m * GGX, F_m = Schlick(base color, 1) (gltf_fresnel). It shares its
// GGX lobe with the plastic's specular reflection: one microfacet evaluation, spec's term.

float gltf_metal_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) {
  return g->outer * b->lobe.gltf.metallic * g->e.e_o;
}

// A mirror reflection crosses the layers over it twice
int gltf_metal_sample(const Bsdf* b, const GltfAtWo* g, float3 wo, float uc, float2 u, BsdfSample* bs) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  if (ggx_is_delta(lobe->ggx)) {
    float3 weight = gltf_mirror_below_sheen(g, lobe->metallic * g->f_metal_o);
    return gltf_mirror(wo, gltf_coat_below(g, (float3)(-wo.x, -wo.y, wo.z)) * weight, g->w[GLTF_METAL], bs);
  }
  return gltf_ggx_direction(lobe->ggx, wo, u, bs);
}

void gltf_metal_lobes(const Bsdf* b, const GltfAtWo* g, float3 wo, float w, BsdfLobes* l) {
  gltf_ggx_lobe(b->lobe.gltf.ggx, wo, w, l);
}

// Its term is spec's (gltf_spec_eval), which adds both lobes and both weights' pdfs
void gltf_metal_eval(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, GltfEval* acc) {}

// Its factor is the base's (bsdf_gltf_params)
bool gltf_metal_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
  return b->lobe.gltf.metallic != 0.0f;
}

void gltf_metal_at_wo(const Bsdf* b, float3 wo, GltfAtWo* g) {}

uint gltf_metal_flags(const Bsdf* b) { return b->lobe.gltf.metallic > 0.0f ? gltf_ggx_flags(b->lobe.gltf.ggx) : 0u; }
