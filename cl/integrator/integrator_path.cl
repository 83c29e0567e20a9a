// Megakernel path tracer: one work-item per pixel (eight with CD_PACKETS) traces `sample_count`
// whole paths per pixel, each
// from a point drawn with the pixel filter's density (filter.cl), and folds them into the
// film with Welford's running mean and squared deviations.
// Strategies (no MIS, each light path counted exactly once):
//   STRATEGY_NEE:  emission counted on camera rays and after delta lobes; all other light
//                  arrives through shadow rays to sampled lights (skipped at delta lobes)
//   STRATEGY_BSDF: no shadow rays; emission counted whenever a sampled ray finds it (so
//                  punctual lights, which no ray can hit, contribute nothing)
//   STRATEGY_AUTO: per vertex and per light, decided before the light sample from the
//                  BSDF's lobes at wo (bsdf_sample_lobes) and the light's extent seen
//                  from the vertex (lights_extent): path_nee_takes. A light sample counts
//                  only for a light the vertex takes by light sampling; a BSDF-sampled ray
//                  that finds an emitter or the environment counts it only for a light the
//                  vertex it left did not take (the path state keeps that vertex's
//                  light-sampling context and lobes).
//                  Delta lights, which no sampled ray can find, are light-sampled at every
//                  vertex under nee and auto.
// Emission found by a delta lobe's ray always counts (no light sample can find it there).
// Participating media (CD_FEATURE_MEDIA, cl/media/media.cl): a medium step after each closest
// hit adds the medium's emission along the segment (under both strategies: media are not
// lights) and may scatter the path there, a vertex like a surface one with the phase
// function as its BSDF; null boundaries are passed without a bounce; shadow rays carry the
// transmittance of the media they cross.

// CPU devices (set by the host): camera rays in packets (render_paths), and the auto
// strategy's choice kept in the path state (PathState.choice; on GPUs it costs registers)
#ifndef CD_PACKETS
#define CD_PACKETS 0
#endif

// STRATEGY_AUTO's cost of a shadow ray, as a factor on light sampling's second moment
// (docs/integrator.md, "The choice")
#ifndef AUTO_SHADOW_COST
#define AUTO_SHADOW_COST 1.0f
#endif

// STRATEGY_AUTO: a factor on a cosine lobe's part of light sampling's second moment under
// the Sobol sampler, whose stratification helps light sampling there more than BSDF
// sampling (the one's integrand, f cos / light pdf, is smooth over the sample square; the
// other's is the light's radiance, edges and all); measured (docs/integrator.md, "The
// choice"). 1 under the independent sampler, where the second moments are the variances.
#ifndef AUTO_COSINE_SOBOL
#if CD_SAMPLER_SOBOL
#define AUTO_COSINE_SOBOL 0.5f
#else
#define AUTO_COSINE_SOBOL 1.0f
#endif
#endif

// STRATEGY_AUTO's choice (path_nee_takes) for one light at one vertex: light -1, none made
typedef struct {
  int light;
  bool takes;
} AutoChoice;

// Everything a path carries from one vertex to the next (pbrt-v4's PathIntegrator state)
typedef struct {
  Ray ray;
  float3 beta;              // throughput
  float3 radiance;          // light gathered so far
  uint depth;               // scattering events so far
  bool specular_bounce;     // emission the ray finds counts: the camera ray, a delta lobe's
                            // ray, or one from a vertex that took no light sample
  bool decide;              // STRATEGY_AUTO: emission counts for lights the vertex it left
  LightSampleContext prev;  // (seen from `prev`, with lobes `lobes`) did not take by light
  BsdfLobes lobes;          // sampling
  float eta_scale;          // product of eta^2 over transmissions, so roulette sees radiance scale
  int medium;               // medium the ray travels in (media.cl); NO_MEDIUM without CD_FEATURE_MEDIA
  MediumStack media;        // interiors entered, innermost = medium (read only with CD_FEATURE_MEDIA)
#if CD_PACKETS
  AutoChoice choice;  // STRATEGY_AUTO: the light sample's choice at `prev`, reused by a ray finding that light
#endif
#if CD_FEATURE_DISPERSION
  int channel;  // the one RGB channel it carries since its first dispersive surface (dispersion.cl); -1: all
#endif
} PathState;

