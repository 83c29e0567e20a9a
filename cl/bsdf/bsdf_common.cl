// What every BSDF lobe (bsdf_*.cl) shares with the dispatch in bsdf.cl: the sample record,
// the BSDF record of a shading point and the material lookups of the lobes' params.

// BsdfSample flags (pbrt-v4's BxDFFlags): what kind of lobe produced the sample
#define BSDF_REFLECTION 1u
#define BSDF_TRANSMISSION 2u
#define BSDF_DIFFUSE 4u
#define BSDF_GLOSSY 8u
#define BSDF_DELTA 16u  // a Dirac lobe: only BSDF sampling can find it

typedef struct {
  float3 wi;   // sampled direction (world space out of bsdf_sample)
  float3 f;    // BSDF value for (wo, wi); for a delta lobe the weight of its Dirac
  float pdf;   // solid-angle pdf of wi (for a delta lobe, the discrete probability)
  uint flags;  // BSDF_*
  float eta;   // relative index of refraction across a transmission, else 1
} BsdfSample;

// Parameters of a MATERIAL_GLTF BSDF at a shading point (bsdf_gltf.cl): the per-hit values of
// GLTF_PARAMS (cl/shared/gltf_params.h; each compiled in with its feature, loaded by
// bsdf_gltf_params), then what the base and the components derive from the parameters
#define GLTF_VALUE_x(name) float name;
#define GLTF_VALUE_y(name) float name;
#define GLTF_VALUE_z(name) float name;
#define GLTF_VALUE_w(name) float name;
#define GLTF_VALUE_factor(name) float name;
#define GLTF_VALUE_xyz(name) float3 name;
#define GLTF_VALUE__(name)
#define GLTF_VALUE(_, name, n, def, lo, hi, ext, key, slot, load, feature, role) CD_IF(feature)(GLTF_VALUE_##load(name))
typedef struct {
  GLTF_PARAMS(GLTF_VALUE)
  Ggx ggx;         // specular roughness, ax along frame.t
  float eta;       // relative index across the surface seen from wo: eta_t / eta_i
  float3 spec_f0;  // dielectric reflectance at normal incidence (KHR_materials_ior, _specular)
  float spec_f90;  // dielectric reflectance at grazing incidence (KHR_materials_specular)
  bool thin;       // a thin-walled sheet: transmission does not bend
  Ggx coat_ggx;
  float3 coat_n;         // the clearcoat layer's normal (world; clearcoatNormalTexture, else the unmapped normal)
  bool coat_own_normal;  // coat_n may differ from frame.n (either layer is normal-mapped)
#if CD_FEATURE_SHEEN
  __global const float* sheen_albedo;  // the sheen's albedo table (sheen.cl); 0: no albedo scaling
#endif
#if CD_FEATURE_IRIDESCENCE
  float iridescence_thickness;  // the film's thickness (nm)
#endif
} GltfBsdf;

// Parameters of a MATERIAL_CONDUCTOR BSDF at a shading point (bsdf_conductor.cl)
typedef struct {
  Ggx ggx;  // ax along frame.t
  float3 eta, k;
  float3 f_avg;  // hemispherical average of its Fresnel term
} ConductorBsdf;

// The members of Bsdf's lobe union, X(type, member): a type's parameters at a shading point
#define BSDF_LOBE_TYPES(X) X(GltfBsdf, gltf) X(ConductorBsdf, conductor)
#define BSDF_LOBE_MEMBER(type, member) type member;

// The lobe union's first member spans all of it as float4 words. A compiler may copy a union
// as the one member it lays the union out by, and skip that member's padding: NVIDIA's
// OpenCL compiler (driver 580) copied a Bsdf as GltfBsdf, whose `bool thin` (one byte, then
// three of padding) lies over a conductor's k.z, and so rendered every measured conductor
// without its blue channel's absorption. Words have no padding, and clang lays a union out by
// its first member of the largest size and alignment. Their count comes from the largest
// member: the size of a union of the members alone, which is only measured (sizeof), never
// an object, so never copied. The device layout test checks it against each member.
typedef union {
  BSDF_LOBE_TYPES(BSDF_LOBE_MEMBER)
} BsdfLobeMembers;
#define BSDF_LOBE_BYTES sizeof(BsdfLobeMembers)
#define BSDF_LOBE_WORDS ((BSDF_LOBE_BYTES + 15) / 16)

// The BSDF of one shading point: what every type has (frame, normals, colour), then the
// parameters of its type's lobe, evaluated there
typedef struct {
  Frame frame;                       // shading frame; frame.n is the (mapped) shading normal on wo's side
  float3 ng;                         // geometric normal on wo's side
  bool entering;                     // wo is on the front face: refraction goes from outside (1) to inside (ior)
  uint type;                         // MATERIAL_*
  float3 base_color;                 // diffuse albedo, metal F0, transmission tint
  __global const float* ggx_albedo;  // GGX albedo table (energy.cl); 0: no energy compensation
#if CD_FEATURE_DISPERSION
  int channel;  // the RGB channel whose wavelength a dispersive material refracts (dispersion.cl); -1: none
#endif
  union {
    float4 words[BSDF_LOBE_WORDS];  // see above: the union as a whole, without padding
    BSDF_LOBE_TYPES(BSDF_LOBE_MEMBER)
  } lobe;  // by type
} Bsdf;

