// Rays, shading frames, triangle helpers and robust ray offsets.

typedef struct {
  float3 org;
  float3 dir;
} Ray;

float3 load3(__global const float* p) { return vload3(0, p); }

float max_component(float3 v) { return fmax(v.x, fmax(v.y, v.z)); }

float luminance(float3 c) { return luminance_rgb(c.x, c.y, c.z); }

bool all_finite(float3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

// atan2(y, x) for finite y and x, within 4e-7 radians of the exact angle, signed zeros as
// atan2's: atan(a) = a P(a^2) on a = min(|x|, |y|) / max(|x|, |y|) in [0, 1], then the
// octant. P is the project's own fit (least squares, reweighted toward a minimax relative
// error: 1.0e-7 in exact arithmetic). Inlined arithmetic instead of the library call that
// every ray leaving an environment-lit scene makes (docs/performance.md).
float atan2_fast(float y, float x) {
  float ax = fabs(x), ay = fabs(y);
  float hi = fmax(ax, ay), lo = fmin(ax, ay);
  float a = hi > 0.0f ? lo / hi : 0.0f, s = a * a;
  float p = -0.004680493380874395f;
  p = p * s + 0.024210669100284576f;
  p = p * s - 0.059433430433273315f;
  p = p * s + 0.09911005944013596f;
  p = p * s - 0.14018453657627106f;
  p = p * s + 0.19969575107097626f;
  p = p * s - 0.33331984281539917f;
  p = p * s + 0.9999998807907104f;
  float r = a * p;
  if (ay > ax) r = 0.5f * PI_F - r;
  if (signbit(x)) r = PI_F - r;  // -0 too, as atan2(0, -0) = pi
  return copysign(r, y);
}

// acos(x) by atan2_fast, x clamped to [-1, 1] (a dot product of unit vectors can round
// past them): within 5e-7 radians of the exact angle (the sine as sqrt((1 - x)(1 + x))
// keeps its relative precision near x = +-1). For the estimates of the auto strategy,
// where the library's acos and atan2 were an eighth of the Cornell box's render time
// (docs/performance.md)
float acos_fast(float x) {
  float c = clamp(x, -1.0f, 1.0f);
  return atan2_fast(sqrt((1.0f - c) * (1.0f + c)), c);
}

// Orthonormal frame (t, b, n); local coordinates have z along n
typedef struct {
  float3 t, b, n;
} Frame;

float3 frame_to_local(const Frame* f, float3 v) { return (float3)(dot(v, f->t), dot(v, f->b), dot(v, f->n)); }

float3 frame_from_local(const Frame* f, float3 v) { return v.x * f->t + v.y * f->b + v.z * f->n; }

// Any frame around unit n (Duff et al. 2017, Building an Orthonormal Basis, Revisited)
Frame frame_from_z(float3 n) {
  float sign = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (sign + n.z);
  float c = n.x * n.y * a;
  Frame f;
  f.t = (float3)(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  f.b = (float3)(c, sign + n.y * n.y * a, -n.y);
  f.n = n;
  return f;
}

// Frame around unit n with t along the part of `tangent` orthogonal to n (Gram-Schmidt);
// any frame when that part vanishes
Frame frame_from_z_x(float3 n, float3 tangent) {
  float3 t = tangent - dot(tangent, n) * n;
  float len = length(t);
  if (!(len > 1e-6f * length(tangent)) || !isfinite(len)) return frame_from_z(n);
  Frame f;
  f.t = t / len;
  f.b = cross(n, f.t);
  f.n = n;
  return f;
}

// Unit normal of triangle (v0, v1, v2) by its counter-clockwise winding; *area gets its area
float3 triangle_normal_area(float3 v0, float3 v1, float3 v2, float* area) {
  float3 c = cross(v1 - v0, v2 - v0);
  float len = length(c);
  *area = 0.5f * len;
  return c / len;
}

// Move p off its surface along the geometric normal n by a few ulps, on the side of n
// (Waechter and Binder 2019, A Fast and Robust Method for Avoiding Self-Intersection).
// n = 0 (a point in a medium) leaves p where it is.
float3 offset_ray_origin(float3 p, float3 n) {
  const float origin = 1.0f / 32.0f;
  const float float_scale = 1.0f / 65536.0f;
  const float int_scale = 256.0f;
  int3 of_i = convert_int3(int_scale * n);
  float3 p_i = (float3)(as_float(as_int(p.x) + (p.x < 0.0f ? -of_i.x : of_i.x)),
                        as_float(as_int(p.y) + (p.y < 0.0f ? -of_i.y : of_i.y)),
                        as_float(as_int(p.z) + (p.z < 0.0f ? -of_i.z : of_i.z)));
  return (float3)(fabs(p.x) < origin ? p.x + float_scale * n.x : p_i.x,
                  fabs(p.y) < origin ? p.y + float_scale * n.y : p_i.y,
                  fabs(p.z) < origin ? p.z + float_scale * n.z : p_i.z);
}
