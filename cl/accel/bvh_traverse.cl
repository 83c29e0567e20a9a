// 8-wide BVH traversal: one float8 slab test per axis tests a node's eight child boxes at
// once (AVX on x86 CPUs); hit children are visited nearest first (a vector sorting network
// on their entry distances, the others on a stack, stored with one vstore8); any-hit
// early exit for shadow rays, whose stack holds node references only (half the private
// memory of the closest-hit one's).
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
float8 bvh_max8(float8 a, float8 b) { return a > b ? a : b; }
float8 bvh_min8(float8 a, float8 b) { return a < b ? a : b; }

// One step of a bitonic sorting network (Batcher 1968, Sorting networks and their
// applications) on eight lanes: lane i and its partner (dp, cp: the same vectors with
// lanes i and i ^ j exchanged) trade places when out of order, the lanes in `first`
// (-1) keeping the larger distance, the others the smaller. Ties stay put.
#define BVH_SORT_STEP(d, c, swz, first)                           \
  {                                                               \
    float8 dp_ = (d).swz;                                         \
    int8 cp_ = (c).swz;                                           \
    int8 s_ = ((first) & (dp_ > (d))) | (~(first) & (dp_ < (d))); \
    d = select(d, dp_, s_);                                       \
    c = select(c, cp_, s_);                                       \
  }

// A ray's constants for the node test: origin and inverse direction splatted, and the
// offsets (in floats, within a node) of the slabs' near planes: lo_* where the direction is
// positive, hi_* (8 floats on) where it is negative; the far planes are the others. Unused
// slots (lo > hi) then give an entry beyond the exit.
typedef struct {
  float8 ox, oy, oz, ix, iy, iz;
  int near_x, near_y, near_z;
} BvhRay;

CD_ALWAYS_INLINE BvhRay bvh_ray(Ray ray) {
  BvhRay r;
  float3 inv_dir = safe_inverse(ray.dir);
  r.ox = (float8)(ray.org.x), r.oy = (float8)(ray.org.y), r.oz = (float8)(ray.org.z);
  r.ix = (float8)(inv_dir.x), r.iy = (float8)(inv_dir.y), r.iz = (float8)(inv_dir.z);
  r.near_x = inv_dir.x >= 0.0f ? 0 : 8;
  r.near_y = inv_dir.y >= 0.0f ? 16 : 24;
  r.near_z = inv_dir.z >= 0.0f ? 32 : 40;
  return r;
}

// The children of node `ref` that the ray enters before tmax, farthest first: entry
// distances *d and references *c, lanes 0 .. n - 1 the n hit children (the nearest in lane
// n - 1), the missed ones after them (distance -INFINITY). Returns n.
CD_ALWAYS_INLINE int bvh_node_children(const BvhRay* r, __global const BvhNode* nodes, int ref, float tmax, float8* d,
                                       int8* c) {
  __global const float* b = (__global const float*)&nodes[ref];
  int far_x = r->near_x ^ 8, far_y = r->near_y ^ 8, far_z = r->near_z ^ 8;
  float8 enter =
      bvh_max8(bvh_max8((vload8(0, b + r->near_x) - r->ox) * r->ix, (vload8(0, b + r->near_y) - r->oy) * r->iy),
               bvh_max8((vload8(0, b + r->near_z) - r->oz) * r->iz, (float8)(0.0f)));
  float8 exit = bvh_min8(bvh_min8((vload8(0, b + far_x) - r->ox) * r->ix, (vload8(0, b + far_y) - r->oy) * r->iy),
                         bvh_min8((vload8(0, b + far_z) - r->oz) * r->iz, (float8)(tmax)));
  // Robust exit (Ize 2013, Robust BVH Ray Traversal): widen by 2 gamma(3), with room
  // for OpenCL's 2.5 ulp division in inv_dir
  int8 hit = enter <= exit * 1.000001f;
  float8 e = select((float8)(-INFINITY), enter, hit);
  int8 k = vload8(0, nodes[ref].child);
  // Descending: six bitonic steps, all lanes at once
  BVH_SORT_STEP(e, k, s10325476, ((int8)(-1, 0, 0, -1, -1, 0, 0, -1)));
  BVH_SORT_STEP(e, k, s23016745, ((int8)(-1, -1, 0, 0, 0, 0, -1, -1)));
  BVH_SORT_STEP(e, k, s10325476, ((int8)(-1, 0, -1, 0, 0, -1, 0, -1)));
  BVH_SORT_STEP(e, k, s45670123, ((int8)(-1, -1, -1, -1, 0, 0, 0, 0)));
  BVH_SORT_STEP(e, k, s23016745, ((int8)(-1, -1, 0, 0, -1, -1, 0, 0)));
  BVH_SORT_STEP(e, k, s10325476, ((int8)(-1, 0, -1, 0, -1, 0, -1, 0)));
  *d = e;
  *c = k;
  int4 h = hit.lo + hit.hi;
  int2 h2 = h.lo + h.hi;
  return -(h2.x + h2.y);
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
  int stack[BVH_STACK_SIZE + BVH_WIDTH];  // room for a full node's vstore8 at the top
  float stack_entry[BVH_STACK_SIZE + BVH_WIDTH];
  int sp = 0;
  int ref = 0;  // >= 0: a node; < 0: a leaf starting at triangle ~ref
  while (true) {
    if (ref >= 0) {
      float8 d;
      int8 c;
      int n = bvh_node_children(&br, nodes, ref, hit.t, &d, &c);
      if (n > 0) {
        // The hit children onto the stack, farthest deepest; the nearest (on top) is next
        vstore8(c, 0, stack + sp);
        vstore8(d, 0, stack_entry + sp);
        sp += n - 1;
        ref = stack[sp];
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
// stays the bound that the node test applies to every child's exit: the stack needs no
// distances. Until that hit the nodes visited, and their order, are the closest-hit
// walk's (which skips an entry beyond the closest hit only once it has one).
bool bvh_occluded(const struct SceneData* sc, __global const BvhNode* nodes, __global const BvhTriangle* tris, Ray ray,
                  float tmax) {
  WatertightRay wr = watertight_ray(ray);
  BvhRay br = bvh_ray(ray);
  int stack[BVH_STACK_SIZE + BVH_WIDTH];
  int sp = 0;
  int ref = 0;  // >= 0: a node; < 0: a leaf starting at triangle ~ref
  while (true) {
    if (ref >= 0) {
      float8 d;
      int8 c;
      int n = bvh_node_children(&br, nodes, ref, tmax, &d, &c);
      if (n > 0) {
        vstore8(c, 0, stack + sp);
        sp += n - 1;
        ref = stack[sp];
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
