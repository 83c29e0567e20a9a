// Multiple-scattering energy compensation of GGX reflection (Kulla & Conty 2017,
// Revisiting Physically Based Shading at Imageworks). A single-scattering microfacet lobe
// loses the light that leaves after bouncing between microfacets: with F = 1 it reflects
// E(mu_o) = integral of f cos_i over the hemisphere, less than 1 at high roughness. The
// lobe f_ms = (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg)), E_avg = 2 integral of
// E(mu) mu dmu, returns exactly the missing 1 - E(mu_o); with Fresnel it is scaled by
// F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)), the light that escapes after two or
// more bounces when each bounce keeps F_avg, the hemispherical average of F.
//
// E and E_avg come from the table of the ggx_albedo scene buffer, computed on each device
// by the two table kernels below, which integrate the lobe's own sampling and evaluation
// (host/energy.cpp runs them before the first launch and caches the result beside the
// program binary). The table covers isotropic lobes; anisotropic ones use it at alpha =
// sqrt(ax ay), an approximation (albedo within a few percent of the exact compensation).

// The table's coordinates: glTF roughness r = sqrt(alpha), and y with y^2 = mu (1 + c) /
// (mu + c), c = 4 alpha. Near grazing E depends on mu / alpha: it rises steeply to 1 at
// mu = 0 and, for smooth lobes, has a narrow dip at mu ~ alpha; y spreads both over many
// nodes for every alpha. Nodes at y, r = i / (N - 1).
float energy_node(int i) { return (float)i / (float)(GGX_ALBEDO_N - 1); }

float energy_y(float mu, float alpha) {
  float c = 4.0f * alpha;
  return sqrt(mu * (1.0f + c) / (mu + c));
}

float energy_mu(float y, float alpha) {
  float c = 4.0f * alpha;
  return y * y * c / (1.0f + c - y * y);
}