PathState path_start(const SceneData* sc, Ray ray) {
  PathState ps;
  ps.ray = ray;
  ps.beta = (float3)(1.0f);
  ps.radiance = (float3)(0.0f);
  ps.depth = 0u;
  ps.specular_bounce = true;  // the camera sees emitters directly
  ps.decide = false;
  ps.eta_scale = 1.0f;
  ps.medium = NO_MEDIUM;
#if CD_FEATURE_DISPERSION
  ps.channel = -1;
#endif
#if CD_FEATURE_MEDIA
  ps.media = media_at_origin(sc, ray);
  ps.medium = media_current(&ps.media);
#endif
  return ps;
}

// Fraction of a light sample's radiance that reaches ctx.p: 0 or 1 (blocked or not), and with
// CD_FEATURE_MEDIA the transmittance of the media on the way (starting in `media`). The
// shadow ray leaves from the side of the surface that wi leaves from.
float3 path_shadow_ray(const SceneData* sc, const LightSampleContext* ctx, const LightSample* ls,
                       const MediumStack* media, Rng* rng) {
  Ray shadow;
  shadow.org = offset_ray_origin(ctx->p, ctx->n * (dot(ls->wi, ctx->n) >= 0.0f ? 1.0f : -1.0f));
  float tmax = INFINITY;
  shadow.dir = ls->wi;
  if (!ls->at_infinity) {
    float3 d = ls->target - shadow.org;
    tmax = length(d);
    if (!(tmax > 0.0f)) return (float3)(0.0f);
    shadow.dir = d / tmax;
  }
#if CD_FEATURE_MEDIA
  return media_shadow_transmittance(sc, shadow, tmax, *media, rng);
#else
  return scene_occluded(sc, shadow, tmax) ? (float3)(0.0f) : (float3)(1.0f);
#endif
}

// The pdf lobe c of solid angle W puts at angle d from its centre (normalized on the
// plane of small angles): a cosine lobe's cos d / pi for W >= pi, else the GGX-shaped
// (1 / W) / (1 + pi d^2 / W)^2 (D of the half vector at small angles, whose tail falls as
// d^-4: a light beside a sharp lobe still gets much of its reflection)
float path_lobe_pdf(float omega, float d) {
  if (omega >= PI_F) return fmax(cospi(d * INV_PI_F), 0.0f) * INV_PI_F;  // cospi: no general reduction
  float x = 1.0f + PI_F * d * d / omega;
  return 1.0f / (omega * x * x);
}

// The integral of path_lobe_pdf(omega, d)^2 over the sphere: 2 / (3 pi) for the cosine
// lobe, 1 / (3 omega) for the GGX-shaped one
float path_lobe_pdf_squared(float omega) { return omega >= PI_F ? 2.0f / (3.0f * PI_F) : 1.0f / (3.0f * omega); }

