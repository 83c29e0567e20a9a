// Multiple-scattering energy compensation of rough dielectric interfaces (the idea of
// Kulla & Conty 2017, Revisiting Physically Based Shading at Imageworks, for reflection
// plus transmission). Radiance crossing into a denser medium is scaled by 1 / eta^2, so the
// quantity that is reciprocal and conserved is X(wo, wi) = f(wo, wi) (n_i / n_o)^2, n_i and
// n_o the indices on wi's and wo's sides: its albedo E_s(mu) = integral of X |cos_i| over
// the sphere is 1 for an ideal interface seen from either side s (s = 0: eta >= 1, the
// rarer side; s = 1: eta < 1, total internal reflection included). A single-scattering
// microfacet interface has E_s < 1. Reciprocity holds for f(wo, wi) / n_o^2 (Walter et al.
// 2007's BTDF has it), i.e. for X(wo, wi) / n_i^2. The compensation adds, with
// A_s = 1 - E_s,avg and n = the denser side's index over the rarer one's,
//   X_ms(wo, wi) = k (1 - E_s(mu_o)) (1 - E_t(mu_i)) / pi,
// s and t the sides of wo and wi, k = a_s on reflection, c n^2 on transmission from side 0
// and c from side 1: k / n_i^2 is symmetric, and X_ms returns exactly 1 - E_s(mu_o) when
//   a_0 A_0 + c n^2 A_1 = 1,  a_1 A_1 + c A_0 = 1.
// The free c sets the split: from the rarer side a share 1 - F_avg (the interface's
// average transmittance) of the missing light is transmitted, c = (1 - F_avg) / (n^2 A_1),
// kept below 1 / A_0 so that a_1 >= 0. A thin-walled sheet has the same medium on both sides:
// its reflection and straight-through lobes share one geometry, so with any Fresnel split
// its single-scattering albedo is the GGX table's E (F = 1); the missing light is split by
// the sheet's average reflectance R'_avg: a = R'_avg / A, c = (1 - R'_avg) / A.
//
// E_s(mu, roughness, eta) comes from the dielectric part of the ggx_albedo buffer, computed
// by the table kernels below from the lobe's own visible-normal sampling (as energy.cl does
// for reflection). Lookups are trilinear in (y, roughness, eta). Anisotropic lobes (with
// CD_FEATURE_ANISOTROPY) have a table of their own over the azimuth and the two alphas too,
// as energy.cl's anisotropic GGX table, at fewer nodes.

// The eta coordinate: x = 2 (eta - 1) / (eta + 1) for eta >= 1 (1 / eta on side 1); node
// k of f is eta = (1 + x / 2) / (1 - x / 2), from 1 (kept at 1.01: an interface of eta 1
// refracts nothing) to 3
float energy_dielectric_eta_node_of(int k, int f) {
  float t = 0.5f * (float)k / (float)(f - 1);
  return fmax((1.0f + t) / (1.0f - t), 1.01f);
}

float energy_dielectric_eta_node(int k) { return energy_dielectric_eta_node_of(k, DIEL_ALBEDO_F); }

float energy_dielectric_eta_x(float eta) {
  float e = eta >= 1.0f ? eta : 1.0f / eta;
  return clamp(2.0f * (e - 1.0f) / (e + 1.0f), 0.0f, 1.0f);
}

float energy_dielectric_r_node(int j) { return (float)j / (float)(DIEL_ALBEDO_R - 1); }
float energy_dielectric_y_node(int i) { return (float)i / (float)(DIEL_ALBEDO_N - 1); }