// E(mu) with F = 1 and E5(mu) with F = (1 - wo.h)^5 by quadrature: the mean weight
// f cos_i / pdf of ggx_reflection_sample (times (1 - wo.h)^5 for E5) over an n x n
// midpoint grid of its random numbers, u.x = 1 - (1 - v)^3 crowding the points toward the
// rim of the visible-normal disk, where GGX's long tail lies (within 2e-4 of the
// converged integral at n = GGX_ALBEDO_QUADRATURE). Schlick's Fresnel term then gives the
// lobe's albedo f0 E + (f90 - f0) E5.
float2 energy_ggx_albedo_quadrature(Ggx g, float mu, uint n) {
  float3 wo = (float3)(sqrt(fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu);
  float2 sum = (float2)(0.0f);
  float weights = 0.0f;
  for (uint a = 0u; a < n; ++a) {
    float v = 1.0f - ((float)a + 0.5f) / (float)n;  // 1 - v of the comment
    float2 row = (float2)(0.0f);
    weights += 3.0f * v * v;
    for (uint b = 0u; b < n; ++b) {
      float2 u = (float2)(1.0f - v * v * v, ((float)b + 0.5f) / (float)n);
      float3 wi;
      float pdf, cos_oh;
      if (!ggx_reflection_sample(g, wo, u, &wi)) continue;
      float f = ggx_reflection_eval(g, wo, wi, &pdf, &cos_oh);
      if (pdf > 0.0f) {
        float w = f * wi.z / pdf;
        float m = 1.0f - cos_oh, m2 = m * m;
        row += (float2)(w, w * m2 * m2 * m);
      }
    }
    sum += 3.0f * v * v * row / (float)n;
  }
  return sum / weights;  // the weights' own sum, not their integral 1: no O(1 / n^2) bias
}

// Table entries (i, j): E(mu(y_i), r_j) and E5(mu_i = i / (N - 1), r_j). E5 has its nodes
// uniform in mu: for smooth lobes it is close to (1 - mu)^5 over the whole range of mu,
// which y would crowd into its last cell. The delta lobe at r = 0 reflects about the
// normal: E = 1, E5 = (1 - mu)^5. At y = 0 (grazing) E = 1: every reflection leaves and
// none is shadowed; E5 at mu = 0 is the quadrature just above grazing. Global size (N, N).
__kernel void energy_ggx_albedo_table(__global float* table, uint n) {
  int i = (int)get_global_id(0), j = (int)get_global_id(1);
  if (i >= GGX_ALBEDO_N || j >= GGX_ALBEDO_N) return;
  Ggx g = ggx_from_roughness(energy_node(j), 0.0f);
  float e = 1.0f, mu5 = energy_node(i), m = 1.0f - mu5, e5 = m * m * m * m * m;
  if (!ggx_is_delta(g)) {
    if (i > 0) e = energy_ggx_albedo_quadrature(g, energy_mu(energy_node(i), g.ax), n).x;
    e5 = energy_ggx_albedo_quadrature(g, fmax(mu5, 1e-4f), n).y;
  }
  table[j * GGX_ALBEDO_N + i] = fmin(e, 1.0f);
  table[GGX_ALBEDO_HALF + j * GGX_ALBEDO_N + i] = clamp(e5, 0.0f, 1.0f);
}

// The table looked up for one lobe seen from mu_o: the roughness cell, E(mu_o), E_avg and
// the same for E5. No table (compensation off) or a delta lobe: nothing to compensate,
// E = 1 (E5 is then unused).
typedef struct {
  __global const float* table;  // 0: no compensation
  float alpha;                  // isotropic alpha of the lobe
  int row;                      // roughness cell [row, row + 1] and the weight of row + 1
  float t;
  float e_o, e_avg;
  float e5_o, e5_avg;
} GgxEnergy;

// The coordinate of mu in part 0 (E: y) or part 1 (E5: mu itself), in [0, 1]
float energy_coordinate(int part, float mu, float alpha) { return part ? mu : energy_y(mu, alpha); }
float energy_coordinate_mu(int part, float x, float alpha) { return part ? x : energy_mu(x, alpha); }

// E(mu) (part 0) or E5(mu) (part 1) interpolated bilinearly in (coordinate, r)
float energy_lookup(const GgxEnergy* e, int part, float mu) {
  float x = clamp(energy_coordinate(part, mu, e->alpha), 0.0f, 1.0f) * (float)(GGX_ALBEDO_N - 1);
  int i = min((int)x, GGX_ALBEDO_N - 2);
  float s = x - (float)i;
  __global const float* lo = e->table + part * GGX_ALBEDO_HALF + e->row * GGX_ALBEDO_N + i;
  __global const float* hi = lo + GGX_ALBEDO_N;
  return mix(mix(lo[0], lo[1], s), mix(hi[0], hi[1], s), e->t);
}

float energy_albedo(const GgxEnergy* e, float mu) { return energy_lookup(e, 0, mu); }

// The lookup at row j exactly (no interpolation in roughness)
GgxEnergy energy_row(__global const float* table, int j) {
  GgxEnergy e;
  e.table = table;
  e.alpha = energy_node(j) * energy_node(j);
  e.row = min(j, GGX_ALBEDO_N - 2);
  e.t = (float)(j - e.row);
  e.e_o = e.e_avg = e.e5_o = e.e5_avg = 1.0f;
  return e;
}

// E_avg(r_j) = 2 integral of E mu dmu over the E that energy_albedo interpolates, so that
// f_ms gives back 1 - E(mu_o) as looked up (exactly at the nodes of r, closely between
// them): 8-point Gauss-Legendre in mu between the mu of consecutive nodes; the same for E5.
// E_avg of the delta row is 1. Runs after energy_ggx_albedo_table; global size (N, 2).
__kernel void energy_ggx_average_table(__global float* table) {
  const float x[4] = {0.1834346424956498f, 0.5255324099163290f, 0.7966664774136267f, 0.9602898564975363f};
  const float w[4] = {0.3626837833783620f, 0.3137066458778873f, 0.2223810344533745f, 0.1012285362903763f};
  int j = (int)get_global_id(0), part = (int)get_global_id(1);
  if (j >= GGX_ALBEDO_N || part > 1) return;
  GgxEnergy e = energy_row(table, j);
  float sum = 0.0f;
  for (int i = 0; i + 1 < GGX_ALBEDO_N; ++i) {
    float a = energy_coordinate_mu(part, energy_node(i), e.alpha);
    float b = energy_coordinate_mu(part, energy_node(i + 1), e.alpha);
    float c = 0.5f * (a + b), h = 0.5f * (b - a), segment = 0.0f;
    for (int k = 0; k < 4; ++k) {
      float lo = c - h * x[k], hi = c + h * x[k];
      segment += w[k] * (lo * energy_lookup(&e, part, lo) + hi * energy_lookup(&e, part, hi));
    }
    sum += 2.0f * h * segment;
  }
  if (j == 0 && part == 0) sum = 1.0f;
  table[part * GGX_ALBEDO_HALF + GGX_ALBEDO_N * GGX_ALBEDO_N + j] = fmin(sum, 1.0f);
}

GgxEnergy energy_ggx(__global const float* table, Ggx g, float mu_o) {
  GgxEnergy e;
  e.table = ggx_is_delta(g) ? 0 : table;
  e.alpha = sqrt(g.ax * g.ay);
  e.row = 0;
  e.t = 0.0f;
  e.e_o = e.e_avg = e.e5_o = e.e5_avg = 1.0f;
  if (!e.table) return e;
  float x = clamp(sqrt(e.alpha), 0.0f, 1.0f) * (float)(GGX_ALBEDO_N - 1);
  e.row = min((int)x, GGX_ALBEDO_N - 2);
  e.t = x - (float)e.row;
  __global const float* avg = table + GGX_ALBEDO_N * GGX_ALBEDO_N + e.row;
  e.e_avg = mix(avg[0], avg[1], e.t);
  e.e5_avg = mix(avg[GGX_ALBEDO_HALF], avg[GGX_ALBEDO_HALF + 1], e.t);
  e.e_o = energy_albedo(&e, mu_o);
  e.e5_o = energy_lookup(&e, 1, mu_o);
  return e;
}

// f_ms without its colour: (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg)), wi above
float energy_ms(const GgxEnergy* e, float mu_i) {
  if (!e->table || mu_i <= 0.0f || e->e_avg >= 1.0f) return 0.0f;
  return (1.0f - e->e_o) * (1.0f - energy_albedo(e, mu_i)) * INV_PI_F / (1.0f - e->e_avg);
}

// Albedo of f_ms from wo: (1 - E(mu_o)) (times the colour of energy_ms_fresnel)
float energy_ms_albedo(const GgxEnergy* e) { return e->table ? 1.0f - e->e_o : 0.0f; }

// The colour of f_ms for a Fresnel term of hemispherical average f_avg:
// F_avg^2 E_avg / (1 - F_avg (1 - E_avg))
float3 energy_ms_fresnel(const GgxEnergy* e, float3 f_avg) {
  return f_avg * f_avg * e->e_avg / (1.0f - f_avg * (1.0f - e->e_avg));
}

// 2 integral of Schlick(f0, f90, mu) mu dmu = f0 + (f90 - f0) / 21
float3 energy_schlick_average(float3 f0, float3 f90) { return f0 + (f90 - f0) * (1.0f / 21.0f); }

// 2 integral of F mu dmu for the exact conductor Fresnel, by 6-point Gauss-Legendre
// quadrature in mu (within 5e-5 of the integral for the conductors of the presets)
float3 energy_conductor_average(float3 eta, float3 k) {
  const float x[3] = {0.2386191860831969f, 0.6612093864662645f, 0.9324695142031521f};
  const float w[3] = {0.4679139345726910f, 0.3607615730481386f, 0.1713244923791704f};
  float3 sum = (float3)(0.0f);
  for (int n = 0; n < 3; ++n) {
    float lo = 0.5f * (1.0f - x[n]), hi = 0.5f * (1.0f + x[n]);
    sum += w[n] * (lo * fresnel_conductor(lo, eta, k) + hi * fresnel_conductor(hi, eta, k));
  }
  return sum;
}