// STRATEGY_AUTO's choice for light `index` at a vertex at p with lobes `lobes`: true when
// light sampling takes it. The second moments of the two estimators of the light's
// contribution, for a BSDF whose f cos is proportional to its sampling pdf sum_c w_c p_c
// and a light of solid angle W_L and radiance L picked with probability pmf
// (docs/integrator.md, "The choice"):
//   M_nee = W_L / pmf * integral over the light of (sum_c w_c p_c)^2 L^2,
//   M_bsdf = integral over the light of sum_c w_c p_c L^2.
// Per lobe, p_c over the light is bounded by its value q_c at the
// point of the light's bounding cone nearest to the lobe's centre, and its mass there is
// P_c = min(1, W_L q_c); the integral of p_c^2 over the light is at most q_c P_c and at
// most S_c, that over the whole sphere (path_lobe_pdf_squared), so for an emitter of
// constant L
//   M_nee ~ W_L / pmf * sum_ab w_a w_b r_ab sqrt(J_a J_b),   M_bsdf ~ sum_c w_c P_c,
// J_c = min(q_c P_c, S_c), with the cross terms of overlapping lobes: r_ab, their
// correlation over the sphere, is 1 for a = b, else min(1, X_ab / sqrt(S_a S_b)), X_ab
// (the integral of p_a p_b) about the wider lobe's pdf at the narrower one's centre.
// Under the Sobol sampler a cosine lobe's J_c is scaled by AUTO_COSINE_SOBOL.
// An environment is sampled in proportion to L (its integral E over the sphere, so the
// samples below a surface are in E already): its bright part, a cone of its effective
// solid angle W_E = E^2 / integral L^2 and radiance E / W_E, enters as a light does, and
// a lobe whose centre lies outside that cone sees the radiance L_c there over its whole
// extent: J_c += L_c S_c and M_bsdf += w_c L_c^2. Light sampling
// takes the light when AUTO_SHADOW_COST * M_nee <= M_bsdf. Evaluated twice per light
// path on GPUs, at the light sample and where the sampled ray finds the light, on the same
// inputs: no contraction, so both give the same answer (CPU devices keep the first,
// path_prev_takes). `pmf`: the light's selection probability
// at ctx. `own_terms_first`: settle first what the lobes' own terms settle (the same
// answer; false only in the test that checks so).
bool path_nee_takes_by_moments(const SceneData* sc, const BsdfLobes* lobes, const LightSampleContext* ctx, uint index,
                               float pmf, bool own_terms_first) {
#pragma OPENCL FP_CONTRACT OFF
  LightExtent e = lights_extent(sc, index, ctx->p);
  if (!(e.omega > 0.0f)) return true;  // a delta light
  e.pmf = pmf;
  float l_bright = e.everywhere ? e.integral / e.omega : 1.0f;
  float m_bsdf = 0.0f, j[BSDF_MAX_LOBES];
  for (uint k = 0u; k < lobes->count; ++k) {
    float w = lobes->weight[k], omega = lobes->omega[k];
    float d = e.radius >= PI_F ? 0.0f : fmax(acos_fast(dot(e.dir, lobes->dir[k])) - e.radius, 0.0f);
    float q = path_lobe_pdf(omega, d);
    float mass = fmin(e.omega * q, 1.0f);
    float whole = path_lobe_pdf_squared(omega);
    j[k] = fmin(q * mass, whole) * l_bright;
    m_bsdf += w * mass * l_bright * l_bright;
    if (e.everywhere && d > 0.0f) {
      float l = luminance(lights_environment_radiance(sc, lobes->dir[k]));
      j[k] += l * whole;
      m_bsdf += w * l * l;
    }
    if (omega >= PI_F) j[k] *= AUTO_COSINE_SOBOL;
  }
  float scale = e.everywhere ? e.integral / e.pmf : e.omega / e.pmf;
  // The cross terms are >= 0, and adding a term >= 0 never lowers a rounded sum: when the
  // lobes' own terms alone, summed in the same order, price light sampling above M_bsdf,
  // so does the whole sum (the same answer without the pairs' angles)
  if (own_terms_first) {
    float m_own = 0.0f;
    for (uint a = 0u; a < lobes->count; ++a) m_own += lobes->weight[a] * lobes->weight[a] * j[a];
    if (!(AUTO_SHADOW_COST * scale * m_own <= m_bsdf)) return false;
  }
  float m_nee = 0.0f;
  for (uint a = 0u; a < lobes->count; ++a) {
    float wa = lobes->weight[a];
    m_nee += wa * wa * j[a];
    for (uint b = a + 1u; b < lobes->count; ++b) {
      float wide = fmax(lobes->omega[a], lobes->omega[b]);
      float x = path_lobe_pdf(wide, acos_fast(dot(lobes->dir[a], lobes->dir[b])));
      float sab = sqrt(path_lobe_pdf_squared(lobes->omega[a]) * path_lobe_pdf_squared(lobes->omega[b]));
      m_nee += 2.0f * wa * lobes->weight[b] * fmin(x / sab, 1.0f) * sqrt(j[a] * j[b]);
    }
  }
  return AUTO_SHADOW_COST * scale * m_nee <= m_bsdf;
}

