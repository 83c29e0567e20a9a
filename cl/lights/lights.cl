// Light sampling from a context (a surface point, or a point in a medium), through one
// light-selection alias table with probabilities proportional to power, or the light tree
// (cl/lights/light_tree.cl) that weighs each light by what it can send to the shading
// point. Directions and pdfs are measured from ctx.p; a finite light's shadow ray ends at
// `target`, just off the light's surface on ctx.p's side. Each light type has its
// functions lights_NAME_* in the file of its family (environment.cl, triangle.cl,
// punctual.cl); the dispatch on the type here is generated from CD_LIGHTS
// (cl/shared/device_types.h), and a type whose feature is off (SceneFeatures: punctual
// lights, the environment) is compiled out.

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
