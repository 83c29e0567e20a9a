// The clear coat (KHR_materials_clearcoat), the mixture's top layer: clearcoat * F_c *
// GGX(coat roughness), F_c = Schlick(0.04, 1), about the coat's own normal n_c
// (clearcoatNormalTexture; without it the unmapped normal, even where the base is
// normal-mapped). It attenuates reflections below by (1 - A_c(mu_o)) (1 - A_c(mu_i)) and
// transmissions by 1 - A_c at the outside direction's angle, A_c = the coat's albedo, mu the
// cosines to n_c. Where n_c is not the shading normal n, its lobe is f_c (wi.n_c) / (wi.n):
// the integrator weighs by wi.n, the coat reflects by the projected solid angle about n_c.
// It has no multiple scattering (F_avg ~ 0.09: under 1 %).

// A(mu) of the clear coat, an isotropic layer: lookups by mu alone, so that kernels with
// CD_FEATURE_ANISOTROPY do not compile the anisotropic lookup at each of the coat's
float gltf_coat_albedo(const GltfLayer* l, float mu) {
  if (!l->e.table) return gltf_layer_albedo_of(l, 1.0f, schlick_weight(mu));
  return gltf_layer_albedo_of(l, energy_lookup_mu(&l->e, 0, mu), energy_lookup_mu(&l->e, 1, mu));
}

// The clearcoat: Schlick(0.04, 1) weighted by the coat factor, never normalized
GltfLayer gltf_coat_layer(const Bsdf* b, float cos_o) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  GgxEnergy e = energy_ggx_mu(lobe->clearcoat > 0.0f ? b->ggx_albedo : 0, lobe->coat_ggx, cos_o);
  GltfLayer l = gltf_layer(e, (float3)(0.04f * lobe->clearcoat), lobe->clearcoat, (float3)(0.0f), false);
  l.a_o = gltf_coat_albedo(&l, cos_o);
  return l;
}

// The diffuse base under the coat and the specular layer gets their transmittance
// T = (1 - A_c)(1 - A_s) at both directions, normalized by T_avg = 2 integral of T mu dmu
// (as gltf_below does for one layer): a white base returns exactly T(mu_o), and the light
// trapped under the coat is not lost. Returns the factor (1 - A_s,avg) / T_avg that turns the
// specular layer's own normalization into this one; 1 without the table or the coat.
// T_avg by 8-point Gauss-Legendre quadrature on [0, 1/4] and [1/4, 1] (A is steep at grazing);
// under an anisotropic specular layer also over four azimuths (midpoints in [0, pi / 2]).
float gltf_coat_base_norm(const Bsdf* b, const GltfLayer* coat, const GltfLayer* spec) {
  if (b->lobe.gltf.clearcoat <= 0.0f || !spec->normalized || !b->ggx_albedo) return 1.0f;
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

// Clearcoat reflectance Schlick(0.04, 1) weighted by the coat factor, at the coat lobe's wo.h
float gltf_coat_fresnel(const Bsdf* b, float cos_i) {
  return b->lobe.gltf.clearcoat * (0.04f + 0.96f * schlick_weight(cos_i));
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

float gltf_coat_weight(const Bsdf* b, const GltfAtWo* g, float cos_o) { return g->coat.a_o; }

// A mirror reflection (in the coat's frame where it has its own normal: a mirror about n_c, a
// GGX sample about it)
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

// Reflected light crosses the coat twice; transmitted light once, at the angle of the
// direction outside (the diffuse transmission twice, as a reflection). Then the coat's own lobe.
void gltf_coat_eval(const Bsdf* b, const GltfAtWo* g, float3 wo, float3 wi, GltfEval* acc) {
  const GltfBsdf* lobe = &b->lobe.gltf;
  acc->f = acc->under * (wi.z > 0.0f ? gltf_coat_below(g, wi) : gltf_coat_across(b, g, wi));
  if (wi.z < 0.0f) acc->f += acc->dtrans * gltf_coat_below(g, wi);
  if (wi.z > 0.0f && lobe->clearcoat > 0.0f && !ggx_is_delta(lobe->coat_ggx)) {
    float coat_p, coat_h;
    float3 wi_c = gltf_coat_local(g, wi);
    float coat_d = ggx_reflection_eval(lobe->coat_ggx, gltf_coat_local(g, wo), wi_c, &coat_p, &coat_h);
    // About a normal of its own, the coat's projected solid angle is wi.n_c, not wi.z
    if (g->coat_tilted) coat_d *= wi_c.z / wi.z;
    acc->f += gltf_coat_fresnel(b, coat_h) * coat_d;
    acc->pdf += g->w[GLTF_COAT] * coat_p;
  }
}

// Its factor, roughness and normal: its own normal map, else the interpolated normal
bool gltf_coat_params(const SceneData* sc, __global const Material* m, const SurfaceHit* s, Bsdf* b) {
  __global const GltfMaterial* g = &m->params.gltf;
  GltfBsdf* lobe = &b->lobe.gltf;
  float coat_rough = g->clearcoat_roughness * bsdf_texture(sc, m, TEX_CLEARCOAT_ROUGHNESS, s).y;
  lobe->coat_ggx = ggx_from_roughness(coat_rough, 0.0f);
  Frame geo = bsdf_geometry_frame(s);
  lobe->coat_n = geo.n;
  lobe->coat_own_normal = false;
  if (lobe->clearcoat > 0.0f) {
    bsdf_mapped_normal(sc, m, s, &geo, TEX_CLEARCOAT_NORMAL, g->clearcoat_normal_scale, &lobe->coat_n);
    lobe->coat_own_normal =
        m->textures[TEX_CLEARCOAT_NORMAL].index != NO_TEXTURE || m->textures[TEX_NORMAL].index != NO_TEXTURE;
  }
  return lobe->clearcoat != 0.0f;
}

// Its frame, where it has a normal of its own, and its layer at wo, which leaves the rest
// 1 - A_c(mu_o) (the first factor of g->outer)
void gltf_coat_at_wo(const Bsdf* b, float3 wo, GltfAtWo* g) {
  g->coat_tilted = b->lobe.gltf.coat_own_normal;
  g->coat_o = wo.z;
  if (g->coat_tilted) {
    g->coat_frame = frame_from_z(frame_to_local(&b->frame, b->lobe.gltf.coat_n));
    g->coat_o = dot(wo, g->coat_frame.n);
  }
  g->coat = gltf_coat_layer(b, clamp(g->coat_o, 0.0f, 1.0f));
  g->outer = 1.0f - g->coat.a_o;
}

uint gltf_coat_flags(const Bsdf* b) {
  return b->lobe.gltf.clearcoat > 0.0f ? gltf_ggx_flags(b->lobe.gltf.coat_ggx) : 0u;
}
