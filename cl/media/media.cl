// Participating media (compiled in with CD_FEATURE_MEDIA): which medium a path is in, the
// free-flight distance to the next scattering event, transmittance along shadow rays and
// the light media emit. Records are `Medium` (device_types.h), in the `media` buffer:
// media[GLOBAL_MEDIUM] fills the scene (vacuum when the scene declares none), the others
// are interiors of closed meshes, named by Material.medium.
//
// Tracking (MediumStack): a path keeps the interiors it has entered, innermost last; the
// ray is in the innermost one, else in the global medium. Crossing a boundary by
// transmission (or through a null boundary) from its front face pushes the material's
// medium; crossing from the back face removes the topmost entry of that medium, and does
// nothing when the path never entered it. A push onto a full stack is dropped (more than
// MEDIUM_STACK_SIZE nested interiors). A camera ray starts with the interiors its origin
// lies in (media_at_origin).
//
// Coefficients: sigma_t = sigma_a + sigma_s per RGB channel, times the grid's density for
// MEDIUM_GRID (dense) and MEDIUM_NANOVDB (nanovdb.cl); `emission` is emitted radiance per
// unit length (L_e(z) of the radiative transfer equation; for grids times the density, or the value of the
// emission grid Medium.emission_grid names), so a ray crossing length d of a homogeneous
// medium gathers emission (1 - exp(-sigma_t d)) / sigma_t.

#define MEDIUM_STACK_SIZE 4
#define MEDIA_WALK_MAX 32  // boundaries media_at_origin and shadow rays cross at most

typedef struct {
  int entered[MEDIUM_STACK_SIZE];  // media entered, innermost last
  uint count;
} MediumStack;

#if CD_FEATURE_MEDIA

MediumStack media_stack_empty(void) {
  MediumStack st;
  st.count = 0u;
  for (int i = 0; i < MEDIUM_STACK_SIZE; ++i) st.entered[i] = NO_MEDIUM;
  return st;
}

int media_current(const MediumStack* st) { return st->count > 0u ? st->entered[st->count - 1u] : GLOBAL_MEDIUM; }

// The ray crosses a boundary whose interior is `medium`: entering (from the front face)
// or leaving
void media_cross(MediumStack* st, int medium, bool entering) {
  if (medium == NO_MEDIUM) return;
  if (entering) {
    if (st->count < MEDIUM_STACK_SIZE) st->entered[st->count++] = medium;
    return;
  }
  for (int i = (int)st->count - 1; i >= 0; --i) {
    if (st->entered[i] != medium) continue;
    for (int k = i; k + 1 < (int)st->count; ++k) st->entered[k] = st->entered[k + 1];
    st->count -= 1u;
    return;
  }
}

bool media_is_null_boundary(const SceneData* sc, uint material) {
  return (sc->materials[material].flags & MATERIAL_NULL_BOUNDARY) != 0u;
}

// Does the ray along `dir` hit primitive `prim` on its front face?
bool media_front_face(const SceneData* sc, uint prim, float3 dir) {
  float3 v0, v1, v2;
  scene_prim_positions(sc, prim, &v0, &v1, &v2);
  return dot(cross(v1 - v0, v2 - v0), dir) < 0.0f;
}

// The interiors that ray.org lies in: walk the ray to infinity through every boundary.
// A boundary left from the back face that was not entered on the way encloses the origin;
// the farthest of them is the outermost.
MediumStack media_at_origin(const SceneData* sc, Ray ray) {
  Ray r = ray;                    // walked along: never assign to a struct parameter (README, Kernel portability)
  int inside[MEDIUM_STACK_SIZE];  // media enclosing the origin, innermost first
  uint n_inside = 0u;
  MediumStack passed = media_stack_empty();  // entered along the ray, not yet left
  for (int k = 0; k < MEDIA_WALK_MAX; ++k) {
    Hit hit = scene_intersect(sc, r, INFINITY);
    if (hit.prim < 0) break;
    int medium = sc->materials[sc->prims[hit.prim].material].medium;
    bool front = media_front_face(sc, (uint)hit.prim, r.dir);
    if (medium != NO_MEDIUM) {
      uint before = passed.count;
      media_cross(&passed, medium, front);
      if (!front && passed.count == before && n_inside < MEDIUM_STACK_SIZE) inside[n_inside++] = medium;
    }
    float3 v0, v1, v2;
    scene_prim_positions(sc, (uint)hit.prim, &v0, &v1, &v2);
    float area;
    float3 n = triangle_normal_area(v0, v1, v2, &area);
    r.org = offset_ray_origin(r.org + hit.t * r.dir, n * (dot(n, r.dir) > 0.0f ? 1.0f : -1.0f));
  }
  MediumStack st = media_stack_empty();
  for (uint i = 0u; i < n_inside; ++i) st.entered[i] = inside[n_inside - 1u - i];
  st.count = n_inside;
  return st;
}

