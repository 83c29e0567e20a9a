// Punctual lights (KHR_lights_punctual; CD_LIGHTS entries point, spot and directional). Each
// is a delta in direction: the sample carries the irradiance arriving normal to wi as
// `radiance` with pdf 1 (times the selection pmf), so path_direct_light's f * radiance * cos
// / pdf is the reflected radiance, and no BSDF-sampled ray can hit one (lights_pdf = 0).

// The extension's recommended window for a finite `range`: 1 - (d / range)^4, clamped to
// [0, 1], on top of the inverse square; exactly 0 at and beyond the range. range 0: none.
float lights_range_window(float range, float dist) {
  if (!(range > 0.0f)) return 1.0f;
  float x = dist / range;
  x *= x;
  return clamp(1.0f - x * x, 0.0f, 1.0f);
}

// Point and spot lights: intensity I gives irradiance I / d^2 at ctx.p, a spot's (spot not
// 0) scaled by its cone profile (spot_profile, cl/shared/light_profiles.h); the shadow ray
// ends at the light's position
bool lights_sample_position(__global const Light* light, float3 pos, __global const SpotLight* spot,
                            const LightSampleContext* ctx, LightSample* ls) {
  float3 d = pos - ctx->p;
  float dist2 = dot(d, d);
  if (!(dist2 > 0.0f)) return false;
  float dist = sqrt(dist2);
  ls->wi = d / dist;
  float scale = lights_range_window(light->radiance[3], dist) / dist2;
  if (spot) scale *= spot_profile(-dot(ls->wi, load3(spot->axis)), spot->cone_scale, spot->cone_offset);
  ls->radiance = load3(light->radiance) * scale;
  ls->pdf = 1.0f;
  ls->is_delta = true;
  ls->at_infinity = false;
  ls->target = pos;
  return scale > 0.0f && isfinite(scale);
}

bool lights_point_sample(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx, float2 u,
                         LightSample* ls) {
  return lights_sample_position(light, load3(light->params.point.position), 0, ctx, ls);
}

bool lights_spot_sample(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx, float2 u,
                        LightSample* ls) {
  return lights_sample_position(light, load3(light->params.spot.position), &light->params.spot, ctx, ls);
}

// Directional light: irradiance E at normal incidence from the one direction it comes from
bool lights_directional_sample(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx,
                               float2 u, LightSample* ls) {
  ls->wi = -load3(light->params.directional.direction);
  ls->radiance = load3(light->radiance);
  ls->pdf = 1.0f;
  ls->is_delta = true;
  ls->at_infinity = true;
  return true;
}

// Delta lights: no extent (only light sampling finds them), no primitive
void lights_point_extent(const SceneData* sc, __global const Light* light, float3 p, LightExtent* e) {}
void lights_spot_extent(const SceneData* sc, __global const Light* light, float3 p, LightExtent* e) {}
void lights_directional_extent(const SceneData* sc, __global const Light* light, float3 p, LightExtent* e) {}
float lights_point_omega_bound(const SceneData* sc, __global const Light* light, float3 p) { return 0.0f; }
float lights_spot_omega_bound(const SceneData* sc, __global const Light* light, float3 p) { return 0.0f; }
float lights_directional_omega_bound(const SceneData* sc, __global const Light* light, float3 p) { return 0.0f; }
uint lights_point_prim(__global const Light* light) { return UINT_MAX; }
uint lights_spot_prim(__global const Light* light) { return UINT_MAX; }
uint lights_directional_prim(__global const Light* light) { return UINT_MAX; }

// A delta in direction: no sampled direction finds a punctual light
float lights_point_pdf(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx, float3 wi) {
  return 0.0f;
}
float lights_spot_pdf(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx, float3 wi) {
  return 0.0f;
}
float lights_directional_pdf(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx,
                             float3 wi) {
  return 0.0f;
}
