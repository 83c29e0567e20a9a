// BSDF interface: one record per shading point holding the shading frame, the geometric
// normal and the material's evaluated parameters; sample / eval / pdf dispatched by a
// switch on the material type. Lobes (bsdf_*.cl) work in the local frame (z = shading
// normal, turned to the side wo comes from); this file converts world <-> local and makes
// the geometric-normal side test, once, for every lobe: a direction on wo's side of the
// surface can only be reflected into, one on the other side only transmitted into.

typedef struct {
  Frame frame;  // shading frame; frame.n is the shading normal on wo's side
  float3 ng;  // geometric normal on wo's side
  bool entering;  // wo is on the front face (dielectrics: outside -> inside)
  uint type;  // MATERIAL_*
  float3 base_color;  // glTF base color: factor x texture x COLOR_0
} Bsdf;

Bsdf bsdf_at(const SceneData* sc, const SurfaceHit* s) {
  __global const Material* m = &sc->materials[s->material];
  Bsdf b;
  b.frame = frame_from_z_x(s->ns, s->tangent);
  b.ng = s->ng;
  b.entering = s->front;
  b.type = m->type;
  b.base_color = load3(m->base_color) * textures_lookup(sc, &m->base_color_texture, s->uvs).xyz *
                 s->vertex_color;
  return b;
}

// The kinds of lobe this BSDF has (BSDF_* flags); light sampling and the integrator ask
uint bsdf_flags(const Bsdf* b) {
  switch (b->type) {
    case MATERIAL_DIFFUSE:
    default:
      return BSDF_REFLECTION | BSDF_DIFFUSE;
  }
}

// The geometric side test: wi lies on wo's side of the surface
bool bsdf_is_reflection(const Bsdf* b, float3 wi) { return dot(wi, b->ng) > 0.0f; }

float3 bsdf_eval(const Bsdf* b, float3 wo, float3 wi) {
  float3 wo_l = frame_to_local(&b->frame, wo), wi_l = frame_to_local(&b->frame, wi);
  bool reflect = bsdf_is_reflection(b, wi);
  switch (b->type) {
    case MATERIAL_DIFFUSE:
    default:
      return reflect ? bsdf_diffuse_eval(b->base_color, wo_l, wi_l) : (float3)(0.0f);
  }
}

float bsdf_pdf(const Bsdf* b, float3 wo, float3 wi) {
  float3 wo_l = frame_to_local(&b->frame, wo), wi_l = frame_to_local(&b->frame, wi);
  bool reflect = bsdf_is_reflection(b, wi);
  switch (b->type) {
    case MATERIAL_DIFFUSE:
    default:
      return reflect ? bsdf_diffuse_pdf(wo_l, wi_l) : 0.0f;
  }
}

// Samples bs->wi (world space) from uc (lobe choice) and u; false when the path ends here
bool bsdf_sample(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs) {
  float3 wo_l = frame_to_local(&b->frame, wo);
  bool ok;
  switch (b->type) {
    case MATERIAL_DIFFUSE:
    default:
      ok = bsdf_diffuse_sample(b->base_color, wo_l, u, bs);
  }
  if (!ok) return false;
  bs->wi = frame_from_local(&b->frame, bs->wi);
  // A direction whose geometric side disagrees with its lobe carries nothing
  if (bsdf_is_reflection(b, bs->wi) != ((bs->flags & BSDF_REFLECTION) != 0u)) return false;
  return bs->pdf > 0.0f && max_component(bs->f) > 0.0f;
}
