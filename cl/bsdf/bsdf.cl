// BSDF interface: bsdf_at evaluates the material at a shading point into a Bsdf record;
// flags / eval / pdf / sample / lobes go to the material type's lobe (bsdf_NAME.cl).
// Every dispatch on the type is generated from CD_MATERIALS (cl/shared/device_types.h): a
// type whose feature is off (SceneFeatures) has its `if (0 && ...)` folded away, so its lobe
// is compiled out; an unknown type shades as MATERIAL_DIFFUSE. Lobes work in the local frame
// (z = shading normal, turned to the geometric side wo comes from; where the shading normal
// bends away, wo may still lie below it and glossy lobes then return nothing). This file
// converts world <-> local and makes the geometric-normal side test, once, for every lobe: a
// direction on wo's side of the surface can only be reflected into, one on the other side
// only transmitted into.

// The shading frame: the interpolated normal and tangent (bsdf_geometry_frame), then the
// normal map (bsdf_mapped_normal, bent back above the geometric plane on wo's side)
Frame bsdf_shading_frame(const SceneData* sc, __global const Material* m, const SurfaceHit* s) {
  Frame f = bsdf_geometry_frame(s);
  float3 n;
  if (bsdf_mapped_normal(sc, m, s, &f, TEX_NORMAL, m->normal_scale, &n)) {
    float handed = s->tangent_sign * (s->front ? 1.0f : -1.0f);
    f = frame_from_z_x(n, f.t);
    f.b *= handed;
  }
  return f;
}

// The BSDF at a shading point: what every type has, then the type's params. `channel`
// (CD_FEATURE_DISPERSION): the RGB channel a dispersive material takes its ior at, -1 none
Bsdf bsdf_at_channel(const SceneData* sc, const SurfaceHit* s, int channel) {
  __global const Material* m = &sc->materials[s->material];
  const uint type = m->type;
  Bsdf b;
  b.frame = bsdf_shading_frame(sc, m, s);
  b.ng = s->ng;
  b.entering = s->front;
  b.type = type;
  b.base_color = load3(m->base_color) * bsdf_texture(sc, m, TEX_BASE_COLOR, s).xyz * s->vertex_color;
  b.ggx_albedo = sc->ggx_albedo;
#if CD_FEATURE_DISPERSION
  b.channel = channel;
#endif
#define BSDF_PARAMS(id, name, feature) \
  if (feature && type == id) bsdf_##name##_params(sc, m, s, &b);
  CD_MATERIALS(BSDF_PARAMS)
#undef BSDF_PARAMS
  return b;
}

Bsdf bsdf_at(const SceneData* sc, const SurfaceHit* s) { return bsdf_at_channel(sc, s, -1); }

// The kinds of lobe this BSDF has (BSDF_* flags); light sampling and the integrator ask
uint bsdf_flags(const Bsdf* b) {
#define BSDF_FLAGS(id, name, feature) \
  if (feature && b->type == id) return bsdf_##name##_flags(b);
  CD_MATERIALS(BSDF_FLAGS)
#undef BSDF_FLAGS
  return bsdf_diffuse_flags(b);
}

// STRATEGY_AUTO's lobe summary of this BSDF at wo (BsdfLobes, bsdf_common.cl): the type's
// lobes, turned to world space
void bsdf_lobes_local(const Bsdf* b, float3 wo, BsdfLobes* l) {
#define BSDF_LOBES(id, name, feature) \
  if (feature && b->type == id) {     \
    bsdf_##name##_lobes(b, wo, l);    \
    return;                           \
  }
  CD_MATERIALS(BSDF_LOBES)
#undef BSDF_LOBES
  bsdf_diffuse_lobes(b, wo, l);
}

// The lobes' directions from the shading frame to world space
void bsdf_lobes_to_world(const Bsdf* b, BsdfLobes* l) {
  for (uint k = 0u; k < l->count; ++k) l->dir[k] = frame_from_local(&b->frame, l->dir[k]);
}

// (The integrator takes the lobes from bsdf_sample_lobes; the tests check the two agree.)
BsdfLobes bsdf_lobes(const Bsdf* b, float3 wo) {
  BsdfLobes l;
  l.count = 0u;
  bsdf_lobes_local(b, frame_to_local(&b->frame, wo), &l);
  bsdf_lobes_to_world(b, &l);
  return l;
}