// The lobes of a BSDF at wo, for the strategy choice (bsdf_sample_lobes in bsdf.cl; the
// integrator's STRATEGY_AUTO): each non-delta lobe's centre direction, its solid angle
// (1 / its peak pdf: pi for a cosine lobe, 4 pi ax ay for a GGX reflection) and its
// selection weight at wo. Each material type declares its lobes in bsdf_NAME_lobes (in the
// local frame); lobes of the same centre and solid angle merge, and past BSDF_MAX_LOBES a
// lobe joins the one nearest in solid angle.
#define BSDF_MAX_LOBES 4
typedef struct {
  float3 dir[BSDF_MAX_LOBES];    // centre (local while the type fills it, then world)
  float omega[BSDF_MAX_LOBES];   // solid angle, > 0
  float weight[BSDF_MAX_LOBES];  // selection probability at wo
  uint count;
} BsdfLobes;

void bsdf_lobes_add(BsdfLobes* l, float3 dir, float omega, float weight) {
  if (!(weight > 0.0f) || !(omega > 0.0f)) return;  // absent, or a delta lobe
  for (uint k = 0u; k < l->count; ++k) {
    if (l->omega[k] == omega && all(l->dir[k] == dir)) {
      l->weight[k] += weight;
      return;
    }
  }
  if (l->count == BSDF_MAX_LOBES) {  // the logarithms only here: the common case has room
    uint nearest = 0u;
    for (uint k = 1u; k < l->count; ++k)
      if (fabs(log(l->omega[k] / omega)) < fabs(log(l->omega[nearest] / omega))) nearest = k;
    l->weight[nearest] += weight;
    return;
  }
  l->dir[l->count] = dir;
  l->omega[l->count] = omega;
  l->weight[l->count] = weight;
  ++l->count;
}

// Solid angles of the lobe shapes: a cosine lobe (1 / its peak pdf 1 / pi), a GGX
// reflection (peak D / 4 = 1 / (4 pi ax ay) at normal incidence), a GGX refraction from wo
// across relative index eta (a facet tilt d turns the refracted ray by d (1 - 1/eta): the
// half-vector solid angle pi ax ay times (1 - 1/eta)^2); each at most 2 pi
float bsdf_lobe_omega_cosine(void) { return PI_F; }
float bsdf_lobe_omega_ggx(Ggx g) { return fmin(4.0f * PI_F * g.ax * g.ay, 2.0f * PI_F); }
float bsdf_lobe_omega_ggx_refraction(Ggx g, float eta) {
  float s = 1.0f - 1.0f / eta;
  return fmin(fmax(PI_F * g.ax * g.ay * s * s, 1e-9f), 2.0f * PI_F);
}

// A texture slot of the material at the hit
float4 bsdf_texture(const SceneData* sc, __global const Material* m, int slot, const SurfaceHit* s) {
  return textures_lookup(sc, &m->textures[slot], s->uvs);
}

// The frame of the interpolated normal and tangent at the hit: the glTF tangent space
// (bitangent = sign * n x t; back faces mirror it)
Frame bsdf_geometry_frame(const SurfaceHit* s) {
  Frame f = frame_from_z_x(s->ns, s->tangent);
  f.b *= s->tangent_sign * (s->front ? 1.0f : -1.0f);
  return f;
}

// The normal of a normal-map slot (normalTexture, clearcoatNormalTexture) in world space:
// the texel's tangent-space normal, its xy times `scale`, in the geometry frame f. A mapped
// normal that would face away from wo's side of the geometry is bent back to just above it,
// so no light leaks through and no black fringe appears (the method is to clamp the mapped
// normal to the geometric hemisphere, as many renderers do). False without a texture in the
// slot, or where the texel gives no direction
bool bsdf_mapped_normal(const SceneData* sc, __global const Material* m, const SurfaceHit* s, const Frame* f, int slot,
                        float scale, float3* n) {
#if CD_FEATURE_TEXTURES
  if (m->textures[slot].index == NO_TEXTURE) return false;
  float3 t = bsdf_texture(sc, m, slot, s).xyz * 2.0f - 1.0f;
  t.xy *= scale;
  float3 v = frame_from_local(f, (float3)(t.x, s->front ? t.y : -t.y, t.z));
  float len = length(v);
  if (!(len > 0.0f) || !isfinite(len)) return false;
  v /= len;
  float c = dot(v, s->ng);
  if (c < 0.01f) v = normalize(v + (0.01f - c) * s->ng);
  *n = v;
  return true;
#else
  return false;
#endif
}

// GGX roughness (x metallicRoughnessTexture G) and KHR_materials_anisotropy: the strength,
// and a direction in the tangent plane, rotated, that the frame's tangent turns to
Ggx bsdf_microfacet_at(const SceneData* sc, __global const Material* m, const SurfaceHit* s, float roughness,
                       float anisotropy_strength, float anisotropy_rotation, Frame* frame) {
  float r = roughness * bsdf_texture(sc, m, TEX_METALLIC_ROUGHNESS, s).y;
  float4 an = bsdf_texture(sc, m, TEX_ANISOTROPY, s);
  float2 dir = m->textures[TEX_ANISOTROPY].index != NO_TEXTURE ? an.xy * 2.0f - 1.0f : (float2)(1.0f, 0.0f);
  float strength = anisotropy_strength * (m->textures[TEX_ANISOTROPY].index != NO_TEXTURE ? an.z : 1.0f);
  if (strength > 0.0f) {
    float cr, sr = sincos(anisotropy_rotation, &cr);
    float3 t = (cr * dir.x - sr * dir.y) * frame->t + (sr * dir.x + cr * dir.y) * frame->b;
    float hand = dot(cross(frame->n, frame->t), frame->b) < 0.0f ? -1.0f : 1.0f;
    *frame = frame_from_z_x(frame->n, t);
    frame->b *= hand;
  }
  return ggx_from_roughness(r, strength);
}
