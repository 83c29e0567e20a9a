// Light sampling from a context (a surface point, or a point in a medium), through one
// light-selection alias table with probabilities proportional to power, or the light tree
// (below) that weighs each light by what it can send to the shading point. Directions and pdfs
// are measured from ctx.p; a finite light's shadow ray ends at `target`, just off the
// light's surface on ctx.p's side. Each light type has lights_NAME_sample and
// lights_NAME_pdf; the dispatch on the type is generated from CD_LIGHTS
// (cl/shared/device_types.h), and a type whose feature is off (SceneFeatures: punctual
// lights, the environment) is compiled out.

typedef struct {
  float3 p;
  float3 n;        // geometric normal on the side light is gathered from; 0 at a point in a medium
  float3 ns;       // shading normal on the same side; 0 in a medium
  bool transmits;  // the BSDF (or phase function) also scatters light arriving from behind n
} LightSampleContext;

typedef struct {
  float3 wi;         // unit direction from ctx.p toward the light
  float3 radiance;   // emitted radiance arriving along -wi (intensity for delta lights)
  float pdf;         // solid-angle pdf of wi including the selection probability (delta: pmf)
  bool is_delta;     // a punctual or directional light: no BSDF-sampled ray can hit it
  bool at_infinity;  // shadow ray along wi without end
  float3 target;     // finite lights: the sampled point, moved off the light toward ctx.p
  uint light;        // index of the light picked
  float pmf;         // the probability of picking it (lights_select_pmf)
} LightSample;

// What STRATEGY_AUTO's choice between light and BSDF sampling needs of a light seen from a
// point (integrator_path.cl): its solid angle, the direction to its centre, and the
// probability with which light selection picks it
typedef struct {
  float3 dir;       // unit direction to the light's centre (an environment: its bright part's)
  float omega;      // solid angle (0: a delta light)
  float radius;     // angle from dir that holds the whole light
  float pmf;        // selection probability (set by path_nee_takes, not lights_extent)
  float integral;   // an environment: integral of its luminance over the sphere
  bool everywhere;  // an environment: it surrounds the point, overlapping every lobe
} LightExtent;

LightSampleContext light_context_at_surface(const SurfaceHit* s, const Bsdf* b) {
  LightSampleContext ctx;
  ctx.p = s->p;
  ctx.n = s->ng;
  ctx.ns = b->frame.n;  // the BSDF's shading normal (normal-mapped)
  ctx.transmits = (bsdf_flags(b) & BSDF_TRANSMISSION) != 0u;
  return ctx;
}

// Environment light: a constant, or an equirectangular map (cl/lights/environment.cl)
__global const Light* lights_environment(const SceneData* sc) {
  int i = sc->params->environment_light;
  return i == NO_LIGHT ? 0 : &sc->lights[i];
}

// Radiance arriving along -dir from infinitely far away
float3 lights_environment_radiance(const SceneData* sc, float3 dir) {
#if CD_FEATURE_ENVIRONMENT
  __global const Light* env = lights_environment(sc);
  if (!env) return (float3)(0.0f);
  if (environment_map(env) != NO_TEXTURE) return environment_radiance(sc, env, dir);
  return load3(env->radiance);
#else
  return (float3)(0.0f);
#endif
}

// Reflection-only surfaces see the environment over the hemisphere of n (sampled by the
// cosine to n); points in media and transmissive surfaces over the whole sphere
bool lights_environment_hemisphere(const LightSampleContext* ctx) {
  return !ctx->transmits && dot(ctx->n, ctx->n) > 0.0f;
}

// A map is importance-sampled over the whole sphere, whatever the context
float lights_environment_pdf(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx,
                             float3 wi) {
  __global const Light* env = lights_environment(sc);
  if (env && environment_map(env) != NO_TEXTURE) return environment_pdf(sc, env, wi);
  if (lights_environment_hemisphere(ctx)) return sample_cosine_hemisphere_pdf(dot(wi, ctx->n));
  return sample_uniform_sphere_pdf();
}

bool lights_environment_sample(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx,
                               float2 u, LightSample* ls) {
  __global const Light* env = lights_environment(sc);
  if (env && environment_map(env) != NO_TEXTURE) {
    ls->wi = environment_sample(sc, env, u, &ls->pdf, &ls->radiance);
    ls->at_infinity = true;
    return ls->pdf > 0.0f;
  }
  if (lights_environment_hemisphere(ctx)) {
    Frame f = frame_from_z(ctx->n);
    ls->wi = frame_from_local(&f, sample_cosine_hemisphere(u.x, u.y));
  } else {
    ls->wi = sample_uniform_sphere(u.x, u.y);
  }
  ls->pdf = lights_environment_pdf(sc, light, ctx, ls->wi);
  ls->radiance = lights_environment_radiance(sc, ls->wi);
  ls->at_infinity = true;
  return ls->pdf > 0.0f;
}

