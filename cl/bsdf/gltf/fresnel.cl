// The Fresnel terms of the metal's and the plastic's specular GGX lobes and their modifiers:
//   metal:    F_m = Schlick(base color, 1)
//   specular: F_d = Schlick(F0 from ior and KHR_materials_specular, f90 = specular); the
//             specular colour and factor enter through spec_f0 and spec_f90 (bsdf_gltf_params)
//   film:     (CD_FEATURE_IRIDESCENCE) KHR_materials_iridescence mixes a thin film's
//             reflectance (iridescence.cl) into F_m and F_d: F = mix(F, film over that base,
//             factor), the dielectric's film scaled by its specular factor; the glass's split
//             between reflection and transmission takes the film too (glass.cl), for every
//             base index, 1 included. The layering (W, the albedo weights) and the multiple
//             scattering keep the base's own Fresnel terms

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

// The film's factor (texture R) and thickness, from minimum to maximum by texture G; a film
// of thickness 0 is none
void gltf_fresnel_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
#if CD_FEATURE_IRIDESCENCE
  __global const GltfMaterial* g = &m->params.gltf;
  GltfBsdf* lobe = &b->lobe.gltf;
  lobe->iridescence_thickness = mix(g->iridescence_thickness_min, g->iridescence_thickness_max,
                                    bsdf_texture(sc, m, TEX_IRIDESCENCE_THICKNESS, s).y);
  if (!(lobe->iridescence_thickness > 0.0f)) lobe->iridescence = 0.0f;
#endif
}
