// Rays, frames and robust ray offsets.

typedef struct {
  float3 org;
  float3 dir;
} Ray;

float3 load3(__global const float* p) { return vload3(0, p); }

float max_component(float3 v) { return fmax(v.x, fmax(v.y, v.z)); }

float luminance(float3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

bool all_finite(float3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

// Orthonormal basis around unit n (Duff et al. 2017, Building an Orthonormal Basis, Revisited)
void frame_from_normal(float3 n, float3* t, float3* b) {
  float sign = n.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (sign + n.z);
  float c = n.x * n.y * a;
  *t = (float3)(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  *b = (float3)(c, sign + n.y * n.y * a, -n.y);
}

float3 frame_to_world(float3 v, float3 n) {
  float3 t, b;
  frame_from_normal(n, &t, &b);
  return v.x * t + v.y * b + v.z * n;
}

// Move p off its surface along the geometric normal n by a few ulps, on the side of n
// (Waechter and Binder 2019, A Fast and Robust Method for Avoiding Self-Intersection).
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