uint lights_environment_prim(__global const Light* light) { return UINT_MAX; }

// An environment seen from anywhere: its bright part as a cone of its effective solid angle
// (integral L)^2 / integral L^2 about the direction its L^2 is centred on (the whole
// sphere for a constant), and integral L, L its luminance (computed on the host:
// Light.params[3..7])
void lights_environment_extent(const SceneData* sc, __global const Light* light, float3 p, LightExtent* e) {
  e->omega = light->params[3];
  e->everywhere = true;
  e->dir = (float3)(light->params[4], light->params[5], light->params[6]);
  e->radius = dot(e->dir, e->dir) > 0.0f ? acos_fast(1.0f - e->omega * (0.5f * INV_PI_F)) : PI_F;
  bool map = environment_map(light) != NO_TEXTURE;
  e->integral = light->params[7] * (map ? light->params[1] : luminance(load3(light->radiance)));
}

// An environment surrounds every point: no bound smaller than its extent
float lights_environment_omega_bound(const SceneData* sc, __global const Light* light, float3 p) { return -1.0f; }

// Triangle lights are sampled uniformly in the solid angle they subtend at ctx.p (Arvo
// 1995, Stratified Sampling of Spherical Triangles) where that solid angle is at least
// LIGHTS_SPHERICAL_MIN_SOLID_ANGLE (0.1 sr), else uniformly in area. Solid-angle sampling
// removes the 1/r^2 and the emitter's cosine from the estimator: half the error of area
// sampling under a large light close to a surface (1.7x the equal-time efficiency), but its
// trigonometry costs time: on the Cornell box, whose light subtends about 0.05 sr from the
// floor, it lowers the error by 7 % for 12 % more CPU time, a loss. Below the threshold
// (small or distant triangles, where 1/r^2 and the cosine hardly vary over the triangle,
// and the spherical formulas lose precision in float) area sampling is used. CD_TRIANGLE_SAMPLING_AREA (a build option)
// keeps area sampling everywhere, for comparison (README "Light sampling").
#ifndef LIGHTS_SPHERICAL_MIN_SOLID_ANGLE
#define LIGHTS_SPHERICAL_MIN_SOLID_ANGLE 0.1f
#endif

// Solid angle of the spherical triangle of unit vectors (a, b, c) (Van Oosterom and
// Strackee 1983): tan(omega / 2) = num / den with num = |a.(b x c)|, den = 1 + a.b + b.c + c.a
float lights_spherical_triangle_num(float3 a, float3 b, float3 c) { return fabs(dot(a, cross(b, c))); }
float lights_spherical_triangle_den(float3 a, float3 b, float3 c) { return 1.0f + dot(a, b) + dot(b, c) + dot(c, a); }
float lights_spherical_triangle_angle(float num, float den) {
  float omega = 2.0f * atan2(num, den);
  return omega >= 0.0f ? omega : omega + 2.0f * PI_F;
}

// Directions from p to the triangle's vertices, and whether it is sampled by solid angle
bool lights_triangle_spherical(float3 p, float3 v0, float3 v1, float3 v2, float3* a, float3* b, float3* c,
                               float* omega) {
#ifdef CD_TRIANGLE_SAMPLING_AREA
  return false;
#else
  *a = normalize(v0 - p);
  *b = normalize(v1 - p);
  *c = normalize(v2 - p);
  float num = lights_spherical_triangle_num(*a, *b, *c), den = lights_spherical_triangle_den(*a, *b, *c);
  // Small triangles are the common case (area sampling) and need no atan2: tan(x) > x, so
  // num < (MIN / 2) den (den > 0) means omega < MIN with room to spare for rounding; the
  // others take the exact test, so the choice is the same as with omega alone
  if (den > 0.0f && !(num >= 0.5f * LIGHTS_SPHERICAL_MIN_SOLID_ANGLE * den)) return false;
  *omega = lights_spherical_triangle_angle(num, den);
  return *omega >= LIGHTS_SPHERICAL_MIN_SOLID_ANGLE && isfinite(*omega);
#endif
}

// The component of v orthogonal to unit n, normalized
float3 lights_orthonormal(float3 v, float3 n) { return normalize(v - dot(v, n) * n); }

