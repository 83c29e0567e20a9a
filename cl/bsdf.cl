// BSDF interface: one record per shading point, and sample / eval / pdf dispatched by
// a switch on the material type. Directions point away from the surface; ns and ng are
// already turned to the side of wo.

typedef struct {
  uint type;
  float3 base_color;
} Bsdf;

// glTF base color: factor x texture x COLOR_0
Bsdf bsdf_at(__global const Material* m, const TextureSet* textures, const SurfaceHit* s) {
  Bsdf b;
  b.type = m->type;
  b.base_color = load3(m->base_color) *
                 textures_lookup(textures, m->base_color_texture, s->uv).xyz * s->vertex_color;
  return b;
}

float3 bsdf_eval(const Bsdf* b, float3 wo, float3 wi, float3 ns, float3 ng) {
  switch (b->type) {
    case MATERIAL_DIFFUSE:
    default:
      return bsdf_diffuse_eval(b->base_color, wi, ns, ng);
  }
}

float bsdf_pdf(const Bsdf* b, float3 wo, float3 wi, float3 ns, float3 ng) {
  switch (b->type) {
    case MATERIAL_DIFFUSE:
    default:
      return bsdf_diffuse_pdf(wi, ns, ng);
  }
}

// Samples wi; returns false when the path ends here.
bool bsdf_sample(const Bsdf* b, float3 wo, float3 ns, float3 ng, float2 u, float3* wi,
                 float3* f, float* pdf) {
  switch (b->type) {
    case MATERIAL_DIFFUSE:
    default:
      return bsdf_diffuse_sample(b->base_color, ns, ng, u, wi, f, pdf);
  }
}
