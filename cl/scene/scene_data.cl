// The scene as kernel code sees it: every buffer of CD_SCENE_BUFFERS (device_types.h) in
// one struct, and geometry looked up by stable primitive index.

#define CD_SCENE_FIELD(type, name) __global const type* name;
#define CD_SCENE_PARAM(type, name) __global const type *name,
#define CD_SCENE_INIT(type, name) name,

typedef struct SceneData {
  CD_SCENE_BUFFERS(CD_SCENE_FIELD)
  __global const RenderParams* params;
#if CD_MOTION_STEPS
  // The time of the sample's path (motion blur): between pose motion_step and the next, a
  // fraction motion_mix of the way (scene_set_time)
  uint motion_step;
  float motion_mix;
#endif
} SceneData;

#if CD_MOTION_STEPS
// Sets the time, `time` in poses (0: the shutter opens, CD_MOTION_STEPS: it closes)
void scene_set_time(SceneData* sc, float time) {
  uint step = min((uint)time, (uint)(CD_MOTION_STEPS - 1));
  sc->motion_step = step;
  sc->motion_mix = clamp(time - (float)step, 0.0f, 1.0f);
}

// Vertex v of the per-pose array `a` (positions, normals: pose s of v at v (K + 1) + s) at
// the time: linear between the two poses around it (a rotation follows their chord)
float3 scene_motion_vertex(const SceneData* sc, __global const float* a, uint v) {
  uint i = v * (uint)(CD_MOTION_STEPS + 1) + sc->motion_step;
  return mix(vload3(i, a), vload3(i + 1u, a), sc->motion_mix);
}
#endif

// Closest hit along the ray in (0, tmax), by stable primitive index, skipping hits that
// alpha lets through (cut-outs, BLEND's stochastic passes: cl/scene/alpha.cl)
Hit scene_intersect(const SceneData* sc, Ray ray, float tmax) {
  return bvh_intersect(sc, sc->bvh_nodes, sc->bvh_tris, ray, tmax);
}

// Closest hits of eight rays at once, as scene_intersect finds each (bvh_intersect8: for
// coherent rays)
void scene_intersect8(const SceneData* sc, const Ray* rays, const float* tmax, Hit* hits) {
  bvh_intersect8(sc, sc->bvh_nodes, sc->bvh_tris, rays, tmax, hits);
}

// Anything in (0, tmax) along the ray, by the same alpha tests?
bool scene_occluded(const SceneData* sc, Ray ray, float tmax) {
  return bvh_occluded(sc, sc->bvh_nodes, sc->bvh_tris, ray, tmax);
}

void scene_prim_positions(const SceneData* sc, uint prim, float3* p0, float3* p1, float3* p2) {
  __global const Prim* pr = &sc->prims[prim];
#if CD_MOTION_STEPS
  *p0 = scene_motion_vertex(sc, sc->positions, pr->v[0]);
  *p1 = scene_motion_vertex(sc, sc->positions, pr->v[1]);
  *p2 = scene_motion_vertex(sc, sc->positions, pr->v[2]);
#else
  *p0 = vload3(pr->v[0], sc->positions);
  *p1 = vload3(pr->v[1], sc->positions);
  *p2 = vload3(pr->v[2], sc->positions);
#endif
}
