// Megakernel path tracer: one work-item per pixel traces `sample_count` whole paths and
// folds them into the film with Welford's running mean and squared deviations.
// Strategies (no MIS, each light path counted exactly once):
//   STRATEGY_NEE:  emission seen by camera rays, all other light through shadow rays
//   STRATEGY_BSDF: no shadow rays; emission added whenever a sampled ray finds it

typedef struct {
  __global const BvhNode* nodes;
  __global const Triangle* tris;
  __global const TriangleShading* shading;
  __global const TriangleColors* colors;
  __global const Material* materials;
  TextureSet textures;
  __global const Light* lights;
  __global const uint* light_thresholds;
  __global const RenderParams* params;
} SceneData;

// Next-event estimate of light arriving at s and scattered toward wo
float3 path_direct_light(const SceneData* sc, const SurfaceHit* s, const Bsdf* bsdf, float3 wo,
                         Rng* rng) {
  uint x_select = rng_next_uint(rng);
  float2 u = (float2)(rng_next(rng), rng_next(rng));
  LightSample ls;
  if (!lights_sample(sc->lights, sc->light_thresholds, sc->params->num_lights, sc->tris,
                     sc->shading, sc->materials, &sc->textures, s->p, s->ns, x_select, u, &ls))
    return (float3)(0.0f);
  float3 f = bsdf_eval(bsdf, wo, ls.wi, s->ns, s->ng);
  float cos_i = fabs(dot(ls.wi, s->ns));
  float3 contrib = f * ls.radiance * (cos_i / ls.pdf);
  if (max_component(contrib) <= 0.0f) return (float3)(0.0f);
  Ray shadow;
  shadow.org = offset_ray_origin(s->p, s->ng);
  float tmax = INFINITY;
  shadow.dir = ls.wi;
  if (!ls.at_infinity) {
    float3 d = ls.target - shadow.org;
    tmax = length(d);
    if (!(tmax > 0.0f)) return (float3)(0.0f);
    shadow.dir = d / tmax;
  }
  if (bvh_occluded(sc->nodes, sc->tris, shadow, tmax)) return (float3)(0.0f);
  return contrib;
}

// Radiance along one camera ray
float3 path_trace(const SceneData* sc, Ray ray, Rng* rng) {
  __global const RenderParams* params = sc->params;
  const bool nee = params->strategy == STRATEGY_NEE;
  float3 radiance = (float3)(0.0f);
  float3 beta = (float3)(1.0f);
  for (uint depth = 0u;; ++depth) {
    Hit hit = bvh_intersect(sc->nodes, sc->tris, ray, INFINITY, false);
    bool counts_emission = depth == 0u || !nee;
    if (hit.tri < 0) {
      if (counts_emission) radiance += beta * load3(params->background);
      break;
    }
    SurfaceHit s = surface_at(sc->tris, sc->shading, sc->colors, hit, ray.dir);
    __global const Material* m = &sc->materials[s.material];
    if (counts_emission) radiance += beta * surface_emission(m, s.front, &sc->textures, s.uv);
    if (depth >= params->max_depth) break;

    float3 wo = -ray.dir;
    Bsdf bsdf = bsdf_at(m, &sc->textures, &s);
    if (nee) radiance += beta * path_direct_light(sc, &s, &bsdf, wo, rng);

    // Continue the path by sampling the BSDF
    float2 u = (float2)(rng_next(rng), rng_next(rng));
    float3 wi, f;
    float pdf;
    if (!bsdf_sample(&bsdf, wo, s.ns, s.ng, u, &wi, &f, &pdf)) break;
    beta *= f * (fabs(dot(wi, s.ns)) / pdf);

    // Russian roulette on the throughput
    if (depth + 1u >= params->rr_depth) {
      float q = fmin(max_component(beta), 0.95f);
      if (rng_next(rng) >= q) break;
      beta /= q;
    }
    ray.org = offset_ray_origin(s.p, dot(wi, s.ng) > 0.0f ? s.ng : -s.ng);
    ray.dir = wi;
  }
  return radiance;
}

__kernel void render_paths(__global const BvhNode* nodes, __global const Triangle* tris,
                           __global const TriangleShading* shading,
                           __global const TriangleColors* colors,
                           __global const Material* materials,
                           __global const TextureInfo* textures, __global const uchar4* texels,
                           __global const float* srgb_to_linear,
                           __global const Light* lights,
                           __global const uint* light_thresholds,
                           __global const RenderParams* params, __global float4* film_mean,
                           __global float4* film_m2) {
  uint pixel = params->pixel_begin + (uint)get_global_id(0);
  if (pixel >= params->pixel_end) return;
  SceneData sc = {nodes,
                  tris,
                  shading,
                  colors,
                  materials,
                  {textures, texels, srgb_to_linear},
                  lights,
                  light_thresholds,
                  params};
  uint px = pixel % params->width, py = pixel / params->width;

  // Welford state: mean.w counts kept samples, m2.w counts dropped (non-finite) ones
  float4 mean = film_mean[pixel];
  float4 m2 = film_m2[pixel];
  for (uint k = 0u; k < params->sample_count; ++k) {
    Rng rng = rng_init(pixel, params->sample_begin + k, params->seed);
    float jx = rng_next(&rng), jy = rng_next(&rng);
    Ray ray = camera_ray(params, (float)px + jx, (float)py + jy);
    float3 l = path_trace(&sc, ray, &rng);
    if (!all_finite(l)) {
      m2.w += 1.0f;
      continue;
    }
    float n = mean.w + 1.0f;
    float3 delta = l - mean.xyz;
    float3 new_mean = mean.xyz + delta / n;
    m2.xyz += delta * (l - new_mean);
    mean = (float4)(new_mean, n);
  }
  film_mean[pixel] = mean;
  film_m2[pixel] = m2;
}