// A test that settles most of the choices without the light's extent. For a light that is
// not `everywhere`, J_c <= k_c q_c P_c (k_c: AUTO_COSINE_SOBOL for a cosine lobe, else 1)
// and r_ab <= 1 give M_nee <= W_L / pmf (sum_c w_c sqrt(k_c q_c P_c))^2, at most
// W_L / pmf (sum_c w_c k_c q_c) (sum_c w_c P_c) = W_L / pmf (sum_c w_c k_c q_c) M_bsdf by
// Cauchy-Schwarz. q_c is at most the lobe's peak density (1 / pi for a cosine lobe, 1 / W_c
// for the GGX-shaped one) and W_L at most `omega_bound` (lights_omega_bound; negative:
// none), so light sampling takes the light when
// AUTO_SHADOW_COST omega_bound sum_c w_c k_c peak_c <= pmf. W_L is taken at 1e-6 sr at
// least, over the rounding of a far, tiny triangle's solid angle, with 1 % to spare.
bool path_nee_surely_takes(const BsdfLobes* lobes, float omega_bound, float pmf) {
#pragma OPENCL FP_CONTRACT OFF
  if (!(omega_bound >= 0.0f)) return false;
  float sum = 0.0f;
  for (uint k = 0u; k < lobes->count; ++k) {
    float omega = lobes->omega[k];
    sum += lobes->weight[k] * (omega >= PI_F ? AUTO_COSINE_SOBOL * INV_PI_F : 1.0f / omega);
  }
  return AUTO_SHADOW_COST * fmax(omega_bound, 1e-6f) * sum <= 0.99f * pmf;
}

// STRATEGY_AUTO's choice: path_nee_takes_by_moments, most often settled by
// path_nee_surely_takes first (the same answer, for a fraction of the work). `pmf`: the
// light's selection probability at ctx when the caller has it (the light sample's:
// lights_select_pmf's value exactly), else negative (lights_select_pmf computes it).
bool path_nee_takes(const SceneData* sc, const BsdfLobes* lobes, const LightSampleContext* ctx, uint index, float pmf) {
  if (pmf < 0.0f) pmf = lights_select_pmf(sc, ctx, index);
  return path_nee_surely_takes(lobes, lights_omega_bound(sc, index, ctx->p), pmf) ||
         path_nee_takes_by_moments(sc, lobes, ctx, index, pmf, true);
}

// Next-event estimate of light arriving at ctx and scattered by bsdf toward wo; with
// `lobes` (STRATEGY_AUTO), only of a light the vertex takes by light sampling (the others
// count when a sampled ray finds them: a sample of one contributes nothing here).
// `media`: the media on wo's side; a shadow ray through the surface enters (or leaves)
// `interior`, the medium inside the surface. x_select, u_select (lights_select_numbers) and
// u (rng_next_2d): its random numbers, which the caller draws. `choice`: with CD_PACKETS and
// `lobes`, set to the light selected and path_nee_takes' answer for it.
float3 path_direct_light(const SceneData* sc, const LightSampleContext* ctx, const Bsdf* bsdf, float3 wo,
                         const BsdfLobes* lobes, const MediumStack* media, int interior, uint x_select, float u_select,
                         float2 u, Rng* rng, AutoChoice* choice) {
  uint light;
  float pmf;
  if (!lights_select(sc, ctx, x_select, u_select, &light, &pmf)) return (float3)(0.0f);
  // The choice depends on the light and the vertex, not on the direction: a light left to
  // BSDF sampling costs no direction sample (a delta light is always taken)
  if (lobes) {
    bool takes = path_nee_takes(sc, lobes, ctx, light, pmf);
#if CD_PACKETS
    choice->light = (int)light;
    choice->takes = takes;
#endif
    if (!takes) return (float3)(0.0f);
  }
  LightSample ls;
  if (!lights_sample_selected(sc, ctx, light, pmf, u, &ls)) return (float3)(0.0f);
  float3 f = bsdf_eval(bsdf, wo, ls.wi);
  float cos_i = fabs(dot(ls.wi, ctx->ns));
  float3 contrib = f * ls.radiance * (cos_i / ls.pdf);
  if (max_component(contrib) <= 0.0f) return (float3)(0.0f);
#if CD_FEATURE_MEDIA
  MediumStack st = *media;
  if (dot(ls.wi, ctx->n) < 0.0f) media_cross(&st, interior, bsdf->entering);
  return contrib * path_shadow_ray(sc, ctx, &ls, &st, rng);
#else
  return contrib * path_shadow_ray(sc, ctx, &ls, media, rng);
#endif
}