float3 media_sigma_a(__global const Medium* m) { return load3(m->sigma_a); }
float3 media_sigma_s(__global const Medium* m) { return load3(m->sigma_s); }
float3 media_sigma_t(__global const Medium* m) { return load3(m->sigma_a) + load3(m->sigma_s); }

float media_average(float3 v) { return (v.x + v.y + v.z) * (1.0f / 3.0f); }

float3 media_exp(float3 x) { return (float3)(exp(x.x), exp(x.y), exp(x.z)); }

// (1 - exp(-s d)) / s per channel: the length of the segment [0, d] weighted by its
// transmittance from the start (d where s d is tiny; 1 / s for d = infinity)
float media_weighted_length1(float s, float d) {
  float x = s * d;
  if (!(x > 1e-4f)) return d * (1.0f - 0.5f * x);
  return (1.0f - exp(-x)) / s;
}

float3 media_weighted_length(float3 s, float d) {
  return (float3)(media_weighted_length1(s.x, d), media_weighted_length1(s.y, d), media_weighted_length1(s.z, d));
}

// Density of a MEDIUM_GRID at p: trilinear between the grid's nodes, which span the box
// from grid_min to grid_max (node i at grid_min + i / (n - 1) of the box); 0 outside
float media_density(const SceneData* sc, __global const Medium* m, float3 p) {
  float3 lo = load3(m->grid_min), hi = load3(m->grid_max);
  float3 u = (p - lo) / (hi - lo);
  if (u.x < 0.0f || u.y < 0.0f || u.z < 0.0f || u.x > 1.0f || u.y > 1.0f || u.z > 1.0f) return 0.0f;
  int nx = (int)m->grid_size[0], ny = (int)m->grid_size[1], nz = (int)m->grid_size[2];
  float3 g = u * (float3)((float)(nx - 1), (float)(ny - 1), (float)(nz - 1));
  int x0 = min((int)g.x, nx - 2), y0 = min((int)g.y, ny - 2), z0 = min((int)g.z, nz - 2);
  float fx = g.x - (float)x0, fy = g.y - (float)y0, fz = g.z - (float)z0;
  __global const float* d = sc->densities + m->grid_offset;
  int sx = 1, sy = nx, sz = nx * ny;
  int i = x0 + y0 * sy + z0 * sz;
  float c00 = mix(d[i], d[i + sx], fx), c10 = mix(d[i + sy], d[i + sy + sx], fx);
  float c01 = mix(d[i + sz], d[i + sz + sx], fx), c11 = mix(d[i + sz + sy], d[i + sz + sy + sx], fx);
  return m->density_scale * mix(mix(c00, c10, fy), mix(c01, c11, fy), fz);
}

// A grid medium's lookups along one ray: the ray in the grid's lookup space (world space
// for MEDIUM_GRID, the grid's index space for MEDIUM_NANOVDB; the map is affine, so a point
// at ray parameter t is at parameter t in both) and, for NanoVDB, the grid and its accessor
typedef struct {
  Ray r;
#if CD_FEATURE_NANOVDB
  NanoVdbGrid vdb;
#endif
} MediaGridRay;

MediaGridRay media_grid_ray(const SceneData* sc, __global const Medium* m, Ray r) {
  MediaGridRay g;
  g.r = r;
#if CD_FEATURE_NANOVDB
  if (m->type == MEDIUM_NANOVDB) {
    g.vdb = nanovdb_grid(sc->nanovdb + m->grid_offset);
    g.r.org = nanovdb_world_to_index(&g.vdb, r.org);
    g.r.dir = nanovdb_world_to_index_dir(&g.vdb, r.dir);
  }
#endif
  return g;
}

// Density (grid value x density_scale) at ray parameter t of the ray g was made for
float media_grid_density(const SceneData* sc, __global const Medium* m, MediaGridRay* g, float t) {
  float3 q = g->r.org + t * g->r.dir;
#if CD_FEATURE_NANOVDB
  if (m->type == MEDIUM_NANOVDB) return m->density_scale * fmax(nanovdb_trilinear(&g->vdb, q), 0.0f);
#endif
  return media_density(sc, m, q);
}

