// 4-wide BVH traversal: one float4 slab test per axis tests a node's four child boxes at
// once; hit children are visited nearest first (a sorting network on their entry
// distances, the others on a short stack); any-hit early exit for shadow rays, whose stack
// holds node references only (half the private memory of the closest-hit one's).
// The node and leaf layout (BvhNode, BvhTriangle, cl/shared/device_types.h) is private to this
// file and host/bvh_builder.cpp; everything else sees hits by stable primitive index.
// Hits on triangles flagged BVH_TRI_ALPHA_TEST count only where the scene's alpha test
// says so (cut-outs, stochastic opacity): that code is compiled in with CD_FEATURE_ALPHA.

// Does the hit at barycentrics (b1, b2) of primitive `prim` along `ray` count? Defined by
// the scene (cl/scene/alpha.cl); the traversal passes `sc` through without reading it.
struct SceneData;
bool scene_alpha_passes(const struct SceneData* sc, uint prim, float b1, float b2, Ray ray);

CD_ALWAYS_INLINE bool bvh_leaf_triangle_hit(const WatertightRay* r, __global const BvhTriangle* tri, float tmax,
                                            float* t, float* b1, float* b2) {
  return intersect_triangle(r, load3(tri->v0), load3(tri->v1), load3(tri->v2), tmax, t, b1, b2);
}

// Leaf position of a hit to its stable primitive index
Hit bvh_hit_to_prim(Hit leaf_hit, __global const BvhTriangle* tris) {
  Hit hit = leaf_hit;  // a copy: struct parameters are never assigned (README, Kernel portability)
  if (hit.prim >= 0) hit.prim = (int)tris[hit.prim].prim;
  return hit;
}

// 1/d with zero components replaced by a tiny value of the same sign: finite, never NaN
float3 safe_inverse(float3 d) {
  const float tiny = 1e-30f;
  return (float3)(1.0f / (fabs(d.x) > tiny ? d.x : copysign(tiny, d.x)),
                  1.0f / (fabs(d.y) > tiny ? d.y : copysign(tiny, d.y)),
                  1.0f / (fabs(d.z) > tiny ? d.z : copysign(tiny, d.z)));
}

// Plain compares instead of fmax/fmin: the slab distances are never NaN
float4 bvh_max4(float4 a, float4 b) { return a > b ? a : b; }
float4 bvh_min4(float4 a, float4 b) { return a < b ? a : b; }

// Orders (d[a], c[a]) and (d[b], c[b]) by distance
#define BVH_SORT2(da, ca, db, cb) \
  {                               \
    bool s_ = db < da;            \
    float dt_ = s_ ? db : da;     \
    int ct_ = s_ ? cb : ca;       \
    db = s_ ? da : db;            \
    cb = s_ ? ca : cb;            \
    da = dt_;                     \
    ca = ct_;                     \
  }

// A ray's constants for the node test: origin and inverse direction splatted, and the
// offsets (in floats, within a node) of the slabs' near planes: lo_* where the direction is
// positive, hi_* (4 floats on) where it is negative; the far planes are the others. Unused
// slots (lo > hi) then give an entry beyond the exit.
typedef struct {
  float4 ox, oy, oz, ix, iy, iz;
  int near_x, near_y, near_z;
} BvhRay;

CD_ALWAYS_INLINE BvhRay bvh_ray(Ray ray) {
  BvhRay r;
  float3 inv_dir = safe_inverse(ray.dir);
  r.ox = (float4)(ray.org.x), r.oy = (float4)(ray.org.y), r.oz = (float4)(ray.org.z);
  r.ix = (float4)(inv_dir.x), r.iy = (float4)(inv_dir.y), r.iz = (float4)(inv_dir.z);
  r.near_x = inv_dir.x >= 0.0f ? 0 : 4;
  r.near_y = inv_dir.y >= 0.0f ? 8 : 12;
  r.near_z = inv_dir.z >= 0.0f ? 16 : 20;
  return r;
}

// The children of node `ref` that the ray enters before tmax, nearest first: entry
// distances d[0..3] (INFINITY: missed) and references c[0..3]
CD_ALWAYS_INLINE void bvh_node_children(const BvhRay* r, __global const BvhNode* nodes, int ref, float tmax, float* d,
                                        int* c) {
  __global const float* b = (__global const float*)&nodes[ref];
  int far_x = r->near_x ^ 4, far_y = r->near_y ^ 4, far_z = r->near_z ^ 4;
  float4 enter =
      bvh_max4(bvh_max4((vload4(0, b + r->near_x) - r->ox) * r->ix, (vload4(0, b + r->near_y) - r->oy) * r->iy),
               bvh_max4((vload4(0, b + r->near_z) - r->oz) * r->iz, (float4)(0.0f)));
  float4 exit = bvh_min4(bvh_min4((vload4(0, b + far_x) - r->ox) * r->ix, (vload4(0, b + far_y) - r->oy) * r->iy),
                         bvh_min4((vload4(0, b + far_z) - r->oz) * r->iz, (float4)(tmax)));
  // Robust exit (Ize 2013, Robust BVH Ray Traversal): widen by 2 gamma(3), with room
  // for OpenCL's 2.5 ulp division in inv_dir
  float4 e = enter <= exit * 1.000001f ? enter : (float4)(INFINITY);
  int4 k = vload4(0, nodes[ref].child);
  float d0 = e.s0, d1 = e.s1, d2 = e.s2, d3 = e.s3;
  int c0 = k.s0, c1 = k.s1, c2 = k.s2, c3 = k.s3;
  BVH_SORT2(d0, c0, d1, c1);
  BVH_SORT2(d2, c2, d3, c3);
  BVH_SORT2(d0, c0, d2, c2);
  BVH_SORT2(d1, c1, d3, c3);
  BVH_SORT2(d1, c1, d2, c2);
  d[0] = d0, d[1] = d1, d[2] = d2, d[3] = d3;
  c[0] = c0, c[1] = c1, c[2] = c2, c[3] = c3;
}