// E(wo) of the interface (eta seen from wo) by quadrature over the visible normals h, as
// energy_ggx_albedo_quadrature does: each h reflects with F(wo.h) and refracts with
// 1 - F, and the weight X |cos_i| / pdf of either is G(wo, wi) / G1(wo)
float energy_dielectric_quadrature_wo(Ggx g, float eta, float3 wo, uint n) {
  float lo = ggx_lambda(g, wo);
  float sum = 0.0f, weights = 0.0f;
  for (uint a = 0u; a < n; ++a) {
    float v = 1.0f - ((float)a + 0.5f) / (float)n;
    float row = 0.0f;
    weights += 3.0f * v * v;
    for (uint b = 0u; b < n; ++b) {
      float2 u = (float2)(1.0f - v * v * v, ((float)b + 0.5f) / (float)n);
      float3 h = ggx_sample_visible(g, wo, u), wi;
      float f = fresnel_dielectric(dot(wo, h), eta);
      wi = fresnel_reflect(wo, h);
      if (wi.z > 0.0f) row += f * (1.0f + lo) / (1.0f + lo + ggx_lambda(g, wi));
      if (f < 1.0f && fresnel_refract(wo, h, eta, &wi) && wi.z < 0.0f)
        row += (1.0f - f) * (1.0f + lo) / (1.0f + lo + ggx_lambda(g, wi));
    }
    sum += 3.0f * v * v * row / (float)n;
  }
  return sum / weights;
}