// Arvo's sampling of the spherical triangle (a, b, c) of area omega: pick the sub-triangle
// (a, b, c') of area u.x * omega, then a point on the arc from b to c' with the density
// that makes the result uniform in solid angle
float3 lights_sample_spherical_triangle(float3 a, float3 b, float3 c, float omega, float2 u) {
  // Interior angle at a between the great circles (a, b) and (a, c), and the cosine of
  // the side opposite c
  float3 n_ab = normalize(cross(a, b)), n_ac = normalize(cross(a, c));
  float cos_alpha = clamp(dot(n_ab, n_ac), -1.0f, 1.0f);
  float sin_alpha = sqrt(fmax(0.0f, 1.0f - cos_alpha * cos_alpha));  // alpha in [0, pi]
  float cos_c = dot(a, b);
  // phi = sub-triangle area - alpha, by the angle-difference formulas (no acos)
  float cos_s, sin_s = sincos(u.x * omega, &cos_s);
  float cos_phi = cos_s * cos_alpha + sin_s * sin_alpha;
  float sin_phi = sin_s * cos_alpha - cos_s * sin_alpha;
  float uu = cos_phi - cos_alpha;
  float vv = sin_phi + sin_alpha * cos_c;
  float q = ((vv * cos_phi - uu * sin_phi) * cos_alpha - vv) / ((vv * sin_phi + uu * cos_phi) * sin_alpha);
  q = clamp(q, -1.0f, 1.0f);
  float3 c_sub = q * a + sqrt(fmax(0.0f, 1.0f - q * q)) * lights_orthonormal(c, a);
  float z = 1.0f - u.y * (1.0f - dot(c_sub, b));
  z = clamp(z, -1.0f, 1.0f);
  return normalize(z * b + sqrt(fmax(0.0f, 1.0f - z * z)) * lights_orthonormal(c_sub, b));
}

// Barycentric weights (b1, b2) of v1, v2 where the ray from p along d meets the plane of
// (v0, v1, v2), clamped into the triangle (the direction came from inside it; float error
// may put it a hair outside); false when the ray runs parallel to the plane
bool lights_triangle_barycentrics(float3 p, float3 d, float3 v0, float3 v1, float3 v2, float2* bary) {
  float3 e1 = v1 - v0, e2 = v2 - v0;
  float3 pv = cross(d, e2);
  float det = dot(e1, pv);
  if (det == 0.0f || !isfinite(det)) return false;
  float3 tv = p - v0;
  float b1 = dot(tv, pv) / det;
  float b2 = dot(d, cross(tv, e1)) / det;
  b1 = clamp(b1, 0.0f, 1.0f);
  b2 = clamp(b2, 0.0f, 1.0f - b1);
  *bary = (float2)(b1, b2);
  return true;
}

// Area measure to solid angle at ctx.p for a point y on a triangle of normal n and area A
float lights_triangle_solid_angle_pdf(float3 p, float3 y, float3 n, float area) {
  float3 d = y - p;
  float dist2 = dot(d, d);
  float cos_light = fabs(dot(n, d)) / sqrt(dist2);
  return dist2 / (cos_light * area);  // dw/dA = cos(theta_y) / r^2
}

// A point on the light's triangle, uniform in solid angle or in area (see above), with
// its solid-angle pdf at ctx.p
bool lights_triangle_sample(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx, float2 u,
                            LightSample* ls) {
  float3 v0, v1, v2;
  scene_prim_positions(sc, light->index, &v0, &v1, &v2);
  float area;
  float3 n = triangle_normal_area(v0, v1, v2, &area);
  float3 a, b, c;
  float omega;
  float2 bary;
  if (lights_triangle_spherical(ctx->p, v0, v1, v2, &a, &b, &c, &omega)) {
    float3 dir = lights_sample_spherical_triangle(a, b, c, omega, u);
    if (!lights_triangle_barycentrics(ctx->p, dir, v0, v1, v2, &bary)) return false;
    ls->pdf = 1.0f / omega;
  } else {
    bary = sample_triangle(u.x, u.y);
    ls->pdf = -1.0f;  // converted from area below
  }
  float b1 = bary.x, b2 = bary.y;
  float3 y = (1.0f - b1 - b2) * v0 + b1 * v1 + b2 * v2;
  float3 d = y - ctx->p;
  float dist2 = dot(d, d);
  if (!(dist2 > 0.0f)) return false;
  ls->wi = d / sqrt(dist2);
  if (ls->pdf < 0.0f) ls->pdf = lights_triangle_solid_angle_pdf(ctx->p, y, n, light->params[0]);
  bool front = dot(n, ls->wi) < 0.0f;
  __global const Prim* pr = &sc->prims[light->index];
  ls->radiance = surface_emission(sc, &sc->materials[pr->material], front, surface_uvs(sc, pr, b1, b2));
  // Where alpha lets rays through, BSDF-sampled rays find the emitter only that often
  ls->radiance *= alpha_coverage(sc, light->index, b1, b2);
  ls->at_infinity = false;
  ls->target = offset_ray_origin(y, n * (front ? 1.0f : -1.0f));
  return ls->pdf > 0.0f && isfinite(ls->pdf);
}

