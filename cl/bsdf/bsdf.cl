// BSDF interface: bsdf_at evaluates the material at a shading point into a Bsdf record
// (bsdf_common.cl); sample / eval / pdf are dispatched by a switch on the material type.
// Lobes (bsdf_*.cl) work in the local frame (z = shading normal, turned to the geometric
// side wo comes from; where the shading normal bends away, wo may still lie below it and
// glossy lobes then return nothing). This file converts world <-> local and makes the
// geometric-normal side test, once, for every lobe: a direction on wo's side of the
// surface can only be reflected into, one on the other side only transmitted into.

// Material types a scene has none of are compiled out (SceneFeatures; glTF materials that
// are exactly Lambertian arrive as MATERIAL_DIFFUSE, MaterialDesc::kernel_type)
#ifndef CD_FEATURE_GLTF_BSDF
#define CD_FEATURE_GLTF_BSDF 1
#endif
#ifndef CD_FEATURE_CONDUCTOR
#define CD_FEATURE_CONDUCTOR 1
#endif

float4 bsdf_texture(const SceneData* sc, __global const Material* m, int slot, const SurfaceHit* s) {
  return textures_lookup(sc, &m->textures[slot], s->uvs);
}

// The shading frame: the interpolated normal and tangent, then the normal map in the
// glTF tangent space (bitangent = sign * n x t; back faces mirror it). A mapped normal
// that would face away from wo's side of the geometry is bent back to just above it, so
// no light leaks through and no black fringe appears (the method is to clamp the
// mapped normal to the geometric hemisphere, as many renderers do).
Frame bsdf_shading_frame(const SceneData* sc, __global const Material* m, const SurfaceHit* s) {
  Frame f = frame_from_z_x(s->ns, s->tangent);
  float handed = s->tangent_sign * (s->front ? 1.0f : -1.0f);
  f.b *= handed;
#if CD_FEATURE_TEXTURES
  if (m->textures[TEX_NORMAL].index != NO_TEXTURE) {
    float3 t = bsdf_texture(sc, m, TEX_NORMAL, s).xyz * 2.0f - 1.0f;
    t.xy *= m->normal_scale;
    float3 n = frame_from_local(&f, (float3)(t.x, s->front ? t.y : -t.y, t.z));
    float len = length(n);
    if (len > 0.0f && isfinite(len)) {
      n /= len;
      float c = dot(n, s->ng);
      if (c < 0.01f) n = normalize(n + (0.01f - c) * s->ng);
      f = frame_from_z_x(n, f.t);
      f.b *= handed;
    }
  }
#endif
  return f;
}

// Roughness (x metallicRoughnessTexture G) and KHR_materials_anisotropy: the strength, and
// a direction in the tangent plane, rotated, that the frame's tangent turns to
void bsdf_roughness_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
  float roughness = m->roughness * bsdf_texture(sc, m, TEX_METALLIC_ROUGHNESS, s).y;
  float4 an = bsdf_texture(sc, m, TEX_ANISOTROPY, s);
  float2 dir = m->textures[TEX_ANISOTROPY].index != NO_TEXTURE ? an.xy * 2.0f - 1.0f : (float2)(1.0f, 0.0f);
  float strength = m->anisotropy_strength * (m->textures[TEX_ANISOTROPY].index != NO_TEXTURE ? an.z : 1.0f);
  if (strength > 0.0f) {
    float cr, sr = sincos(m->anisotropy_rotation, &cr);
    float3 t = (cr * dir.x - sr * dir.y) * b->frame.t + (sr * dir.x + cr * dir.y) * b->frame.b;
    float hand = dot(cross(b->frame.n, b->frame.t), b->frame.b) < 0.0f ? -1.0f : 1.0f;
    b->frame = frame_from_z_x(b->frame.n, t);
    b->frame.b *= hand;
  }
  b->ggx = ggx_from_roughness(roughness, strength);
}

void bsdf_gltf_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
  b->metallic = m->metallic * bsdf_texture(sc, m, TEX_METALLIC_ROUGHNESS, s).z;
  bsdf_roughness_params(sc, m, s, b);
  b->transmission = m->transmission * bsdf_texture(sc, m, TEX_TRANSMISSION, s).x;
  b->thin = (m->flags & MATERIAL_THIN_WALLED) != 0u;
  // KHR_materials_specular: F0 = min(F0(ior) x colour, 1) x specular, F90 = specular
  float spec = m->specular_color[3] * bsdf_texture(sc, m, TEX_SPECULAR, s).w;
  float r = (m->ior - 1.0f) / (m->ior + 1.0f);
  float3 tint = load3(m->specular_color) * bsdf_texture(sc, m, TEX_SPECULAR_COLOR, s).xyz;
  b->spec_f0 = fmin(r * r * tint, (float3)(1.0f)) * spec;
  b->spec_f90 = spec;
  // A thin sheet has air on both sides: light meets air -> glass from either face
  b->eta = b->entering || b->thin ? m->ior : 1.0f / m->ior;
  b->coat = m->clearcoat * bsdf_texture(sc, m, TEX_CLEARCOAT, s).x;
  float coat_rough = m->clearcoat_roughness * bsdf_texture(sc, m, TEX_CLEARCOAT_ROUGHNESS, s).y;
  b->coat_ggx = ggx_from_roughness(coat_rough, 0.0f);
}