// The part [*t0, *t1] of the ray inside a grid medium's box (in its lookup space: r is the
// ray there), within [0, tmax]; false: none
bool media_grid_span(__global const Medium* m, Ray r, float tmax, float* t0, float* t1) {
  float3 inv = safe_inverse(r.dir);
  float3 a = (load3(m->grid_min) - r.org) * inv, b = (load3(m->grid_max) - r.org) * inv;
  float3 near = fmin(a, b), far = fmax(a, b);
  *t0 = fmax(fmax(near.x, near.y), fmax(near.z, 0.0f));
  *t1 = fmin(fmin(far.x, far.y), fmin(far.z, tmax));
  return *t0 < *t1;
}

// Exponential step of rate `rate` (> 0)
float media_exp_step(float rate, Rng* rng) { return -log(1.0f - rng_next(rng)) / rate; }

// What happened along a ray segment in a medium
#define MEDIUM_PASSED 0     // the ray reached the surface (or escaped); beta holds the weight
#define MEDIUM_SCATTERED 1  // a real scattering event at *p; beta holds the weight
#define MEDIUM_ABSORBED 2   // the path ends in the medium (delta tracking's absorption)

// Homogeneous medium: the free-flight distance is sampled from one channel's sigma_t,
// the channel chosen uniformly, so the pdf of a distance t is the average over channels of
// sigma_t exp(-sigma_t t) and the probability of reaching tmax the average of exp(-sigma_t
// tmax) (one-sample MIS over the channels; unbiased for chromatic media). The weight is
// sigma_s T(t) / pdf at a scattering event and T(tmax) / P(pass) at the surface. Without
// scattering nothing is sampled and the weight is T(tmax) exactly.
int media_sample_homogeneous(__global const Medium* m, Ray r, float tmax, Rng* rng, float3* beta, float3* p) {
  float3 sigma_t = media_sigma_t(m), sigma_s = media_sigma_s(m);
  if (max_component(sigma_s) <= 0.0f) {
    if (max_component(sigma_t) > 0.0f) *beta *= media_exp(-sigma_t * tmax);
    return MEDIUM_PASSED;
  }
  float uc = rng_next(rng);
  float s = uc < 1.0f / 3.0f ? sigma_t.x : uc < 2.0f / 3.0f ? sigma_t.y : sigma_t.z;
  float t = s > 0.0f ? media_exp_step(s, rng) : INFINITY;
  if (t < tmax) {
    float3 tr = media_exp(-sigma_t * t);
    *beta *= sigma_s * tr / media_average(sigma_t * tr);
    *p = r.org + t * r.dir;
    return MEDIUM_SCATTERED;
  }
  float3 tr = media_exp(-sigma_t * tmax);
  *beta *= tr / media_average(tr);
  return MEDIUM_PASSED;
}

// Walks the majorant cells of a grid medium that a ray crosses, in order (3D DDA, Amanatides
// and Woo 1987): `t` is where the current cell's part of the span starts.
typedef struct {
  float t, t1;     // current position and the end of the span inside the box
  float3 t_next;   // ray distance to the next cell boundary along each axis
  float3 t_delta;  // ray distance across one cell along each axis
  int3 cell, step, size;
  uint offset;  // the medium's first majorant cell in `densities`
} MediaDda;

// Starts the walk over the part of [0, tmax] inside the box (r in the grid's lookup space,
// MediaGridRay); false: the ray misses it
bool media_dda_start(__global const Medium* m, Ray r, float tmax, MediaDda* it) {
  if (!(m->majorant > 0.0f) || !media_grid_span(m, r, tmax, &it->t, &it->t1)) return false;
  float3 lo = load3(m->grid_min), hi = load3(m->grid_max);
  it->size = (int3)((int)m->majorant_size[0], (int)m->majorant_size[1], (int)m->majorant_size[2]);
  float3 cell_size = (hi - lo) / convert_float3(it->size);
  float3 p = r.org + it->t * r.dir;
  it->cell = clamp(convert_int3(floor((p - lo) / cell_size)), (int3)(0), it->size - 1);
  it->step = (int3)(r.dir.x >= 0.0f ? 1 : -1, r.dir.y >= 0.0f ? 1 : -1, r.dir.z >= 0.0f ? 1 : -1);
  float3 inv = safe_inverse(r.dir);
  float3 boundary = lo + convert_float3(it->cell + max(it->step, (int3)(0))) * cell_size;
  it->t_next = (boundary - r.org) * inv;
  it->t_delta = fabs(cell_size * inv);
  it->offset = m->majorant_offset;
  return true;
}

