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
// program binary). Anisotropic lobes (ax != ay) have E(wo) depending on the azimuth of wo as
// well: a table of its own over (mu, azimuth, major roughness, ratio), whose lookups take
// directions, so f_ms stays reciprocal and returns exactly the looked-up 1 - E(wo). That
// table and its lookups are compiled in with CD_FEATURE_ANISOTROPY; a kernel without it
// looks anisotropic lobes up in the isotropic table at alpha = sqrt(ax ay) (the test
// program's lobes; a scene's kernel has the feature whenever a material is anisotropic).

// The table's coordinates: glTF roughness r = sqrt(alpha), and y with y^2 = mu (1 + c) /
// (mu + c), c = 4 alpha. Near grazing E depends on mu / alpha: it rises steeply to 1 at
// mu = 0 and, for smooth lobes, has a narrow dip at mu ~ alpha; y spreads both over many
// nodes for every alpha. Nodes at y, r = i / (N - 1).
float energy_node(int i) { return (float)i / (float)(GGX_ALBEDO_N - 1); }

// The cell [*cell, *cell + 1] of x in [0, 1] on `nodes` uniform nodes and the weight of *cell + 1
void energy_cell_of(float x, int nodes, int* cell, float* weight) {
  float z = clamp(x, 0.0f, 1.0f) * (float)(nodes - 1);
  *cell = min((int)z, nodes - 2);
  *weight = z - (float)*cell;
}