// The same at cosine mu (wo in the xz-plane)
float energy_dielectric_quadrature(Ggx g, float eta, float mu, uint n) {
  return energy_dielectric_quadrature_wo(g, eta, (float3)(sqrt(fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu), n);
}

// Entry (i, j, k + F side): E at y_i, roughness r_j, eta node k on side `side`. The delta
// row (r = 0) is an ideal interface: E = 1. Global size (N, R, 2 F).
#if CD_TABLE_KERNELS
__kernel void energy_dielectric_albedo_table(__global float* table, uint n) {
  int i = (int)get_global_id(0), j = (int)get_global_id(1), ks = (int)get_global_id(2);
  if (i >= DIEL_ALBEDO_N || j >= DIEL_ALBEDO_R || ks >= 2 * DIEL_ALBEDO_F) return;
  int side = ks / DIEL_ALBEDO_F, k = ks % DIEL_ALBEDO_F;
  Ggx g = ggx_from_roughness(energy_dielectric_r_node(j), 0.0f);
  float eta = energy_dielectric_eta_node(k);
  if (side) eta = 1.0f / eta;
  float e = 1.0f;
  if (!ggx_is_delta(g))
    e = energy_dielectric_quadrature(g, eta, fmax(energy_mu(energy_dielectric_y_node(i), g.ax), 1e-4f), n);
  table[DIEL_ALBEDO_OFFSET + ((side * DIEL_ALBEDO_F + k) * DIEL_ALBEDO_R + j) * DIEL_ALBEDO_N + i] = fmin(e, 1.0f);
}
#endif

// The table looked up for one interface (eta seen from wo): the roughness and eta cells,
// E_s(mu_o), and the averages of both sides
typedef struct {
  __global const float* table;  // 0: no compensation
  float alpha;
  int row, col;  // roughness cell [row, row + 1], eta cell [col, col + 1]
  float t, s;    // the weights of row + 1 and col + 1
  int side;      // wo's side
#if CD_FEATURE_ANISOTROPY
  bool aniso;    // ax != ay: the anisotropic table, row in sqrt(a1), col in its eta nodes
  bool swap;     // the major axis is the frame's y
  float a1, a0;  // major and minor alpha
  int qrow;      // ratio cell in (a0 / a1)^(1/4) and the weight of qrow + 1
  float tq;
#endif
} DielectricEnergy;

DielectricEnergy energy_dielectric_cells(__global const float* table, Ggx g, float eta) {
  DielectricEnergy d;
  d.table = table;
  d.alpha = sqrt(g.ax * g.ay);
  d.side = eta < 1.0f;
#if CD_FEATURE_ANISOTROPY
  d.aniso = g.ax != g.ay;
  d.swap = g.ay > g.ax;
  d.a1 = fmax(g.ax, g.ay);
  d.a0 = fmin(g.ax, g.ay);
  d.qrow = 0;
  d.tq = 0.0f;
  if (d.aniso) {
    energy_cell_of(sqrt(d.a1), DIEL_ANISO_R, &d.row, &d.t);
    energy_cell_of(sqrt(sqrt(d.a0 / d.a1)), DIEL_ANISO_Q, &d.qrow, &d.tq);
    energy_cell_of(energy_dielectric_eta_x(eta), DIEL_ANISO_F, &d.col, &d.s);
    return d;
  }
#endif
  energy_cell_of(sqrt(d.alpha), DIEL_ALBEDO_R, &d.row, &d.t);
  energy_cell_of(energy_dielectric_eta_x(eta), DIEL_ALBEDO_F, &d.col, &d.s);
  return d;
}

// The isotropic interface at node (j, k) of the table on `side` exactly
DielectricEnergy energy_dielectric_node(__global const float* table, int j, int k, int side) {
  Ggx g;
  g.ax = g.ay = energy_dielectric_r_node(j) * energy_dielectric_r_node(j);
  float eta = energy_dielectric_eta_node(k);
  DielectricEnergy d = energy_dielectric_cells(table, g, side ? 1.0f / eta : eta);
  energy_node_cell(j, DIEL_ALBEDO_R, &d.row, &d.t);
  energy_node_cell(k, DIEL_ALBEDO_F, &d.col, &d.s);
  return d;
}

#if CD_FEATURE_ANISOTROPY
__global const float* energy_dielectric_aniso_entry(__global const float* table, int side, int f, int k, int j, int l,
                                                    int i) {
  return table + DIEL_ANISO_OFFSET +
         ((((side * DIEL_ANISO_F + f) * DIEL_ANISO_Q + k) * DIEL_ANISO_R + j) * DIEL_ANISO_P + l) * DIEL_ANISO_N + i;
}

__global const float* energy_dielectric_aniso_average_entry(__global const float* table, int side, int f, int k,
                                                            int j) {
  return table + DIEL_ANISO_OFFSET + DIEL_ANISO_NODES * DIEL_ANISO_P * DIEL_ANISO_N +
         ((side * DIEL_ANISO_F + f) * DIEL_ANISO_Q + k) * DIEL_ANISO_R + j;
}

// The anisotropic table's y: energy_y at the alpha seen along the azimuth, at least
// DIEL_ANISO_Y_ALPHA: along the minor axis of a line-shaped lobe alpha is tiny, and
// energy_y would spend every node but one on grazing angles, while the interface's E has
// its edge where total internal reflection sets in, at mid angles
#define DIEL_ANISO_Y_ALPHA 0.1f

float energy_dielectric_aniso_y_alpha(const DielectricEnergy* d, float t) {
  return fmax(energy_aniso_alpha(d->a1, d->a0, t), DIEL_ANISO_Y_ALPHA);
}

// E_side of an anisotropic interface at (t, mu): bilinear in (y, t) at each of the eight
// (roughness, ratio, eta) corners of its cells
float energy_dielectric_aniso_lookup_at(const DielectricEnergy* d, int side, float t, float mu) {
  int i, l;
  float sy, sp;
  energy_cell_of(energy_y(mu, energy_dielectric_aniso_y_alpha(d, t)), DIEL_ANISO_N, &i, &sy);
  energy_cell_of(t, DIEL_ANISO_P, &l, &sp);
  float sum = 0.0f;
  for (int corner = 0; corner < 8; ++corner) {
    int dj = corner & 1, dk = (corner >> 1) & 1, df = corner >> 2;
    float w = (dj ? d->t : 1.0f - d->t) * (dk ? d->tq : 1.0f - d->tq) * (df ? d->s : 1.0f - d->s);
    __global const float* c =
        energy_dielectric_aniso_entry(d->table, side, d->col + df, d->qrow + dk, d->row + dj, l, i);
    sum += w * mix(mix(c[0], c[1], sy), mix(c[DIEL_ANISO_N], c[DIEL_ANISO_N + 1], sy), sp);
  }
  return sum;
}
#endif

// E_side(w), trilinear in (y, roughness, eta) (anisotropic: energy_dielectric_aniso_lookup_at)
float energy_dielectric_lookup(const DielectricEnergy* d, int side, EnergyDir dir) {
  float mu = energy_dir_mu(dir);
#if CD_FEATURE_ANISOTROPY
  if (d->aniso) return energy_dielectric_aniso_lookup_at(d, side, energy_aniso_t_from(d->swap, dir), mu);
#endif
  int i;
  float w;
  energy_cell_of(energy_y(mu, d->alpha), DIEL_ALBEDO_N, &i, &w);
  __global const float* p =
      d->table + DIEL_ALBEDO_OFFSET + ((side * DIEL_ALBEDO_F + d->col) * DIEL_ALBEDO_R + d->row) * DIEL_ALBEDO_N + i;
  const int dr = DIEL_ALBEDO_N, dc = DIEL_ALBEDO_R * DIEL_ALBEDO_N;
  float e00 = mix(p[0], p[1], w), e10 = mix(p[dr], p[dr + 1], w);
  float e01 = mix(p[dc], p[dc + 1], w), e11 = mix(p[dc + dr], p[dc + dr + 1], w);
  return mix(mix(e00, e10, d->t), mix(e01, e11, d->t), d->s);
}

// E_side,avg, bilinear in (roughness, eta) between the node averages (anisotropic: trilinear
// in (roughness, ratio, eta))
float energy_dielectric_average(const DielectricEnergy* d, int side) {
#if CD_FEATURE_ANISOTROPY
  if (d->aniso) {
    float sum = 0.0f;
    for (int corner = 0; corner < 8; ++corner) {
      int dj = corner & 1, dk = (corner >> 1) & 1, df = corner >> 2;
      float w = (dj ? d->t : 1.0f - d->t) * (dk ? d->tq : 1.0f - d->tq) * (df ? d->s : 1.0f - d->s);
      sum += w * *energy_dielectric_aniso_average_entry(d->table, side, d->col + df, d->qrow + dk, d->row + dj);
    }
    return sum;
  }
#endif
  __global const float* p = d->table + DIEL_ALBEDO_OFFSET + DIEL_ALBEDO_ROWS * DIEL_ALBEDO_N +
                            (side * DIEL_ALBEDO_F + d->col) * DIEL_ALBEDO_R + d->row;
  return mix(mix(p[0], p[1], d->t), mix(p[DIEL_ALBEDO_R], p[DIEL_ALBEDO_R + 1], d->t), d->s);
}

// E_avg of node row (j, k, side) = 2 integral of E mu dmu over the E the lookups
// interpolate: 8-point Gauss-Legendre between the mu of consecutive y nodes. Runs after
// energy_dielectric_albedo_table; global size (R, 2 F). Not vectorized across work-items
// on Intel's CPU compiler, which gets it wrong (as energy_ggx_average_table).
#if CD_TABLE_KERNELS
__kernel __attribute__((vec_type_hint(float4))) void energy_dielectric_average_table(__global float* table) {
  const float x[4] = {0.1834346424956498f, 0.5255324099163290f, 0.7966664774136267f, 0.9602898564975363f};
  const float w[4] = {0.3626837833783620f, 0.3137066458778873f, 0.2223810344533745f, 0.1012285362903763f};
  int j = (int)get_global_id(0), ks = (int)get_global_id(1);
  if (j >= DIEL_ALBEDO_R || ks >= 2 * DIEL_ALBEDO_F) return;
  int side = ks / DIEL_ALBEDO_F, k = ks % DIEL_ALBEDO_F;
  DielectricEnergy d = energy_dielectric_node(table, j, k, side);
  float sum = 0.0f;
  for (int i = 0; i + 1 < DIEL_ALBEDO_N; ++i) {
    float a = energy_mu(energy_dielectric_y_node(i), d.alpha), b = energy_mu(energy_dielectric_y_node(i + 1), d.alpha);
    float c = 0.5f * (a + b), h = 0.5f * (b - a), segment = 0.0f;
    for (int q = 0; q < 4; ++q) {
      float lo = c - h * x[q], hi = c + h * x[q];
      segment += w[q] * (lo * energy_dielectric_lookup(&d, side, energy_dir(lo)) +
                         hi * energy_dielectric_lookup(&d, side, energy_dir(hi)));
    }
    sum += 2.0f * h * segment;
  }
  if (j == 0) sum = 1.0f;
  table[DIEL_ALBEDO_OFFSET + DIEL_ALBEDO_ROWS * DIEL_ALBEDO_N + ks * DIEL_ALBEDO_R + j] = fmin(sum, 1.0f);
}
#endif

#if CD_FEATURE_ANISOTROPY
// The anisotropic lobe at node (j, k): major alpha a1 = r_j^2 along x, minor
// a0 = max(q_k^4 a1, GGX_DELTA_ALPHA) (the fourth root of the ratio: nodes crowd towards the
// line-shaped lobes, whose E changes fastest); j = 0 is the delta lobe
Ggx energy_dielectric_aniso_node(int j, int k) {
  float r = (float)j / (float)(DIEL_ANISO_R - 1), q = (float)k / (float)(DIEL_ANISO_Q - 1);
  Ggx g;
  g.ax = r * r;
  g.ay = fmin(g.ax, fmax(q * q * q * q * g.ax, GGX_DELTA_ALPHA));
  return g;
}

// Node (j, k, f, side) of the anisotropic table from its flat index: roughness fastest
void energy_dielectric_aniso_node_of(int index, int* j, int* k, int* f, int* side) {
  *j = index % DIEL_ANISO_R;
  *k = (index / DIEL_ANISO_R) % DIEL_ANISO_Q;
  *f = (index / (DIEL_ANISO_R * DIEL_ANISO_Q)) % DIEL_ANISO_F;
  *side = index / (DIEL_ANISO_R * DIEL_ANISO_Q * DIEL_ANISO_F);
}

// Entry (i, l) of node (j, k, f, side): E at y_i and the azimuth with sin^2 = t_l from the
// major axis, by quadrature (the delta row: 1); without `exact`, the isotropic table's value
// at alpha = sqrt(ax ay) instead (runs after the isotropic table and its averages). Global
// size (N, P, DIEL_ANISO_NODES).
#if CD_TABLE_KERNELS
__kernel void energy_dielectric_aniso_table(__global float* table, uint n, uint exact) {
  int i = (int)get_global_id(0), l = (int)get_global_id(1), node = (int)get_global_id(2);
  if (i >= DIEL_ANISO_N || l >= DIEL_ANISO_P || node >= DIEL_ANISO_NODES) return;
  int j, k, f, side;
  energy_dielectric_aniso_node_of(node, &j, &k, &f, &side);
  Ggx g = energy_dielectric_aniso_node(j, k);
  float eta = energy_dielectric_eta_node_of(f, DIEL_ANISO_F);
  if (side) eta = 1.0f / eta;
  float t = (float)l / (float)(DIEL_ANISO_P - 1), e = 1.0f;
  float y_alpha = fmax(energy_aniso_alpha(g.ax, g.ay, t), DIEL_ANISO_Y_ALPHA);
  float mu = fmax(energy_mu((float)i / (float)(DIEL_ANISO_N - 1), y_alpha), 1e-4f);
  if (!ggx_is_delta(g) && exact) {
    float st = sqrt(fmax(0.0f, 1.0f - mu * mu));
    e = energy_dielectric_quadrature_wo(g, eta, (float3)(st * sqrt(1.0f - t), st * sqrt(t), mu), n);
  } else if (!ggx_is_delta(g)) {
    Ggx iso;
    iso.ax = iso.ay = sqrt(g.ax * g.ay);
    DielectricEnergy d = energy_dielectric_cells(table, iso, eta);
    e = energy_dielectric_lookup(&d, side, energy_dir(mu));
  }
  *(__global float*)energy_dielectric_aniso_entry(table, side, f, k, j, l, i) = fmin(e, 1.0f);
}
#endif

// The anisotropic interface at node (roughness j, ratio k, eta f) of the table on `side`
// exactly; the anisotropic cells also for the delta row (ax = ay = 0) and the isotropic
// column (ratio 1)
DielectricEnergy energy_dielectric_aniso_node_cells(__global const float* table, int j, int k, int f, int side) {
  Ggx g = energy_dielectric_aniso_node(j, k);
  float eta = energy_dielectric_eta_node_of(f, DIEL_ANISO_F);
  DielectricEnergy d = energy_dielectric_cells(table, g, side ? 1.0f / eta : eta);
  d.aniso = true;
  d.swap = false;
  energy_node_cell(j, DIEL_ANISO_R, &d.row, &d.t);
  energy_node_cell(k, DIEL_ANISO_Q, &d.qrow, &d.tq);
  energy_node_cell(f, DIEL_ANISO_F, &d.col, &d.s);
  return d;
}

// E_avg of node (j, k, f, side) over the E the lookups interpolate
// (energy_aniso_average_point). Global size DIEL_ANISO_NODES.
#if CD_TABLE_KERNELS
__kernel void energy_dielectric_aniso_average_table(__global float* table) {
  int node = (int)get_global_id(0);
  if (node >= DIEL_ANISO_NODES) return;
  int j, k, f, side;
  energy_dielectric_aniso_node_of(node, &j, &k, &f, &side);
  DielectricEnergy d = energy_dielectric_aniso_node_cells(table, j, k, f, side);
  float total = 0.0f;
  for (int q = 0; q < energy_aniso_average_points(DIEL_ANISO_P, DIEL_ANISO_N); ++q) {
    float3 pt = energy_aniso_average_point(q, DIEL_ANISO_P, DIEL_ANISO_N, d.a1, d.a0, 0, DIEL_ANISO_Y_ALPHA);
    total += pt.z * energy_dielectric_aniso_lookup_at(&d, side, pt.x, pt.y);
  }
  if (j == 0) total = 1.0f;
  *(__global float*)energy_dielectric_aniso_average_entry(table, side, f, k, j) = fmin(total, 1.0f);
}
#endif
#endif

// 2 integral of F mu dmu from the rarer side (eta >= 1), of the sheet's 2F / (1 + F) if
// `sheet`, by 8-point Gauss-Legendre quadrature in mu
float energy_dielectric_fresnel_average(float eta, bool sheet) {
  const float x[4] = {0.1834346424956498f, 0.5255324099163290f, 0.7966664774136267f, 0.9602898564975363f};
  const float w[4] = {0.3626837833783620f, 0.3137066458778873f, 0.2223810344533745f, 0.1012285362903763f};
  float e = eta >= 1.0f ? eta : 1.0f / eta, sum = 0.0f;
  for (int q = 0; q < 4; ++q) {
    float lo = 0.5f * (1.0f - x[q]), hi = 0.5f * (1.0f + x[q]);
    float flo = fresnel_dielectric(lo, e), fhi = fresnel_dielectric(hi, e);
    if (sheet) {
      flo = dielectric_sheet_reflectance(flo);
      fhi = dielectric_sheet_reflectance(fhi);
    }
    sum += w[q] * (lo * flo + hi * fhi);
  }
  return sum;
}

// The compensation of one interface seen from wo: the tables, E_s(mu_o), the coefficients
// for a wi on wo's side (refl) and on the other (trans), and the sampling shares
typedef struct {
  bool on;
  bool thin;
  float eta;
  GgxEnergy ggx;          // thin sheets: the GGX table
  DielectricEnergy diel;  // volumetric interfaces: the dielectric table
  float e_o;              // single-scattering albedo at wo
  float refl, trans;      // a_s and c
  float q;                // probability of sampling the compensation lobe: 1 - e_o
  float p_refl;           // within it, the share of reflection: a_s A_s
} DielectricMs;

DielectricMs energy_dielectric_at(__global const float* table, Ggx g, float eta, bool thin, EnergyDir wo) {
  float mu_o = energy_dir_mu(wo);
  DielectricMs m;
  m.on = false;
  m.thin = thin;
  m.eta = eta;
  m.e_o = 1.0f;
  m.refl = m.trans = m.q = m.p_refl = 0.0f;
  if (!table || ggx_is_delta(g) || mu_o <= 0.0f) return m;
  // A_0, A_1: the missing averages of the rarer and the denser side
  float a_same, a_other, a0, a1, x;
  if (thin) {
    m.ggx = energy_ggx(table, g, wo);
    m.e_o = m.ggx.e_o;
    a_same = a_other = a0 = a1 = 1.0f - m.ggx.e_avg;
    x = 1.0f - energy_dielectric_fresnel_average(eta, true);
  } else {
    m.diel = energy_dielectric_cells(table, g, eta);
    m.e_o = energy_dielectric_lookup(&m.diel, m.diel.side, wo);
    a0 = 1.0f - energy_dielectric_average(&m.diel, 0);
    a1 = 1.0f - energy_dielectric_average(&m.diel, 1);
    a_same = m.diel.side ? a1 : a0;
    a_other = m.diel.side ? a0 : a1;
    x = 1.0f - energy_dielectric_fresnel_average(eta, false);
  }
  if (!(a0 > 1e-6f && a1 > 1e-6f) || m.e_o >= 1.0f) return m;
  float n2 = thin ? 1.0f : (eta >= 1.0f ? eta * eta : 1.0f / (eta * eta));
  float c = fmin(x / (n2 * a1), 1.0f / a0);
  m.trans = thin || m.diel.side ? c : c * n2;  // k of a transmission from wo's side
  m.refl = fmax(1.0f - m.trans * a_other, 0.0f) / a_same;
  m.q = 1.0f - m.e_o;
  m.p_refl = clamp(m.refl * a_same, 0.0f, 1.0f);
  m.on = true;
  return m;
}

// E of the side of wi (wi.z < 0: the other side) at |wi.z|
float energy_dielectric_e_at(const DielectricMs* m, float3 wi) {
  float mu = fabs(wi.z);
  if (m->thin) return energy_albedo(&m->ggx, energy_at((float3)(wi.x, wi.y, mu)));
  return energy_dielectric_lookup(&m->diel, wi.z > 0.0f ? m->diel.side : 1 - m->diel.side,
                                  energy_at((float3)(wi.x, wi.y, mu)));
}

// The compensation lobe f_ms(wo, wi) (radiance: transmission scaled by 1 / eta^2 as the
// single-scattering lobe is, tinted) and its pdf within the lobe
float3 energy_dielectric_ms(const DielectricMs* m, float3 tint, float3 wi, float* pdf) {
  *pdf = 0.0f;
  if (!m->on || wi.z == 0.0f) return (float3)(0.0f);
  float missing = (1.0f - m->e_o) * fmax(1.0f - energy_dielectric_e_at(m, wi), 0.0f) * INV_PI_F;
  float cos_pdf = fabs(wi.z) * INV_PI_F;
  if (wi.z > 0.0f) {
    *pdf = m->p_refl * cos_pdf;
    return (float3)(m->refl * missing);
  }
  *pdf = (1.0f - m->p_refl) * cos_pdf;
  return tint * (m->trans * missing / (m->thin ? 1.0f : m->eta * m->eta));
}

// bsdf_dielectric_eval with the compensation lobe: f and the pdf of
// energy_dielectric_sample (the table 0: bsdf_dielectric_eval)
float3 energy_dielectric_eval(__global const float* table, Ggx g, float eta, bool thin, float3 tint, float3 wo,
                              float3 wi, float* pdf) {
  float3 f = bsdf_dielectric_eval(g, eta, thin, tint, wo, wi, pdf);
  DielectricMs m = energy_dielectric_at(table, g, eta, thin, energy_at(wo));
  if (!m.on) return f;
  float ms_pdf;
  f += energy_dielectric_ms(&m, tint, wi, &ms_pdf);
  *pdf = (1.0f - m.q) * *pdf + m.q * ms_pdf;
  return f;
}

// bsdf_dielectric_sample with the compensation lobe, chosen with probability q by uc and
// sampled by the cosine on the side that p_refl picks
bool energy_dielectric_sample(__global const float* table, Ggx g, float eta, bool thin, float3 tint, float3 wo,
                              float uc, float2 u, BsdfSample* bs) {
  DielectricMs m = energy_dielectric_at(table, g, eta, thin, energy_at(wo));
  if (!m.on) return bsdf_dielectric_sample(g, eta, thin, tint, wo, uc, u, bs);
  if (uc < m.q) {
    float v = uc / m.q;
    bs->wi = sample_cosine_hemisphere(u.x, u.y);
    if (v >= m.p_refl) bs->wi.z = -bs->wi.z;
  } else if (!bsdf_dielectric_sample(g, eta, thin, tint, wo, fmin((uc - m.q) / (1.0f - m.q), 0x1.fffffep-1f), u, bs)) {
    return false;
  }
  bool transmits = bs->wi.z < 0.0f;
  bs->f = energy_dielectric_eval(table, g, eta, thin, tint, wo, bs->wi, &bs->pdf);
  bs->flags = (transmits ? BSDF_TRANSMISSION : BSDF_REFLECTION) | BSDF_GLOSSY;
  bs->eta = transmits && !thin ? eta : 1.0f;
  return bs->pdf > 0.0f;
}