// Russian roulette on throughput x eta_scale (pbrt-v4's rule): a path whose throughput
// is below 1 survives with that probability; one at or above 1 always survives, so paths
// that carry all their energy (white walls, glass) are not cut short. False: path ends.
bool path_survives_roulette(PathState* ps, uint rr_depth, Rng* rng) {
  if (ps->depth + 1u < rr_depth) return true;
  float q = max_component(ps->beta) * ps->eta_scale;
  if (q >= 1.0f) return true;
  if (rng_next(rng) >= q) return false;
  ps->beta /= q;
  return true;
}

#if CD_FEATURE_MEDIA
// Next-event estimate at a point p in a medium of phase asymmetry g, toward wo
float3 path_medium_direct_light(const SceneData* sc, float3 p, float g, float3 wo, const MediumStack* media, Rng* rng) {
  LightSampleContext ctx;
  ctx.p = p;
  ctx.n = ctx.ns = (float3)(0.0f);  // a point in a medium: light from the whole sphere
  ctx.transmits = true;
  uint x_select;
  float u_select;
  lights_select_numbers(sc, rng, &x_select, &u_select);
  float2 u = rng_next_2d(rng);
  LightSample ls;
  if (!lights_sample(sc, &ctx, x_select, u_select, u, &ls)) return (float3)(0.0f);
  float3 contrib = ls.radiance * (phase_eval(g, wo, ls.wi) / ls.pdf);
  if (max_component(contrib) <= 0.0f) return (float3)(0.0f);
  return contrib * path_shadow_ray(sc, &ctx, &ls, media, rng);
}

// The medium step of a path segment that ends at a surface at tmax (INFINITY: it escapes):
// the medium's emission along it, then the free flight (cl/media/media.cl). MEDIUM_PASSED: the
// path goes on to the surface. MEDIUM_SCATTERED: it scattered in the medium, and this did
// that vertex's work (light sampling with the phase function unless `nee` is false, a new
// direction sampled from it, Russian roulette). MEDIUM_ABSORBED: the path ends.
int path_medium_step(const SceneData* sc, PathState* ps, float tmax, bool nee, Rng* rng) {
  float3 p;
  int event = media_sample_segment(sc, ps->medium, ps->ray, tmax, rng, &ps->beta, &ps->radiance, &p);
  if (event != MEDIUM_SCATTERED) return event;
  if (ps->depth >= sc->params->max_depth) return MEDIUM_ABSORBED;
  float g = sc->media[ps->medium].g;
  float3 wo = -ps->ray.dir;
  if (nee) ps->radiance += ps->beta * path_medium_direct_light(sc, p, g, wo, &ps->media, rng);
  float2 u = rng_next_2d(rng);
  float pdf;
  float3 wi = phase_sample(g, wo, u, &pdf);  // exact sampling: the weight f / pdf is 1
  ps->specular_bounce = !nee;                // emission found next counts unless light sampling took it
  ps->decide = false;
  if (!path_survives_roulette(ps, sc->params->rr_depth, rng)) return MEDIUM_ABSORBED;
  ps->ray.org = p;
  ps->ray.dir = wi;
  return MEDIUM_SCATTERED;
}

// The ray crosses the boundary of `material` at s (by transmission or a null boundary)
void path_cross_boundary(const SceneData* sc, PathState* ps, const SurfaceHit* s) {
  media_cross(&ps->media, sc->materials[s->material].medium, s->front);
  ps->medium = media_current(&ps->media);
}
#endif

