// Emissive triangles as lights (CD_LIGHTS entry triangle; TriangleLight)

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
  if (ls->pdf < 0.0f) ls->pdf = lights_triangle_solid_angle_pdf(ctx->p, y, n, light->params.triangle.area);
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
  return lights_triangle_solid_angle_pdf(ctx->p, ctx->p + t * wi, n, light->params.triangle.area);
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
// extent: the smaller of the cone of its bounding sphere (centre c, radius R: TriangleLight's centre and radius),
// 2 pi (1 - sqrt(1 - R^2 / d^2)) <= 2 pi R^2 / d^2 at distance d, and area / (d - R)^2 (no
// point of it is nearer than d - R, and dw = cos dA / r^2), at most 2 pi; 1 % over them
// for rounding
float lights_triangle_omega_bound(const SceneData* sc, __global const Light* light, float3 p) {
#pragma OPENCL FP_CONTRACT OFF
  __global const TriangleLight* t = &light->params.triangle;
  float3 pc = (float3)(t->centre[0], t->centre[1], t->centre[2]) - p;
  float r = t->radius, d2 = dot(pc, pc);
  float near = sqrt(d2) - r;
  float area = near > 0.0f ? t->area / (near * near) : INFINITY;
  float bound = fmin(fmin(2.0f * PI_F * (r * r) / d2, area), 2.0f * PI_F);
  return bound >= 0.0f ? 1.01f * bound : 2.0f * PI_F;  // NaN (p): no help
}