// Shading normals (interpolated, normal-mapped) can tilt so far from the geometric normal
// that, near silhouettes, wo lies below the shading hemisphere or reflects about the
// shading normal to below the surface: no reflection lobe returns anything there, and the
// surface shows black fringes. Where the mirror direction of wo about the shading normal
// falls below q = min(0.9 wo.ng, 0.01) above the geometric plane, the shading normal is
// replaced by the half vector of wo and the direction R' that keeps the mirror direction's
// azimuth at height q (the idea of Cycles' ensure_valid_reflection). The frame's tangent
// follows by Gram-Schmidt; the geometric side test still decides reflection and
// transmission. Called by the integrator once it knows wo (the BSDF tests see the
// unmodified frame).
void bsdf_face_wo(Bsdf* b, float3 wo) {
  float3 n = b->frame.n, ng = b->ng;
  float cos_o = dot(wo, ng);
  if (!(cos_o > 0.0f)) return;
  float q = fmin(0.9f * cos_o, 0.01f);
  float3 r = 2.0f * dot(wo, n) * n - wo;
  if (dot(r, ng) >= q) return;
  float3 rt = r - dot(r, ng) * ng;
  float len = length(rt);
  if (!(len > 1e-6f)) {
    rt = dot(wo, ng) * ng - wo;  // the mirror image of wo's tangential part
    len = length(rt);
    if (!(len > 1e-6f)) return;
  }
  float3 r_valid = rt * (sqrt(1.0f - q * q) / len) + q * ng;
  float3 n_new = normalize(wo + r_valid);
  float handed = dot(cross(b->frame.n, b->frame.t), b->frame.b) >= 0.0f ? 1.0f : -1.0f;
  b->frame = frame_from_z_x(n_new, b->frame.t);
  b->frame.b *= handed;
}

// The geometric side test: wi lies on wo's side of the surface
bool bsdf_is_reflection(const Bsdf* b, float3 wi) { return dot(wi, b->ng) > 0.0f; }

// f(wo, wi) of the non-delta lobes, and their pdf for bsdf_sample in *pdf
float3 bsdf_eval_pdf(const Bsdf* b, float3 wo, float3 wi, float* pdf) {
  float3 wo_l = frame_to_local(&b->frame, wo), wi_l = frame_to_local(&b->frame, wi);
  *pdf = 0.0f;
  // The local side must agree with the geometric one
  if (bsdf_is_reflection(b, wi) != (wi_l.z > 0.0f)) return (float3)(0.0f);
#define BSDF_EVAL(id, name, feature) \
  if (feature && b->type == id) return bsdf_##name##_eval(b, wo_l, wi_l, pdf);
  CD_MATERIALS(BSDF_EVAL)
#undef BSDF_EVAL
  return bsdf_diffuse_eval(b, wo_l, wi_l, pdf);
}

float3 bsdf_eval(const Bsdf* b, float3 wo, float3 wi) {
  float pdf;
  return bsdf_eval_pdf(b, wo, wi, &pdf);
}

float bsdf_pdf(const Bsdf* b, float3 wo, float3 wi) {
  float pdf;
  bsdf_eval_pdf(b, wo, wi, &pdf);
  return pdf;
}

// The lobe's sample in the local frame (and with l its lobes at wo)
bool bsdf_sample_local(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs, BsdfLobes* l) {
#define BSDF_SAMPLE(id, name, feature) \
  if (feature && b->type == id) return bsdf_##name##_sample(b, wo, uc, u, bs, l);
  CD_MATERIALS(BSDF_SAMPLE)
#undef BSDF_SAMPLE
  return bsdf_diffuse_sample(b, wo, uc, u, bs, l);
}

// Samples bs->wi (world space) from uc (lobe choice) and u; false when the path ends here.
// With `lobes` (STRATEGY_AUTO), also bsdf_lobes(b, wo) into it, whatever the sample, so that
// a type can compute what both need at wo once (the glTF mixture does).
bool bsdf_sample_lobes(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs, BsdfLobes* lobes) {
  float3 wo_l = frame_to_local(&b->frame, wo);
  if (lobes) lobes->count = 0u;
  bool ok = bsdf_sample_local(b, wo_l, uc, u, bs, lobes);
  if (lobes) bsdf_lobes_to_world(b, lobes);
  if (!ok) return false;
  bool local_reflection = bs->wi.z > 0.0f;
  bs->wi = frame_from_local(&b->frame, bs->wi);
  // A direction whose geometric side disagrees with its lobe carries nothing
  if (bsdf_is_reflection(b, bs->wi) != ((bs->flags & BSDF_REFLECTION) != 0u)) return false;
  if (local_reflection != ((bs->flags & BSDF_REFLECTION) != 0u)) return false;
  return bs->pdf > 0.0f && max_component(bs->f) > 0.0f;
}

bool bsdf_sample(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs) {
  return bsdf_sample_lobes(b, wo, uc, u, bs, 0);
}
