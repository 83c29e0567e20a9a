// 4-wide BVH traversal: one float4 slab test per axis tests a node's four child boxes at
// once; hit children are visited nearest first (a sorting network on their entry
// distances, the others on a short stack); any-hit early exit for shadow rays.
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

// Closest hit in (0, tmax), or with any_hit the first hit found; `sc` goes to the alpha test
Hit bvh_intersect(const struct SceneData* sc, __global const BvhNode* nodes, __global const BvhTriangle* tris, Ray ray,
                  float tmax, bool any_hit) {
  Hit hit;
  hit.t = tmax;
  hit.prim = -1;
  hit.b1 = hit.b2 = 0.0f;
  WatertightRay wr = watertight_ray(ray);
  float3 inv_dir = safe_inverse(ray.dir);
  float4 ox = (float4)(ray.org.x), oy = (float4)(ray.org.y), oz = (float4)(ray.org.z);
  float4 ix = (float4)(inv_dir.x), iy = (float4)(inv_dir.y), iz = (float4)(inv_dir.z);
  // Offsets (in floats, within a node) of the slabs' near planes: lo_* where the
  // direction is positive, hi_* (4 floats on) where it is negative; the far planes are the
  // others. Unused slots (lo > hi) then give an entry beyond the exit.
  int near_x = inv_dir.x >= 0.0f ? 0 : 4, near_y = inv_dir.y >= 0.0f ? 8 : 12, near_z = inv_dir.z >= 0.0f ? 16 : 20;
  int far_x = near_x ^ 4, far_y = near_y ^ 4, far_z = near_z ^ 4;

  int stack[BVH_STACK_SIZE];
  float stack_entry[BVH_STACK_SIZE];
  int sp = 0;
  int ref = 0;  // >= 0: a node; < 0: a leaf starting at triangle ~ref
  while (true) {
    if (ref >= 0) {
      __global const float* b = (__global const float*)&nodes[ref];
      float4 enter = bvh_max4(bvh_max4((vload4(0, b + near_x) - ox) * ix, (vload4(0, b + near_y) - oy) * iy),
                              bvh_max4((vload4(0, b + near_z) - oz) * iz, (float4)(0.0f)));
      float4 exit = bvh_min4(bvh_min4((vload4(0, b + far_x) - ox) * ix, (vload4(0, b + far_y) - oy) * iy),
                             bvh_min4((vload4(0, b + far_z) - oz) * iz, (float4)(hit.t)));
      // Robust exit (Ize 2013, Robust BVH Ray Traversal): widen by 2 gamma(3), with room
      // for OpenCL's 2.5 ulp division in inv_dir
      float4 d = enter <= exit * 1.000001f ? enter : (float4)(INFINITY);
      int4 c = vload4(0, nodes[ref].child);
      float d0 = d.s0, d1 = d.s1, d2 = d.s2, d3 = d.s3;
      int c0 = c.s0, c1 = c.s1, c2 = c.s2, c3 = c.s3;
      BVH_SORT2(d0, c0, d1, c1);
      BVH_SORT2(d2, c2, d3, c3);
      BVH_SORT2(d0, c0, d2, c2);
      BVH_SORT2(d1, c1, d3, c3);
      BVH_SORT2(d1, c1, d2, c2);
      if (d0 != INFINITY) {
        // Farther hit children onto the stack (farthest deepest), the nearest next
        stack[sp] = c3;
        stack_entry[sp] = d3;
        sp += d3 != INFINITY;
        stack[sp] = c2;
        stack_entry[sp] = d2;
        sp += d2 != INFINITY;
        stack[sp] = c1;
        stack_entry[sp] = d1;
        sp += d1 != INFINITY;
        ref = c0;
        continue;
      }
    } else {
      for (int i = ~ref;; ++i) {
        float t, b1, b2;
        uint flags = tris[i].flags;
        if (bvh_leaf_triangle_hit(&wr, &tris[i], hit.t, &t, &b1, &b2)
#if CD_FEATURE_ALPHA
            && (!(flags & BVH_TRI_ALPHA_TEST) || scene_alpha_passes(sc, tris[i].prim, b1, b2, ray))
#endif
        ) {
          hit.t = t;
          hit.b1 = b1;
          hit.b2 = b2;
          hit.prim = i;  // leaf position until the end
          if (any_hit) return bvh_hit_to_prim(hit, tris);
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

bool bvh_occluded(const struct SceneData* sc, __global const BvhNode* nodes, __global const BvhTriangle* tris, Ray ray,
                  float tmax) {
  return bvh_intersect(sc, nodes, tris, ray, tmax, true).prim >= 0;
}