// The current cell's majorant and where the ray leaves it (within the span); false: done
bool media_dda_cell(const SceneData* sc, const MediaDda* it, float* sigma_bar, float* t_end) {
  if (!(it->t < it->t1)) return false;
  int3 c = it->cell;
  *sigma_bar = sc->densities[it->offset + (uint)(c.x + it->size.x * (c.y + it->size.y * c.z))];
  *t_end = fmin(it->t1, fmin(it->t_next.x, fmin(it->t_next.y, it->t_next.z)));
  return true;
}

// On to the next cell (false: the ray leaves the grid)
bool media_dda_advance(MediaDda* it) {
  float3 tn = it->t_next;
  int axis = tn.x <= tn.y && tn.x <= tn.z ? 0 : tn.y <= tn.z ? 1 : 2;
  float t_end = axis == 0 ? tn.x : axis == 1 ? tn.y : tn.z;
  it->t = fmax(it->t, fmin(t_end, it->t1));
  if (axis == 0) {
    it->cell.x += it->step.x;
    it->t_next.x += it->t_delta.x;
  }
  if (axis == 1) {
    it->cell.y += it->step.y;
    it->t_next.y += it->t_delta.y;
  }
  if (axis == 2) {
    it->cell.z += it->step.z;
    it->t_next.z += it->t_delta.z;
  }
  bool inside = all(it->cell >= (int3)(0)) && all(it->cell < it->size);
  if (!inside) it->t = it->t1;
  return inside;
}

// Next tentative collision of a grid medium along the walk: an optical depth drawn from
// Exp(1) is spent cell by cell against each cell's majorant (cells of majorant 0 are
// skipped at no cost). False: the ray leaves the span first. *sigma_bar: the majorant there.
bool media_dda_collision(const SceneData* sc, MediaDda* it, Rng* rng, float* sigma_bar) {
  float tau = -log(1.0f - rng_next(rng));
  float sb, t_end;
  while (media_dda_cell(sc, it, &sb, &t_end)) {
    float room = sb * fmax(t_end - it->t, 0.0f);
    if (tau < room) {
      it->t += tau / sb;
      *sigma_bar = sb;
      return true;
    }
    tau -= room;
    if (!media_dda_advance(it)) return false;
  }
  return false;
}

// Grid medium: delta tracking against the piecewise-constant majorant sigma_bar of the
// majorant grid. Tentative collisions come at rate sigma_bar; at each the event is
// absorption, scattering or a null collision with probabilities avg(sigma_a),
// avg(sigma_s), avg(sigma_bar - sigma_t) over sigma_bar, weighted by sigma / (sigma_bar
// P(event)) per channel (1 for grey media: analog delta tracking). Emission: each tentative
// collision adds beta x emission(t) / sigma_bar, an unbiased estimate of the integral of
// T(t) emission(t) (tentative collisions happen at rate sigma_bar while the path goes on);
// emission(t) is emission x density, or emission x the emission grid (Medium.emission_grid).
int media_sample_grid(const SceneData* sc, __global const Medium* m, Ray r, float tmax, Rng* rng, float3* beta,
                      float3* radiance, float3* p) {
  MediaGridRay g = media_grid_ray(sc, m, r);
  MediaDda it;
  if (!media_dda_start(m, g.r, tmax, &it)) return MEDIUM_PASSED;
  float3 sigma_a = media_sigma_a(m), sigma_s = media_sigma_s(m), emission = load3(m->emission);
  bool emits = max_component(emission) > 0.0f;
  // An emission grid (a MEDIUM_GRID record in world space) scales the emission in place of
  // the density; the host made the majorant positive wherever it is
  __global const Medium* em = m->emission_grid != 0u ? &sc->media[m->emission_grid] : 0;
  float sigma_bar;
  while (media_dda_collision(sc, &it, rng, &sigma_bar)) {
    float d = media_grid_density(sc, m, &g, it.t);
    if (emits) {
      float e = em ? media_density(sc, em, r.org + it.t * r.dir) : d;
      *radiance += *beta * emission * (e / sigma_bar);
    }
    float3 sa = d * sigma_a, ss = d * sigma_s, sn = fmax((float3)(sigma_bar)-sa - ss, 0.0f);
    float pa = media_average(sa) / sigma_bar, ps = media_average(ss) / sigma_bar;
    float u = rng_next(rng);
    if (u < pa) return MEDIUM_ABSORBED;
    if (u < pa + ps) {
      *beta *= ss / media_average(ss);
      *p = r.org + it.t * r.dir;
      return MEDIUM_SCATTERED;
    }
    float an = media_average(sn);
    if (!(an > 0.0f)) return MEDIUM_ABSORBED;  // only reachable through rounding
    *beta *= sn / an;
  }
  return MEDIUM_PASSED;
}