// Does triangle i (leaf position) count as a hit in (0, tmax)?
CD_ALWAYS_INLINE bool bvh_leaf_hit(const struct SceneData* sc, const WatertightRay* wr,
                                   __global const BvhTriangle* tris, int i, uint flags, Ray ray, float tmax, float* t,
                                   float* b1, float* b2) {
  return bvh_leaf_triangle_hit(wr, &tris[i], tmax, t, b1, b2)
#if CD_FEATURE_ALPHA
         && (!(flags & BVH_TRI_ALPHA_TEST) || scene_alpha_passes(sc, tris[i].prim, *b1, *b2, ray))
#endif
      ;
}

// Closest hit in (0, tmax); `sc` goes to the alpha test
Hit bvh_intersect(const struct SceneData* sc, __global const BvhNode* nodes, __global const BvhTriangle* tris, Ray ray,
                  float tmax) {
  Hit hit;
  hit.t = tmax;
  hit.prim = -1;
  hit.b1 = hit.b2 = 0.0f;
  WatertightRay wr = watertight_ray(ray);
  BvhRay br = bvh_ray(ray);
  int stack[BVH_STACK_SIZE];
  float stack_entry[BVH_STACK_SIZE];
  int sp = 0;
  int ref = 0;  // >= 0: a node; < 0: a leaf starting at triangle ~ref
  while (true) {
    if (ref >= 0) {
      float d[4];
      int c[4];
      bvh_node_children(&br, nodes, ref, hit.t, d, c);
      if (d[0] != INFINITY) {
        // Farther hit children onto the stack (farthest deepest), the nearest next
        stack[sp] = c[3];
        stack_entry[sp] = d[3];
        sp += d[3] != INFINITY;
        stack[sp] = c[2];
        stack_entry[sp] = d[2];
        sp += d[2] != INFINITY;
        stack[sp] = c[1];
        stack_entry[sp] = d[1];
        sp += d[1] != INFINITY;
        ref = c[0];
        continue;
      }
    } else {
      for (int i = ~ref;; ++i) {
        float t, b1, b2;
        uint flags = tris[i].flags;
        if (bvh_leaf_hit(sc, &wr, tris, i, flags, ray, hit.t, &t, &b1, &b2)) {
          hit.t = t;
          hit.b1 = b1;
          hit.b2 = b2;
          hit.prim = i;  // leaf position until the end
        }
        if (flags & BVH_TRI_LAST) break;
      }
    }
    // Pop, skipping entries that start beyond the closest hit found since the push
    do {
      if (sp == 0) return bvh_hit_to_prim(hit, tris);
      --sp;
      ref = stack[sp];
    } while (stack_entry[sp] > hit.t);
  }
}

// Anything in (0, tmax) that counts as a hit? The first hit found ends the walk, so tmax
// stays the bound, and a child entered beyond it is not pushed: the stack needs no
// distances. The closest-hit walk skips such entries when it pops them; the nodes visited,
// and their order, are the same.
bool bvh_occluded(const struct SceneData* sc, __global const BvhNode* nodes, __global const BvhTriangle* tris, Ray ray,
                  float tmax) {
  WatertightRay wr = watertight_ray(ray);
  BvhRay br = bvh_ray(ray);
  float bound = fmin(tmax, FLT_MAX);  // a pushed child enters at or before tmax, and finitely
  int stack[BVH_STACK_SIZE];
  int sp = 0;
  int ref = 0;  // >= 0: a node; < 0: a leaf starting at triangle ~ref
  while (true) {
    if (ref >= 0) {
      float d[4];
      int c[4];
      bvh_node_children(&br, nodes, ref, tmax, d, c);
      if (d[0] != INFINITY) {
        stack[sp] = c[3];
        sp += d[3] <= bound;
        stack[sp] = c[2];
        sp += d[2] <= bound;
        stack[sp] = c[1];
        sp += d[1] <= bound;
        ref = c[0];
        continue;
      }
    } else {
      for (int i = ~ref;; ++i) {
        float t, b1, b2;
        uint flags = tris[i].flags;
        if (bvh_leaf_hit(sc, &wr, tris, i, flags, ray, tmax, &t, &b1, &b2)) return true;
        if (flags & BVH_TRI_LAST) break;
      }
    }
    if (sp == 0) return false;
    ref = stack[--sp];
  }
}