// The cell of node j itself on `nodes` nodes: [j, j + 1] with weight 0, or for the last node
// the last cell with weight 1 (a lookup exactly at a node, no interpolation)
void energy_node_cell(int j, int nodes, int* cell, float* weight) {
  *cell = min(j, nodes - 2);
  *weight = (float)(j - *cell);
}

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
float2 energy_ggx_albedo_quadrature_wo(Ggx g, float3 wo, uint n) {
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

// The same seen from mu in the xz-plane
float2 energy_ggx_albedo_quadrature(Ggx g, float mu, uint n) {
  return energy_ggx_albedo_quadrature_wo(g, (float3)(sqrt(fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu), n);
}

// Table entries (i, j): E(mu(y_i), r_j) and E5(mu_i = i / (N - 1), r_j). E5 has its nodes
// uniform in mu: for smooth lobes it is close to (1 - mu)^5 over the whole range of mu,
// which y would crowd into its last cell. The delta lobe at r = 0 reflects about the
// normal: E = 1, E5 = (1 - mu)^5. At y = 0 (grazing) E = 1: every reflection leaves and
// none is shadowed; E5 at mu = 0 is the quadrature just above grazing. Global size (N, N).
#if CD_TABLE_KERNELS
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
#endif

// The table looked up for one lobe seen from wo: the roughness cell, E(wo), E_avg and the
// same for E5. No table (compensation off) or a delta lobe: nothing to compensate, E = 1
// (E5 is then unused). An anisotropic lobe also has its ratio cell, and its lookups take
// the azimuth from its major axis.
typedef struct {
  __global const float* table;  // 0: no compensation
  float alpha;                  // isotropic alpha of the lobe
  int row;                      // roughness cell [row, row + 1] and the weight of row + 1
  float t;
#if CD_FEATURE_ANISOTROPY
  bool aniso;    // ax != ay: the anisotropic table, cells (row, t) in sqrt(a1) and (qrow, tq)
  bool swap;     // its major axis is the frame's y
  float a1, a0;  // major and minor alpha
  int qrow;      // ratio cell in sqrt(a0 / a1)
  float tq;
#endif
  float e_o, e_avg;
  float e5_o, e5_avg;
} GgxEnergy;

// What a lookup needs of a direction w (local frame): the direction itself with
// CD_FEATURE_ANISOTROPY, else only its cosine mu = w.z. energy_at(w) makes one from w,
// energy_dir(mu) one at cosine mu (in the xz-plane), energy_dir_mu(d) gives back mu.
#if CD_FEATURE_ANISOTROPY
typedef float3 EnergyDir;
#define energy_at(w) (w)
#define energy_dir_mu(d) ((d).z)
EnergyDir energy_dir(float mu) { return (float3)(sqrt(fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu); }
#else
typedef float EnergyDir;
#define energy_at(w) ((w).z)
#define energy_dir_mu(d) (d)
#define energy_dir(mu) (mu)
#endif

// The coordinate of mu in part 0 (E: y) or part 1 (E5: mu itself), in [0, 1]
float energy_coordinate(int part, float mu, float alpha) { return part ? mu : energy_y(mu, alpha); }
float energy_coordinate_mu(int part, float x, float alpha) { return part ? x : energy_mu(x, alpha); }

#if CD_FEATURE_ANISOTROPY
// The anisotropic table: t = sin^2 of the azimuth from the major axis (nodes uniform in t:
// E is a smooth even function of the azimuth, so a smooth function of cos 2 phi = 1 - 2 t)
// and the alpha seen along it, sqrt(a1^2 cos^2 + a0^2 sin^2), which sets the y coordinate
// as alpha does for isotropic lobes
float energy_aniso_alpha(float a1, float a0, float t) { return sqrt(a1 * a1 * (1.0f - t) + a0 * a0 * t); }

__global const float* energy_aniso_entry(__global const float* table, int part, int i, int l, int j, int k) {
  return table + GGX_ANISO_OFFSET + part * GGX_ANISO_PART + ((k * GGX_ANISO_R + j) * GGX_ANISO_P + l) * GGX_ANISO_N + i;
}

__global const float* energy_aniso_average(__global const float* table, int part, int j, int k) {
  return table + GGX_ANISO_OFFSET + part * GGX_ANISO_PART + GGX_ANISO_ROWS * GGX_ANISO_N + k * GGX_ANISO_R + j;
}

// E (part 0) or E5 (part 1) at (t, mu): bilinear in (coordinate, t) at each of the four
// (roughness, ratio) corners, weighted by the lobe's cells
float energy_aniso_lookup_at(const GgxEnergy* e, int part, float t, float mu) {
  int i, l;
  float s, sp;
  energy_cell_of(energy_coordinate(part, mu, energy_aniso_alpha(e->a1, e->a0, t)), GGX_ANISO_N, &i, &s);
  energy_cell_of(t, GGX_ANISO_P, &l, &sp);
  float sum = 0.0f;
  for (int dk = 0; dk < 2; ++dk)
    for (int dj = 0; dj < 2; ++dj) {
      float w = (dk ? e->tq : 1.0f - e->tq) * (dj ? e->t : 1.0f - e->t);
      __global const float* c = energy_aniso_entry(e->table, part, i, l, e->row + dj, e->qrow + dk);
      sum += w * mix(mix(c[0], c[1], s), mix(c[GGX_ANISO_N], c[GGX_ANISO_N + 1], s), sp);
    }
  return sum;
}

// sin^2 of the azimuth of w from a lobe's major axis, the frame's x (its y if `swap`); 0 at
// the normal
float energy_aniso_t_from(bool swap, float3 w) {
  float c = swap ? w.y : w.x, s = swap ? w.x : w.y;
  float r2 = c * c + s * s;
  return r2 > 0.0f ? s * s / r2 : 0.0f;
}

float energy_aniso_t(const GgxEnergy* e, float3 w) { return energy_aniso_t_from(e->swap, w); }
#endif

// E(mu) (part 0) or E5(mu) (part 1) of an isotropic lobe: bilinear in (coordinate, r)
float energy_lookup_mu(const GgxEnergy* e, int part, float mu) {
  int i;
  float s;
  energy_cell_of(energy_coordinate(part, mu, e->alpha), GGX_ALBEDO_N, &i, &s);
  __global const float* lo = e->table + part * GGX_ALBEDO_HALF + e->row * GGX_ALBEDO_N + i;
  __global const float* hi = lo + GGX_ALBEDO_N;
  return mix(mix(lo[0], lo[1], s), mix(hi[0], hi[1], s), e->t);
}

// E(w) (part 0) or E5(w) (part 1) of any lobe
float energy_lookup(const GgxEnergy* e, int part, EnergyDir w) {
#if CD_FEATURE_ANISOTROPY
  if (e->aniso) return energy_aniso_lookup_at(e, part, energy_aniso_t(e, w), w.z);
#endif
  return energy_lookup_mu(e, part, energy_dir_mu(w));
}

float energy_albedo(const GgxEnergy* e, EnergyDir w) { return energy_lookup(e, 0, w); }

// An isotropic lookup of alpha in roughness cell (row, t), nothing looked up yet (E = 1)
GgxEnergy energy_cell(__global const float* table, float alpha, int row, float t) {
  GgxEnergy e;
  e.table = table;
  e.alpha = alpha;
  e.row = row;
  e.t = t;
#if CD_FEATURE_ANISOTROPY
  e.aniso = e.swap = false;
  e.a1 = e.a0 = e.alpha;
  e.qrow = 0;
  e.tq = 0.0f;
#endif
  e.e_o = e.e_avg = e.e5_o = e.e5_avg = 1.0f;
  return e;
}

// The lookup at row j exactly (no interpolation in roughness)
GgxEnergy energy_row(__global const float* table, int j) {
  int row;
  float t;
  energy_node_cell(j, GGX_ALBEDO_N, &row, &t);
  return energy_cell(table, energy_node(j) * energy_node(j), row, t);
}

// 8-point Gauss-Legendre nodes and weights on [-1, 1] (half of them: +-x)
#define ENERGY_GL_X \
  { 0.1834346424956498f, 0.5255324099163290f, 0.7966664774136267f, 0.9602898564975363f }
#define ENERGY_GL_W \
  { 0.3626837833783620f, 0.3137066458778873f, 0.2223810344533745f, 0.1012285362903763f }

// E_avg(r_j) = 2 integral of E mu dmu over the E that energy_albedo interpolates, so that
// f_ms gives back 1 - E(mu_o) as looked up (exactly at the nodes of r, closely between
// them): 8-point Gauss-Legendre in mu between the mu of consecutive nodes; the same for E5.
// E_avg of the delta row is 1. Runs after energy_ggx_albedo_table; global size (N, 2).
// The vector type hint keeps Intel's CPU compiler from vectorizing it across work-items:
// vectorized, it returned wrong averages for most rows (E5_avg of the smoothest lobes 0.91
// instead of 2 integral of (1 - mu)^5 mu dmu = 1/21), and f_ms divides by 1 - E_avg.
// A table kernel runs once per device, so its speed does not matter; PoCL's tables are
// unchanged by the hint.
#if CD_TABLE_KERNELS
__kernel __attribute__((vec_type_hint(float4))) void energy_ggx_average_table(__global float* table) {
  const float x[4] = ENERGY_GL_X;
  const float w[4] = ENERGY_GL_W;
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
      segment += w[k] * (lo * energy_lookup(&e, part, energy_dir(lo)) + hi * energy_lookup(&e, part, energy_dir(hi)));
    }
    sum += 2.0f * h * segment;
  }
  if (j == 0 && part == 0) sum = 1.0f;
  table[part * GGX_ALBEDO_HALF + GGX_ALBEDO_N * GGX_ALBEDO_N + j] = fmin(sum, 1.0f);
}
#endif

#if CD_FEATURE_ANISOTROPY
// The anisotropic cells of a lobe with ax != ay, from its cell `iso` (energy_cell: table and alpha)
GgxEnergy energy_ggx_aniso(GgxEnergy iso, Ggx g, float3 wo) {
  GgxEnergy e = iso;
  e.aniso = true;
  e.swap = g.ay > g.ax;
  e.a1 = fmax(g.ax, g.ay);
  e.a0 = fmin(g.ax, g.ay);
  energy_cell_of(sqrt(e.a1), GGX_ANISO_R, &e.row, &e.t);
  energy_cell_of(sqrt(e.a0 / e.a1), GGX_ANISO_Q, &e.qrow, &e.tq);
  float avg[2];
  for (int part = 0; part < 2; ++part) {
    __global const float* lo = energy_aniso_average(e.table, part, e.row, e.qrow);
    __global const float* hi = lo + GGX_ANISO_R;
    avg[part] = mix(mix(lo[0], lo[1], e.t), mix(hi[0], hi[1], e.t), e.tq);
  }
  e.e_avg = avg[0];
  e.e5_avg = avg[1];
  e.e_o = energy_lookup(&e, 0, wo);
  e.e5_o = energy_lookup(&e, 1, wo);
  return e;
}
#endif

// The table looked up for an isotropic lobe seen from mu_o (a lobe known to be isotropic, such
// as the clear coat, whose lookups then take mu alone: energy_lookup_mu)
GgxEnergy energy_ggx_mu(__global const float* table, Ggx g, float mu_o) {
  GgxEnergy e = energy_cell(ggx_is_delta(g) ? 0 : table, sqrt(g.ax * g.ay), 0, 0.0f);
  if (!e.table) return e;
  energy_cell_of(sqrt(e.alpha), GGX_ALBEDO_N, &e.row, &e.t);
  __global const float* avg = table + GGX_ALBEDO_N * GGX_ALBEDO_N + e.row;
  e.e_avg = mix(avg[0], avg[1], e.t);
  e.e5_avg = mix(avg[GGX_ALBEDO_HALF], avg[GGX_ALBEDO_HALF + 1], e.t);
  e.e_o = energy_lookup_mu(&e, 0, mu_o);
  e.e5_o = energy_lookup_mu(&e, 1, mu_o);
  return e;
}

// The table looked up for any lobe seen from wo
GgxEnergy energy_ggx(__global const float* table, Ggx g, EnergyDir wo) {
#if CD_FEATURE_ANISOTROPY
  // An anisotropic lobe overwrites every value the isotropic lookup would compute
  if (g.ax != g.ay && table && !ggx_is_delta(g))
    return energy_ggx_aniso(energy_cell(table, sqrt(g.ax * g.ay), 0, 0.0f), g, wo);
#endif
  return energy_ggx_mu(table, g, energy_dir_mu(wo));
}

#if CD_FEATURE_ANISOTROPY
// The anisotropic lobe at node (j, k): major alpha a1 = r_j^2 along x, minor
// a0 = max(q_k^2 a1, GGX_DELTA_ALPHA); j = 0 is the delta lobe
Ggx energy_aniso_node_ggx(int j, int k) {
  float r = (float)j / (float)(GGX_ANISO_R - 1), q = (float)k / (float)(GGX_ANISO_Q - 1);
  Ggx g;
  g.ax = r * r;
  g.ay = fmin(g.ax, fmax(q * q * g.ax, GGX_DELTA_ALPHA));
  return g;
}

// Point q < energy_aniso_average_points(p, n) of the quadrature of E_avg = (1 / pi)
// integral of E cos over the hemisphere for a lobe (a1, a0) whose table has p azimuth nodes
// and n nodes in part's coordinate (part 0: y at the alpha seen along the azimuth, kept at
// least alpha_floor): 8-point Gauss-Legendre in the azimuth phi in [0, pi / 2] within each
// cell of t = sin^2 phi, and in mu between the mu of consecutive nodes. Returns (t, mu,
// weight), the weight including mu, so that E_avg = sum of weight E(t, mu).
int energy_aniso_average_points(int p, int n) { return 64 * (p - 1) * (n - 1); }

float3 energy_aniso_average_point(int q, int p, int n, float a1, float a0, int part, float alpha_floor) {
  const float x[4] = ENERGY_GL_X;
  const float w[4] = ENERGY_GL_W;
  int qm = q % 8, i = (q / 8) % (n - 1), kp = (q / (8 * (n - 1))) % 8, l = q / (64 * (n - 1));
  float p0 = asin(sqrt((float)l / (float)(p - 1))), p1 = asin(sqrt((float)(l + 1) / (float)(p - 1)));
  float pc = 0.5f * (p0 + p1), ph = 0.5f * (p1 - p0);
  float sp = sin(pc + (kp < 4 ? -ph * x[kp] : ph * x[kp - 4])), t = sp * sp;
  float alpha = fmax(energy_aniso_alpha(a1, a0, t), alpha_floor);
  float a = energy_coordinate_mu(part, (float)i / (float)(n - 1), alpha);
  float b = energy_coordinate_mu(part, (float)(i + 1) / (float)(n - 1), alpha);
  float c = 0.5f * (a + b), h = 0.5f * (b - a), mu = c + (qm < 4 ? -h * x[qm] : h * x[qm - 4]);
  return (float3)(t, mu, ph * w[kp & 3] * 2.0f * h * w[qm & 3] * mu / (0.5f * PI_F));
}

// Table entries (i, l, j, k) as energy_ggx_albedo_table's, seen from the azimuth with
// sin^2 = t_l; global size (N, P, R Q). Without `exact`, the isotropic table's values at
// alpha = sqrt(ax ay) instead of the quadrature (runs after the isotropic table and its averages).
#if CD_TABLE_KERNELS
__kernel void energy_ggx_aniso_table(__global float* table, uint n, uint exact) {
  int i = (int)get_global_id(0), l = (int)get_global_id(1), jk = (int)get_global_id(2);
  if (i >= GGX_ANISO_N || l >= GGX_ANISO_P || jk >= GGX_ANISO_R * GGX_ANISO_Q) return;
  int j = jk % GGX_ANISO_R, k = jk / GGX_ANISO_R;
  Ggx g = energy_aniso_node_ggx(j, k);
  float t = (float)l / (float)(GGX_ANISO_P - 1), c = sqrt(1.0f - t), sn = sqrt(t);
  float y = (float)i / (float)(GGX_ANISO_N - 1);
  float e = 1.0f, mu5 = y, m = 1.0f - mu5, e5 = m * m * m * m * m;
  if (!ggx_is_delta(g) && !exact) {
    Ggx iso;
    iso.ax = iso.ay = sqrt(g.ax * g.ay);
    GgxEnergy approx = energy_ggx(table, iso, energy_dir(1.0f));
    if (i > 0) e = energy_albedo(&approx, energy_dir(energy_mu(y, energy_aniso_alpha(g.ax, g.ay, t))));
    e5 = energy_lookup(&approx, 1, energy_dir(mu5));
  } else if (!ggx_is_delta(g)) {
    if (i > 0) {
      float mu = energy_mu(y, energy_aniso_alpha(g.ax, g.ay, t)), st = sqrt(fmax(0.0f, 1.0f - mu * mu));
      e = energy_ggx_albedo_quadrature_wo(g, (float3)(st * c, st * sn, mu), n).x;
    }
    float mu = fmax(mu5, 1e-4f), st = sqrt(fmax(0.0f, 1.0f - mu * mu));
    e5 = energy_ggx_albedo_quadrature_wo(g, (float3)(st * c, st * sn, mu), n).y;
  }
  int at = ((k * GGX_ANISO_R + j) * GGX_ANISO_P + l) * GGX_ANISO_N + i;
  table[GGX_ANISO_OFFSET + at] = fmin(e, 1.0f);
  table[GGX_ANISO_OFFSET + GGX_ANISO_PART + at] = clamp(e5, 0.0f, 1.0f);
}
#endif

// The lookup at node (j, k) exactly
GgxEnergy energy_aniso_row(__global const float* table, int j, int k) {
  Ggx g = energy_aniso_node_ggx(j, k);
  GgxEnergy e = energy_row(table, 0);
  e.aniso = true;
  e.a1 = g.ax;
  e.a0 = g.ay;
  e.alpha = sqrt(g.ax * g.ay);
  energy_node_cell(j, GGX_ANISO_R, &e.row, &e.t);
  energy_node_cell(k, GGX_ANISO_Q, &e.qrow, &e.tq);
  return e;
}

// E_avg(j, k) = (1 / pi) integral of E cos over the hemisphere as energy_lookup interpolates
// it (energy_aniso_average_point). Global size (R Q, 2).
#if CD_TABLE_KERNELS
__kernel void energy_ggx_aniso_average_table(__global float* table) {
  int jk = (int)get_global_id(0), part = (int)get_global_id(1);
  if (jk >= GGX_ANISO_R * GGX_ANISO_Q || part > 1) return;
  int j = jk % GGX_ANISO_R, k = jk / GGX_ANISO_R;
  GgxEnergy e = energy_aniso_row(table, j, k);
  float total = 0.0f;
  for (int q = 0; q < energy_aniso_average_points(GGX_ANISO_P, GGX_ANISO_N); ++q) {
    float3 pt = energy_aniso_average_point(q, GGX_ANISO_P, GGX_ANISO_N, e.a1, e.a0, part, 0.0f);
    total += pt.z * energy_aniso_lookup_at(&e, part, pt.x, pt.y);
  }
  if (j == 0 && part == 0) total = 1.0f;
  *(__global float*)energy_aniso_average(table, part, j, k) = fmin(total, 1.0f);
}
#endif
#endif

// f_ms without its colour from E(wi) = e_i already looked up (table bound, E_avg < 1, wi above)
float energy_ms_of(const GgxEnergy* e, float e_i) {
  return (1.0f - e->e_o) * (1.0f - e_i) * INV_PI_F / (1.0f - e->e_avg);
}

// f_ms without its colour: (1 - E(wo)) (1 - E(wi)) / (pi (1 - E_avg)), wi above
float energy_ms(const GgxEnergy* e, EnergyDir wi) {
  if (!e->table || energy_dir_mu(wi) <= 0.0f || e->e_avg >= 1.0f) return 0.0f;
  return energy_ms_of(e, energy_albedo(e, wi));
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