// The pdf lights_triangle_sample would give for wi: where the ray from ctx.p along wi
// meets the light's triangle (0 if it misses)
float lights_triangle_pdf(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx, float3 wi) {
  float3 v0, v1, v2;
  scene_prim_positions(sc, light->index, &v0, &v1, &v2);
  Ray r = {ctx->p, wi};
  WatertightRay wr = watertight_ray(r);
  float t, b1, b2;
  if (!intersect_triangle(&wr, v0, v1, v2, INFINITY, &t, &b1, &b2)) return 0.0f;
  float3 a, b, c;
  float omega;
  if (lights_triangle_spherical(ctx->p, v0, v1, v2, &a, &b, &c, &omega)) return 1.0f / omega;
  float area;
  float3 n = triangle_normal_area(v0, v1, v2, &area);
  return lights_triangle_solid_angle_pdf(ctx->p, ctx->p + t * wi, n, light->params[0]);
}

uint lights_triangle_prim(__global const Light* light) { return light->index; }

// A triangle seen from p: its solid angle (Van Oosterom & Strackee 1983, The Solid Angle
// of a Plane Triangle) and the cone about the direction to its centroid that holds its
// three corners
void lights_triangle_extent(const SceneData* sc, __global const Light* light, float3 p, LightExtent* e) {
#pragma OPENCL FP_CONTRACT OFF
  float3 v0, v1, v2;
  scene_prim_positions(sc, light->index, &v0, &v1, &v2);
  float3 a = v0 - p, b = v1 - p, c = v2 - p;
  float3 d = a + b + c;
  float la = length(a), lb = length(b), lc = length(c), ld = length(d);
  if (!(la > 0.0f && lb > 0.0f && lc > 0.0f && ld > 0.0f)) {
    e->omega = 2.0f * PI_F;
    e->radius = PI_F;
    return;
  }
  float den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  e->omega = clamp(2.0f * atan2_fast(fabs(dot(a, cross(b, c))), den), 1e-12f, 2.0f * PI_F);
  e->dir = d / ld;
  float cos_min = fmin(fmin(dot(e->dir, a) / la, dot(e->dir, b) / lb), dot(e->dir, c) / lc);
  e->radius = acos_fast(cos_min);
}

// An upper bound on the solid angle the triangle subtends at p, for far less work than its
// extent: the smaller of the cone of its bounding sphere (centre c, radius R: params[1..4]),
// 2 pi (1 - sqrt(1 - R^2 / d^2)) <= 2 pi R^2 / d^2 at distance d, and area / (d - R)^2 (no
// point of it is nearer than d - R, and dw = cos dA / r^2), at most 2 pi; 1 % over them
// for rounding
float lights_triangle_omega_bound(const SceneData* sc, __global const Light* light, float3 p) {
#pragma OPENCL FP_CONTRACT OFF
  float3 pc = (float3)(light->params[1], light->params[2], light->params[3]) - p;
  float r = light->params[4], d2 = dot(pc, pc);
  float near = sqrt(d2) - r;
  float area = near > 0.0f ? light->params[0] / (near * near) : INFINITY;
  float bound = fmin(fmin(2.0f * PI_F * (r * r) / d2, area), 2.0f * PI_F);
  return bound >= 0.0f ? 1.01f * bound : 2.0f * PI_F;  // NaN (p): no help
}

// Punctual lights (KHR_lights_punctual). Each is a delta in direction: the sample carries
// the irradiance arriving normal to wi as `radiance` with pdf 1 (times the selection
// pmf), so path_direct_light's f * radiance * cos / pdf is the reflected radiance, and no
// BSDF-sampled ray can hit one (lights_pdf = 0).

// The extension's recommended window for a finite `range`: 1 - (d / range)^4, clamped to
// [0, 1], on top of the inverse square; exactly 0 at and beyond the range. range 0: none.
float lights_range_window(float range, float dist) {
  if (!(range > 0.0f)) return 1.0f;
  float x = dist / range;
  x *= x;
  return clamp(1.0f - x * x, 0.0f, 1.0f);
}

// The extension's spot cone profile at cosine `cos_axis` from the axis: t^2 with t
// interpolating the cosine linearly from cos(outer) (t = 0) to cos(inner) (t = 1)
float lights_spot_falloff(__global const Light* light, float cos_axis) {
  float t = clamp(cos_axis * light->params[6] + light->params[7], 0.0f, 1.0f);
  return t * t;
}

