// Sampling routines, each with its pdf (Pharr, Jakob and Humphreys, Physically Based
// Rendering, 4th ed., 2023, appendix A.5).

#define PI_F 3.14159265358979323846f
#define INV_PI_F 0.31830988618379067154f

// sin(2 pi u) and, in *cos_phi, cos(2 pi u): sinpi/cospi reduce their argument exactly and
// cheaply (PoCL's sincos of 2 pi u calls a general argument reduction: 2.4 % more render
// kernel instructions on the Cornell box)
float sincos_turn(float u, float* cos_phi) {
  *cos_phi = cospi(2.0f * u);
  return sinpi(2.0f * u);
}

// Cosine-weighted hemisphere around +z: theta = acos(sqrt(v)), phi = 2 pi u
float3 sample_cosine_hemisphere(float u, float v) {
  float cos_theta = sqrt(v);
  float sin_theta = sqrt(1.0f - v);
  float cos_phi, sin_phi = sincos_turn(u, &cos_phi);
  return (float3)(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta);
}

float sample_cosine_hemisphere_pdf(float cos_theta) { return fmax(cos_theta, 0.0f) * INV_PI_F; }

// Uniform direction on the unit sphere: z = 1 - 2v, phi = 2 pi u
float3 sample_uniform_sphere(float u, float v) {
  float z = 1.0f - 2.0f * v;
  float r = sqrt(fmax(0.0f, 1.0f - z * z));
  float cos_phi, sin_phi = sincos_turn(u, &cos_phi);
  return (float3)(r * cos_phi, r * sin_phi, z);
}

float sample_uniform_sphere_pdf(void) { return 0.25f * INV_PI_F; }

// Uniform point on a triangle (v0, v1, v2): s = 1 - sqrt(u), t = v sqrt(u) (Turk 1990),
// x = s v0 + t v1 + (1-s-t) v2, returned as Hit's barycentric weights (b1, b2) = (t, 1-s-t)
// of v1 and v2, so that x = (1 - b1 - b2) v0 + b1 v1 + b2 v2. The pdf is 1 / area.
float2 sample_triangle(float u, float v) {
  float su = sqrt(u);
  float s = 1.0f - su, t = v * su;
  return (float2)(t, 1.0f - s - t);
}

// Index chosen by the alias table `bins` (n bins) for a uniform 32-bit x: the high 32 bits
// of x n pick a bin, the low 32 bits decide between the bin and its alias. O(1), and each
// x maps to one index, so the host counts the exact probabilities (scene_compiler.cpp).
uint sample_discrete_alias(__global const AliasBin* bins, uint n, uint x) {
  uint bin = mul_hi(x, n);
  AliasBin b = bins[bin];
  return x * n < b.threshold ? bin : b.alias;
}

// Uniform point on the unit disk by Shirley and Chiu's concentric mapping (1997, A
// Low Distortion Map Between Disk and Square): the square [-1, 1]^2 is cut into four
// triangles by its diagonals, and each square ring of half-width r maps to the circle of
// radius r, keeping the area fractions. The pdf is 1 / pi.
float2 sample_concentric_disk(float u, float v) {
  float a = 2.0f * u - 1.0f, b = 2.0f * v - 1.0f;
  if (a == 0.0f && b == 0.0f) return (float2)(0.0f);
  float r, phi;
  if (fabs(a) > fabs(b)) {
    r = a;
    phi = (0.25f * PI_F) * (b / a);
  } else {
    r = b;
    phi = 0.5f * PI_F - (0.25f * PI_F) * (a / b);
  }
  float cos_phi, sin_phi = sincos(phi, &cos_phi);
  return (float2)(r * cos_phi, r * sin_phi);
}
