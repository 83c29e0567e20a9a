// glTF alphaMode on the device. alpha = baseColorFactor.a x the base colour texture's
// alpha. MASK cuts the surface out where alpha < alphaCutoff; BLEND is stochastic
// opacity: a ray passes straight through with probability 1 - alpha; OPAQUE ignores
// alpha. The BVH asks scene_alpha_passes about hits on the triangles the host flagged
// (BVH_TRI_ALPHA_TEST), for closest hits and shadow rays alike; light sampling weighs
// emission by alpha_coverage, so a cut-out emitter emits only where it is opaque.

float alpha_at(const SceneData* sc, __global const Prim* pr, __global const Material* m, float b1, float b2) {
  return m->base_color[3] * textures_lookup(sc, &m->textures[TEX_BASE_COLOR], surface_uvs(sc, pr, b1, b2)).w;
}

// Uniform number in [0, 1) for the stochastic test of primitive `prim` along `ray`: a hash
// of both (pcg4d twice), so one ray decides the same way whatever the traversal order and
// for closest hits and shadow rays, while every path and sample gets its own draw
float alpha_random(uint prim, Ray ray) {
  uint4 h = rng_pcg4d((uint4)(as_uint(ray.org.x), as_uint(ray.org.y), as_uint(ray.org.z), prim));
  h = rng_pcg4d(h ^ (uint4)(as_uint(ray.dir.x), as_uint(ray.dir.y), as_uint(ray.dir.z), 0x9e3779b9u));
  return (float)(h.x >> 8) * 0x1.0p-24f;
}

// Does a hit at (b1, b2) on primitive `prim` along `ray` count (the surface is opaque there)?
bool scene_alpha_passes(const struct SceneData* sc, uint prim, float b1, float b2, Ray ray) {
  __global const Prim* pr = &sc->prims[prim];
  __global const Material* m = &sc->materials[pr->material];
  if (m->flags & MATERIAL_ALPHA_MASK) return alpha_at(sc, pr, m, b1, b2) >= m->alpha_cutoff;
  if (m->flags & MATERIAL_ALPHA_BLEND) return alpha_random(prim, ray) < alpha_at(sc, pr, m, b1, b2);
  return true;
}

// The probability that a ray meeting primitive `prim` at (b1, b2) stops there
float alpha_coverage(const SceneData* sc, uint prim, float b1, float b2) {
#if CD_FEATURE_ALPHA
  __global const Prim* pr = &sc->prims[prim];
  __global const Material* m = &sc->materials[pr->material];
  if (m->flags & MATERIAL_ALPHA_MASK) return alpha_at(sc, pr, m, b1, b2) >= m->alpha_cutoff ? 1.0f : 0.0f;
  if (m->flags & MATERIAL_ALPHA_BLEND) return clamp(alpha_at(sc, pr, m, b1, b2), 0.0f, 1.0f);
#endif
  return 1.0f;
}