// Emission the homogeneous medium sends along the segment [0, tmax] to its start
float3 media_homogeneous_emission(__global const Medium* m, float tmax) {
  float3 e = load3(m->emission);
  if (max_component(e) <= 0.0f) return (float3)(0.0f);
  return e * media_weighted_length(media_sigma_t(m), tmax);
}

// One segment of a path in medium `medium`, from r.org to the surface at tmax (INFINITY:
// the ray escapes): adds the medium's emission along the segment to *radiance (weighted by
// *beta; the light media emit is found this way under every strategy) and samples where
// the path scatters next.
int media_sample_segment(const SceneData* sc, int medium, Ray r, float tmax, Rng* rng, float3* beta, float3* radiance,
                         float3* p) {
  __global const Medium* m = &sc->media[medium];
  if (m->type != MEDIUM_HOMOGENEOUS) return media_sample_grid(sc, m, r, tmax, rng, beta, radiance, p);
  *radiance += *beta * media_homogeneous_emission(m, tmax);
  return media_sample_homogeneous(m, r, tmax, rng, beta, p);
}

// Transmittance exp(-integral sigma_t) through `medium` along [0, tmax]: closed form for
// homogeneous media, ratio tracking against the majorant grid for grids
float3 media_segment_transmittance(const SceneData* sc, int medium, Ray r, float tmax, Rng* rng) {
  __global const Medium* m = &sc->media[medium];
  if (m->type == MEDIUM_HOMOGENEOUS) {
    float3 sigma_t = media_sigma_t(m);
    return max_component(sigma_t) > 0.0f ? media_exp(-sigma_t * tmax) : (float3)(1.0f);
  }
  float3 tr = (float3)(1.0f);
  MediaGridRay g = media_grid_ray(sc, m, r);
  MediaDda it;
  if (!media_dda_start(m, g.r, tmax, &it)) return tr;
  float3 sigma_t = media_sigma_t(m);
  float sigma_bar;
  while (media_dda_collision(sc, &it, rng, &sigma_bar)) {
    float d = media_grid_density(sc, m, &g, it.t);
    tr *= fmax(1.0f - d * sigma_t / sigma_bar, 0.0f);
    if (max_component(tr) <= 0.0f) return tr;
  }
  return tr;
}

// Transmittance of a shadow ray from r.org (in the media of `start`) to distance tmax
// (INFINITY: to infinity): it passes null boundaries, changing medium there, and any other
// surface blocks it
float3 media_shadow_transmittance(const SceneData* sc, Ray ray, float tmax, MediumStack start, Rng* rng) {
  Ray r = ray;  // local copies: the walk changes both (see media_at_origin)
  MediumStack st = start;
  float3 tr = (float3)(1.0f);
  float3 target = r.org + tmax * r.dir;
  for (int k = 0; k < MEDIA_WALK_MAX; ++k) {
    Hit hit = scene_intersect(sc, r, tmax);
    float t = hit.prim < 0 ? tmax : hit.t;
    tr *= media_segment_transmittance(sc, media_current(&st), r, t, rng);
    if (hit.prim < 0 || max_component(tr) <= 0.0f) return tr;
    uint material = sc->prims[hit.prim].material;
    if (!media_is_null_boundary(sc, material)) return (float3)(0.0f);
    bool front = media_front_face(sc, (uint)hit.prim, r.dir);
    media_cross(&st, sc->materials[material].medium, front);
    float3 v0, v1, v2;
    scene_prim_positions(sc, (uint)hit.prim, &v0, &v1, &v2);
    float area;
    float3 n = triangle_normal_area(v0, v1, v2, &area);
    r.org = offset_ray_origin(r.org + hit.t * r.dir, n * (dot(n, r.dir) > 0.0f ? 1.0f : -1.0f));
    if (isfinite(tmax)) {
      tmax = dot(target - r.org, r.dir);
      if (!(tmax > 0.0f)) return tr;
    }
  }
  return (float3)(0.0f);  // more boundaries than the walk follows: treated as blocked
}

#endif  // CD_FEATURE_MEDIA