// Did the vertex the path left (ps->prev, ps->lobes) take light `index` by light sampling?
// With CD_PACKETS the light sample's answer when it chose for the same light: the same
// inputs (lights_select's pmf is lights_select_pmf's value exactly), so the same answer
bool path_prev_takes(const SceneData* sc, const PathState* ps, uint index) {
#if CD_PACKETS
  if (ps->choice.light == (int)index) return ps->choice.takes;
#endif
  return path_nee_takes(sc, &ps->lobes, &ps->prev, index, -1.0f);
}

// With CD_AOV, path_trace also fills the sample's AOVs (aov.cl)
#if CD_AOV
#define AOV_PARAM , PathAov* aov
#define AOV_ARG(a) , a
#else
#define AOV_PARAM
#define AOV_ARG(a)
#endif

// Radiance along one camera ray; `first`: the camera ray's closest hit when it is known
// already (traced in a packet), else 0
float3 path_trace(const SceneData* sc, Ray camera_ray, const Hit* first, Rng* rng AOV_PARAM) {
  __global const RenderParams* params = sc->params;
  const uint strategy = params->strategy;
  PathState ps = path_start(sc, camera_ray);
  for (;; ++ps.depth) {
    Hit hit;
    if (first) {
      hit = *first;
      first = 0;
    } else {
      hit = scene_intersect(sc, ps.ray, INFINITY);
    }
#if CD_FEATURE_MEDIA
    // Medium step: emission and free flight up to the surface; scattering in the medium
    // (the phase function is never near-specular: auto light-samples there, like nee)
    int event = path_medium_step(sc, &ps, hit.prim < 0 ? INFINITY : hit.t, strategy != STRATEGY_BSDF, rng);
#if CD_AOV
    if (event != MEDIUM_PASSED) aov->see_through = false;
#endif
    if (event == MEDIUM_ABSORBED) break;
    if (event == MEDIUM_SCATTERED) continue;
#endif
    bool counts_emission = ps.specular_bounce;
    if (hit.prim < 0) {
      if (counts_emission || ps.decide) {
        float3 le = lights_environment_radiance(sc, ps.ray.dir);
        if (!counts_emission && max_component(le) > 0.0f)
          counts_emission = !path_prev_takes(sc, &ps, (uint)params->environment_light);
#if CD_AOV
        aov_escape(aov, ps.beta, le);
#if CD_TRANSPARENT
        if (aov->see_through) counts_emission = false;
#endif
#endif
        if (counts_emission) ps.radiance += ps.beta * le;
      }
      break;
    }
    SurfaceHit s = surface_at(sc, (uint)hit.prim, hit.b1, hit.b2, ps.ray.dir);
#if CD_FEATURE_MEDIA
    // A null boundary only changes the medium: the ray goes straight on, and no bounce counts
    if (media_is_null_boundary(sc, s.material)) {
#if CD_AOV
      if (ps.depth == 0u) aov->travelled += hit.t;
#endif
      path_cross_boundary(sc, &ps, &s);
      ps.ray.org = offset_ray_origin(s.p, -s.ng);
      --ps.depth;  // the loop's ++ undoes it
      continue;
    }
#endif
#if CD_AOV
    if (ps.depth == 0u) aov->depth = aov->travelled + hit.t;
#endif
#if CD_FEATURE_UNLIT
    // An unlit surface shows its colour to every ray and ends the path (no light sampling finds it)
    if (sc->materials[s.material].flags & MATERIAL_UNLIT) {
      ps.radiance += ps.beta * bsdf_unlit_radiance(sc, &s);
#if CD_AOV
      aov_unlit(aov, bsdf_unlit_radiance(sc, &s), s.ns);
#endif
      break;
    }
#endif
    if (counts_emission || ps.decide) {
      float3 le = surface_emission(sc, &sc->materials[s.material], s.front, s.uvs);
      if (!counts_emission && max_component(le) > 0.0f) {
        int light = lights_of_prim(sc, (uint)hit.prim);
        counts_emission = light == NO_LIGHT || !path_prev_takes(sc, &ps, (uint)light);
      }
      if (counts_emission) ps.radiance += ps.beta * le;
    }
    if (ps.depth >= params->max_depth) break;

    float3 wo = -ps.ray.dir;
#if CD_FEATURE_DISPERSION
    // The first dispersive surface picks the channel the path carries from here: uniformly,
    // its throughput x 3 x the channel's one-hot
    if (ps.channel < 0 && dispersion_material(&sc->materials[s.material])) {
      ps.channel = min((int)(rng_next(rng) * 3.0f), 2);
      ps.beta *= (float3)(ps.channel == 0 ? 3.0f : 0.0f, ps.channel == 1 ? 3.0f : 0.0f, ps.channel == 2 ? 3.0f : 0.0f);
    }
    Bsdf bsdf = bsdf_at_channel(sc, &s, ps.channel);
#else
    Bsdf bsdf = bsdf_at(sc, &s);
#endif
    bsdf_face_wo(&bsdf, wo);  // no black fringes where shading normals tilt away from wo
    uint flags = bsdf_flags(&bsdf);
    // Light sampling, except at lobes that are all delta (no light sample can find them);
    // under auto, of the lights the vertex takes by light sampling (path_nee_takes)
    bool samples_lights = strategy != STRATEGY_BSDF && (flags & (BSDF_DIFFUSE | BSDF_GLOSSY)) != 0u;
    bool chooses = samples_lights && strategy == STRATEGY_AUTO;
    LightSampleContext ctx = light_context_at_surface(&s, &bsdf);
    // The random numbers of the light sample, then of the BSDF sample that continues the
    // path. The BSDF is sampled first, with its lobes when the vertex chooses (a type
    // computes what both need at wo once: for the glTF mixture, most of the vertex's BSDF
    // work), then the light.
    uint x_select = 0u;
    float u_select = 0.0f;
    float2 u_light = (float2)(0.0f);
    if (samples_lights) {
      lights_select_numbers(sc, rng, &x_select, &u_select);
      u_light = rng_next_2d(rng);
    }
    float uc = rng_next(rng);
    float2 u = rng_next_2d(rng);
    BsdfSample bs;
    BsdfLobes lobes;
    bool sampled = bsdf_sample_lobes(&bsdf, wo, uc, u, &bs, chooses ? &lobes : 0);
    AutoChoice choice;
    choice.light = -1;
    choice.takes = false;
    if (samples_lights) {
      ps.radiance +=
          ps.beta * path_direct_light(sc, &ctx, &bsdf, wo, chooses ? &lobes : 0, &ps.media,
                                      sc->materials[s.material].medium, x_select, u_select, u_light, rng, &choice);
    }
#if CD_AOV
    aov_vertex(aov, &bs, sampled, bsdf.frame.n);
#endif
    if (!sampled) break;

    // Continue the path along the sampled direction
    ps.beta *= bs.f * (fabs(dot(bs.wi, bsdf.frame.n)) / bs.pdf);  // the mapped shading normal
    bool delta = (bs.flags & BSDF_DELTA) != 0u;
    ps.specular_bounce = delta || !samples_lights;
    ps.decide = chooses && !delta;
    if (ps.decide) {
      ps.prev = ctx;  // the light selection the light sample saw here
      ps.lobes = lobes;
#if CD_PACKETS
      ps.choice = choice;
#endif
    }
    if (bs.flags & BSDF_TRANSMISSION) ps.eta_scale *= bs.eta * bs.eta;
    if (!path_survives_roulette(&ps, params->rr_depth, rng)) break;
    ps.ray.org = offset_ray_origin(s.p, s.ng * (dot(bs.wi, s.ng) > 0.0f ? 1.0f : -1.0f));
    ps.ray.dir = bs.wi;
#if CD_FEATURE_MEDIA
    if (bs.flags & BSDF_TRANSMISSION) path_cross_boundary(sc, &ps, &s);
#endif
  }
  return ps.radiance;
}