// Point and spot lights: intensity I gives irradiance I / d^2 at ctx.p, a spot's scaled by
// its cone profile; the shadow ray ends at the light's position
bool lights_sample_position(__global const Light* light, const LightSampleContext* ctx, bool spot, LightSample* ls) {
  float3 pos = load3(light->params);
  float3 d = pos - ctx->p;
  float dist2 = dot(d, d);
  if (!(dist2 > 0.0f)) return false;
  float dist = sqrt(dist2);
  ls->wi = d / dist;
  float scale = lights_range_window(light->radiance[3], dist) / dist2;
  if (spot) scale *= lights_spot_falloff(light, -dot(ls->wi, load3(light->params + 3)));
  ls->radiance = load3(light->radiance) * scale;
  ls->pdf = 1.0f;
  ls->is_delta = true;
  ls->at_infinity = false;
  ls->target = pos;
  return scale > 0.0f && isfinite(scale);
}

bool lights_point_sample(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx, float2 u,
                         LightSample* ls) {
  return lights_sample_position(light, ctx, false, ls);
}

bool lights_spot_sample(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx, float2 u,
                        LightSample* ls) {
  return lights_sample_position(light, ctx, true, ls);
}

// Directional light: irradiance E at normal incidence from the one direction it comes from
bool lights_directional_sample(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx,
                               float2 u, LightSample* ls) {
  ls->wi = -load3(light->params + 3);
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

// Light tree (Conty Estevez & Kulla 2018, Importance Sampling of Many Lights with Adaptive
// Tree Splitting): selection descends from the root, taking each child with probability
// proportional to its importance at the shading point, an estimate of the irradiance its
// lights can send there; the selection pmf is the product of those probabilities. A child's
// importance is I cos(theta') cos(theta_i') / d^2: I its summed peak intensity, d the
// distance to the centre of its bounding sphere (the sphere's radius r when ctx.p lies
// inside it, where both cosines are 1), theta' the smallest angle its emission cone can make
// with the direction to ctx.p (the angle from the cone's axis less theta_o and less the angle
// theta_b the sphere subtends; 0 importance beyond theta_e: no light of the child emits
// toward ctx.p), and theta_i' the smallest angle between the shading normal and a direction
// into the sphere (the |cos| the estimator weighs by; 1 in a medium, n = 0). Both cosines
// are kept at least LIGHT_TREE_MIN_COS and the cut-off has a margin of the same size, so
// float rounding never gives 0 to a light that can contribute. A node's four children are
// weighed at once, one child per float4 lane. Every child of nonzero importance is given a
// weight of at least the root's `min_prob` times the sum of the importances before the
// weights are normalized, so a probability of at least min_prob / (1 + 4 min_prob) (also
// when another child's importance is infinite); the host sets min_prob so that the product
// over the deepest trail, times the tree's share, stays above 2^-124: no light's pmf
// underflows (to 0 on devices that flush denormals). Sampling and the pmf of a given light
// (lights_tree_pmf, along its trail) run the same arithmetic, contraction off, so
// STRATEGY_AUTO's two evaluations of a light's selection probability agree exactly.
// Inside a planar emitter of several triangles (cluster nodes) the children are taken by
// their share of the intensity, with no importance to evaluate.
#define LIGHT_TREE_MIN_COS 1e-3f

// The importances of node's four children at ctx (0 in empty slots)
float4 lights_tree_importance(__global const LightTreeNode* node, const LightSampleContext* ctx) {
#pragma OPENCL FP_CONTRACT OFF
  float4 intensity = vload4(0, node->intensity), r = vload4(0, node->radius);
  float4 dx = ctx->p.x - vload4(0, node->centre[0]), dy = ctx->p.y - vload4(0, node->centre[1]),
         dz = ctx->p.z - vload4(0, node->centre[2]);
  float4 dist2 = dx * dx + dy * dy + dz * dz, r2 = r * r;
  int4 outside = isgreater(dist2, r2);
  // 1 / max(d, r): one reciprocal square root serves the direction to ctx.p (outside the
  // sphere, the only place it is used) and the importance's 1 / max(d^2, r^2)
  float4 inv_d = rsqrt(fmax(fmax(dist2, r2), 1e-30f));
  // theta_b, the angle the sphere subtends: its sine r / d and its cosine; the sine of each
  // difference of angles below comes from the addition formula, not from a square root of
  // its cosine
  float4 sin_b = select((float4)(1.0f), fmin(r * inv_d, 1.0f), outside);
  float4 cos_b = sqrt(fmax(1.0f - sin_b * sin_b, 0.0f));
  float4 wx = dx * inv_d, wy = dy * inv_d, wz = dz * inv_d;  // from the child to ctx.p
  // Emitter side: theta' = max(0, theta_w - theta_o - theta_b)
  float4 cos_o = vload4(0, node->cos_o), sin_o = vload4(0, node->sin_o);
  float4 cos_w = vload4(0, node->axis[0]) * wx + vload4(0, node->axis[1]) * wy + vload4(0, node->axis[2]) * wz;
  cos_w = clamp(cos_w, -1.0f, 1.0f);
  float4 sin_w = sqrt(fmax(1.0f - cos_w * cos_w, 0.0f));
  int4 in_cone = isgreaterequal(cos_w, cos_o);  // theta_w <= theta_o
  float4 cos_x = select(cos_w * cos_o + sin_w * sin_o, (float4)(1.0f), in_cone);
  float4 sin_x = select(fmax(sin_w * cos_o - cos_w * sin_o, 0.0f), (float4)(0.0f), in_cone);
  float4 cos_p = select(cos_x * cos_b + sin_x * sin_b, (float4)(1.0f), isgreaterequal(cos_x, cos_b));
  float4 importance = intensity * fmax(cos_p, LIGHT_TREE_MIN_COS);
  importance = select(importance, (float4)(0.0f), isless(cos_p, vload4(0, node->cos_e) - LIGHT_TREE_MIN_COS));
  // Receiver side: theta_i' = max(0, theta_i - theta_b), |cos| to the shading normal
  if (dot(ctx->ns, ctx->ns) > 0.0f) {
    float4 cos_i = fmin(fabs(ctx->ns.x * wx + ctx->ns.y * wy + ctx->ns.z * wz), 1.0f);
    float4 sin_i = sqrt(fmax(1.0f - cos_i * cos_i, 0.0f));
    float4 cos_r = select(cos_i * cos_b + sin_i * sin_b, (float4)(1.0f), isgreaterequal(cos_i, cos_b));
    importance *= fmax(cos_r, LIGHT_TREE_MIN_COS);
  }
  // I cos cos / d^2 outside the sphere, I / r^2 inside
  importance = select(intensity, importance, outside) * (inv_d * inv_d);
  return select((float4)(0.0f), importance, isgreater(intensity, (float4)(0.0f)));
}

// The weights of taking each of node's children at ctx, unnormalized, each nonzero one
// floored at min_prob times their sum (a child is taken with probability q / (q.x + q.y +
// q.z + q.w)); false when none can light ctx.p
bool lights_tree_children(const SceneData* sc, uint node, const LightSampleContext* ctx, float min_prob, float4* q) {
#pragma OPENCL FP_CONTRACT OFF
  __global const LightTreeNode* n = &sc->light_tree[node];
  float4 w = n->cluster ? vload4(0, n->intensity) : lights_tree_importance(n, ctx);
  int4 can_light = isgreater(w, (float4)(0.0f));  // before any rescaling below can flush a lane
  int4 infinite = isinf(w);
  if (any(infinite)) w = select((float4)(0.0f), (float4)(1.0f), infinite);  // the finite get the floor
  float sum = w.x + w.y + w.z + w.w;
  // Weights scaled so that their sum lies in [2^-100, 2^100]: the floors below add at most
  // 4 min_prob times the sum (min_prob is at most about 6, the host's bound), so the total the caller
  // divides by neither overflows (also when finite weights overflow their sum) nor loses
  // bits to denormals; lanes flushed by the scaling keep their floor (can_light)
  if (!(sum <= 0x1p100f)) {
    w *= 0x1p-30f;
    sum = w.x + w.y + w.z + w.w;
  } else if (sum > 0.0f && sum < 0x1p-100f) {
    w *= 0x1p100f;
    sum = w.x + w.y + w.z + w.w;
  }
  if (!(sum > 0.0f)) return false;
  *q = select((float4)(0.0f), fmax(w, min_prob * sum), can_light);
  return true;
}

// Whether selection uses the tree (the kernel has it, it has lights, and the scene was
// compiled for it)
bool lights_tree_used(const SceneData* sc) { return CD_FEATURE_LIGHT_TREE && sc->light_tree[0].share > 0.0f; }

// Whether the tree is used and holds every light: lights_select then needs no draw from the
// alias table (x_select is ignored)
bool lights_tree_holds_all(const SceneData* sc) { return lights_tree_used(sc) && sc->light_tree[0].holds_all; }

// A light of the tree chosen with u, and its probability within the tree; false when no
// light of the tree can light ctx.p
bool lights_tree_sample(const SceneData* sc, const LightSampleContext* ctx, float u, uint* light, float* pmf) {
#pragma OPENCL FP_CONTRACT OFF
  uint node = 0u;
  float prob = 1.0f, min_prob = sc->light_tree[0].min_prob;
  for (uint level = 0u; level < LIGHT_TREE_MAX_DEPTH; ++level) {
    __global const LightTreeNode* n = &sc->light_tree[node];
    // The next node is one of these: its loads overlap this node's arithmetic
    for (uint k = 0u; k < LIGHT_TREE_WIDTH; ++k)
      if (n->leaf[k] == LIGHT_TREE_INTERIOR && n->intensity[k] > 0.0f)
        prefetch((__global const float*)&sc->light_tree[n->child[k]], sizeof(LightTreeNode) / sizeof(float));
    float4 q;
    if (!lights_tree_children(sc, node, ctx, min_prob, &q)) return false;
    // The slot whose interval of the running sum holds t = u x the sum; the last nonzero
    // one when rounding leaves t past them all (slots of weight 0 have empty intervals)
    float c1 = q.x, c2 = c1 + q.y, c3 = c2 + q.z, total = c3 + q.w, t = u * total;
    uint slot = (t >= c1 ? 1u : 0u) + (t >= c2 ? 1u : 0u) + (t >= c3 ? 1u : 0u);
    uint last = q.w > 0.0f ? 3u : (q.z > 0.0f ? 2u : (q.y > 0.0f ? 1u : 0u));
    slot = min(slot, last);
    float below = slot == 0u ? 0.0f : (slot == 1u ? c1 : (slot == 2u ? c2 : c3));
    float taken = slot == 0u ? q.x : (slot == 1u ? q.y : (slot == 2u ? q.z : q.w));
    u = fmin(fmax(t - below, 0.0f) / taken, 0x1.fffffep-1f);
    prob *= taken / total;
    if (n->leaf[slot] == LIGHT_TREE_LEAF) {
      *light = n->child[slot];
      *pmf = prob;
      return prob > 0.0f;
    }
    node = n->child[slot];
  }
  return false;
}

// The probability with which lights_tree_sample picks `light` (one of the tree's) at ctx
float lights_tree_pmf(const SceneData* sc, const LightSampleContext* ctx, uint light) {
#pragma OPENCL FP_CONTRACT OFF
  __global const LightTreeTrail* trail = &sc->light_trails[light];
  uint node = 0u;
  float prob = 1.0f, min_prob = sc->light_tree[0].min_prob;
  for (uint k = 0u; k < trail->depth; ++k) {
    float4 q;
    if (!lights_tree_children(sc, node, ctx, min_prob, &q)) return 0.0f;
    uint slot = (trail->bits[k >> 4] >> (2u * (k & 15u))) & 3u;
    float c1 = q.x, c2 = c1 + q.y, c3 = c2 + q.z, total = c3 + q.w;
    prob *= (slot == 0u ? q.x : (slot == 1u ? q.y : (slot == 2u ? q.z : q.w))) / total;
    node = sc->light_tree[node].child[slot];
  }
  return prob;
}

// The probability with which lights_sample picks light `index` at ctx: the alias table's
// for lights outside the tree (and for all without one), else the tree's share times the
// tree's pmf
float lights_select_pmf(const SceneData* sc, const LightSampleContext* ctx, uint index) {
  __global const Light* light = &sc->lights[index];
  if (!lights_tree_used(sc) || sc->light_trails[index].depth == LIGHT_TREE_NONE) return light->pmf;
  return sc->light_tree[0].share * lights_tree_pmf(sc, ctx, index);
}

// Samples a direction toward `light` by its type
bool lights_sample_light(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx, float2 u,
                         LightSample* ls) {
#define LIGHTS_SAMPLE(id, name, feature) \
  if (feature && light->type == id) return lights_##name##_sample(sc, light, ctx, u, ls);
  CD_LIGHTS(LIGHTS_SAMPLE)
#undef LIGHTS_SAMPLE
  return false;
}

// Picks a light: x_select draws from the alias table (probabilities proportional to
// power); when it falls on a light of the light tree and the tree is used, u_select
// descends the tree instead (lights_tree_sample), so the lights outside it (directional,
// environment) keep their share by power. A tree that holds every light is descended
// without the alias table's draw. *pmf = lights_select_pmf(ctx, *light).
bool lights_select(const SceneData* sc, const LightSampleContext* ctx, uint x_select, float u_select, uint* light,
                   float* pmf) {
  uint n = sc->params->num_lights;
  if (n == 0u) return false;
  *light = lights_tree_holds_all(sc) ? 0u : sample_discrete_alias(sc->light_alias, n, x_select);
  *pmf = sc->lights[*light].pmf;
  if (lights_tree_used(sc) && sc->light_trails[*light].depth != LIGHT_TREE_NONE) {
    float tree_pmf;
    if (!lights_tree_sample(sc, ctx, u_select, light, &tree_pmf)) return false;
    *pmf = sc->light_tree[0].share * tree_pmf;
  }
  return *pmf > 0.0f;
}

// The random numbers of one light selection (lights_select): x_select for the alias table,
// u_select for the light tree. No dimension is spent on what selection does not use: the
// alias table's draw when the tree holds every light, the tree's without a tree
void lights_select_numbers(const SceneData* sc, Rng* rng, uint* x_select, float* u_select) {
  *x_select = lights_tree_holds_all(sc) ? 0u : rng_next_uint(rng);
  *u_select = lights_tree_used(sc) ? rng_next(rng) : 0.0f;
}

// Samples a direction toward light `index`, which lights_select picked with probability pmf
bool lights_sample_selected(const SceneData* sc, const LightSampleContext* ctx, uint index, float pmf, float2 u,
                            LightSample* ls) {
  ls->light = index;
  ls->pmf = pmf;
  ls->is_delta = false;
  bool ok = lights_sample_light(sc, &sc->lights[index], ctx, u, ls);
  ls->pdf *= pmf;
  return ok;
}

// Picks a light (lights_select) and samples a direction toward it
bool lights_sample(const SceneData* sc, const LightSampleContext* ctx, uint x_select, float u_select, float2 u,
                   LightSample* ls) {
  uint light;
  float pmf;
  if (!lights_select(sc, ctx, x_select, u_select, &light, &pmf)) return false;
  return lights_sample_selected(sc, ctx, light, pmf, u, ls);
}

// The pdf with which lights_sample picks light `index` and direction wi from ctx
float lights_pdf(const SceneData* sc, const LightSampleContext* ctx, uint index, float3 wi) {
  __global const Light* light = &sc->lights[index];
#define LIGHTS_PDF(id, name, feature)                                   \
  if (feature && light->type == id) {                                   \
    float pdf = lights_##name##_pdf(sc, light, ctx, wi);                \
    return pdf > 0.0f ? lights_select_pmf(sc, ctx, index) * pdf : 0.0f; \
  }
  CD_LIGHTS(LIGHTS_PDF)
#undef LIGHTS_PDF
  return 0.0f;
}

// The emissive primitive a light is (UINT_MAX for the others), and the light of emissive
// primitive `prim`, or NO_LIGHT (an emitter black throughout). The compile step lists
// triangle lights first, in increasing primitive order (host/compile), so a binary search
// over lights_prim finds it.
uint lights_prim(__global const Light* light) {
#define LIGHTS_PRIM(id, name, feature) \
  if (feature && light->type == id) return lights_##name##_prim(light);
  CD_LIGHTS(LIGHTS_PRIM)
#undef LIGHTS_PRIM
  return UINT_MAX;
}

int lights_of_prim(const SceneData* sc, uint prim) {
  uint lo = 0u, hi = sc->params->num_lights;
  while (lo < hi) {
    uint mid = (lo + hi) / 2u;
    if (lights_prim(&sc->lights[mid]) < prim)
      lo = mid + 1u;
    else
      hi = mid;
  }
  return lo < sc->params->num_lights && lights_prim(&sc->lights[lo]) == prim ? (int)lo : NO_LIGHT;
}

// An upper bound on the solid angle light `index` subtends at p, cheaper than its extent
// (0 for a delta light), or a negative value where it has none
float lights_omega_bound(const SceneData* sc, uint index, float3 p) {
  __global const Light* light = &sc->lights[index];
#define LIGHTS_OMEGA_BOUND(id, name, feature) \
  if (feature && light->type == id) return lights_##name##_omega_bound(sc, light, p);
  CD_LIGHTS(LIGHTS_OMEGA_BOUND)
#undef LIGHTS_OMEGA_BOUND
  return -1.0f;
}

// Light `index` as STRATEGY_AUTO's choice sees it from p, its selection probability aside
// (lights_select_pmf: it depends on where the shading point is and which way it faces)
LightExtent lights_extent(const SceneData* sc, uint index, float3 p) {
  __global const Light* light = &sc->lights[index];
  LightExtent e;
  e.dir = (float3)(0.0f);
  e.omega = 0.0f;
  e.radius = PI_F;
  e.integral = 0.0f;
  e.pmf = 0.0f;
  e.everywhere = false;
#define LIGHTS_EXTENT(id, name, feature) \
  if (feature && light->type == id) lights_##name##_extent(sc, light, p, &e);
  CD_LIGHTS(LIGHTS_EXTENT)
#undef LIGHTS_EXTENT
  return e;
}