Bsdf bsdf_at(const SceneData* sc, const SurfaceHit* s) {
  __global const Material* m = &sc->materials[s->material];
  Bsdf b;
  b.frame = bsdf_shading_frame(sc, m, s);
  b.ng = s->ng;
  b.entering = s->front;
  b.type = m->type;
  b.base_color = load3(m->base_color) * bsdf_texture(sc, m, TEX_BASE_COLOR, s).xyz * s->vertex_color;
  b.metallic = 0.0f;
  b.transmission = 0.0f;
  b.coat = 0.0f;
  b.ggx = ggx_from_roughness(m->roughness, 0.0f);
  b.coat_ggx = b.ggx;
  b.eta = 1.0f;
  b.thin = false;
  b.spec_f0 = (float3)(0.0f);
  b.spec_f90 = 0.0f;
  b.cond_eta = load3(m->conductor_eta);
  b.cond_k = load3(m->conductor_k);
  b.ggx_albedo = sc->ggx_albedo;
#if CD_FEATURE_CONDUCTOR
  if (m->type == MATERIAL_CONDUCTOR) {
    bsdf_roughness_params(sc, m, s, &b);
    bsdf_conductor_params(&b);
  }
#endif
#if CD_FEATURE_GLTF_BSDF
  if (m->type == MATERIAL_GLTF) {
    bsdf_gltf_params(sc, m, s, &b);
    // No specular layer, metal, glass or coat where the textures put none: exactly
    // Lambertian here, so take the short path
    if (b.metallic == 0.0f && b.spec_f90 == 0.0f && b.transmission == 0.0f && b.coat == 0.0f)
      b.type = MATERIAL_DIFFUSE;
  }
#endif
  return b;
}

// The kinds of lobe this BSDF has (BSDF_* flags); light sampling and the integrator ask
uint bsdf_flags(const Bsdf* b) {
  switch (b->type) {
#if CD_FEATURE_GLTF_BSDF
    case MATERIAL_GLTF:
      return bsdf_gltf_flags(b);
#endif
#if CD_FEATURE_CONDUCTOR
    case MATERIAL_CONDUCTOR:
      return BSDF_REFLECTION | (ggx_is_delta(b->ggx) ? BSDF_DELTA : BSDF_GLOSSY);
#endif
    case MATERIAL_DIFFUSE:
    default:
      return BSDF_REFLECTION | BSDF_DIFFUSE;
  }
}

// Alpha (sqrt(ax ay)) of the widest microfacet lobe a non-diffuse BSDF has: how sharp its
// sharpest-but-not-delta reflection is, for the auto strategy (integrator_path.cl)
float bsdf_widest_alpha(const Bsdf* b) {
  float a = sqrt(b->ggx.ax * b->ggx.ay);
  if (b->type == MATERIAL_GLTF && b->coat > 0.0f) a = fmax(a, sqrt(b->coat_ggx.ax * b->coat_ggx.ay));
  return a;
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
  switch (b->type) {
#if CD_FEATURE_GLTF_BSDF
    case MATERIAL_GLTF:
      return bsdf_gltf_eval(b, wo_l, wi_l, pdf);
#endif
#if CD_FEATURE_CONDUCTOR
    case MATERIAL_CONDUCTOR:
      return bsdf_conductor_eval(b, wo_l, wi_l, pdf);
#endif
    case MATERIAL_DIFFUSE:
    default:
      *pdf = bsdf_diffuse_pdf(wo_l, wi_l);
      return bsdf_diffuse_eval(b->base_color, wo_l, wi_l);
  }
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

// Samples bs->wi (world space) from uc (lobe choice) and u; false when the path ends here
bool bsdf_sample(const Bsdf* b, float3 wo, float uc, float2 u, BsdfSample* bs) {
  float3 wo_l = frame_to_local(&b->frame, wo);
  bool ok;
  switch (b->type) {
#if CD_FEATURE_GLTF_BSDF
    case MATERIAL_GLTF:
      ok = bsdf_gltf_sample(b, wo_l, uc, u, bs);
      break;
#endif
#if CD_FEATURE_CONDUCTOR
    case MATERIAL_CONDUCTOR:
      ok = bsdf_conductor_sample(b, wo_l, uc, u, bs);
      break;
#endif
    case MATERIAL_DIFFUSE:
    default:
      ok = bsdf_diffuse_sample(b->base_color, wo_l, u, bs);
  }
  if (!ok) return false;
  bool local_reflection = bs->wi.z > 0.0f;
  bs->wi = frame_from_local(&b->frame, bs->wi);
  // A direction whose geometric side disagrees with its lobe carries nothing
  if (bsdf_is_reflection(b, bs->wi) != ((bs->flags & BSDF_REFLECTION) != 0u)) return false;
  if (local_reflection != ((bs->flags & BSDF_REFLECTION) != 0u)) return false;
  return bs->pdf > 0.0f && max_component(bs->f) > 0.0f;
}
