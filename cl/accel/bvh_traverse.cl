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

// CD_MOTION_STEPS = K > 0 (motion blur, set by the host with --shutter): the vertices hold
// K + 1 poses across the shutter, the leaves' boxes bound every pose, and a leaf's triangle
// is the scene's at the time the SceneData carries (scene_prim_positions), not the copy in
// BvhTriangle. Camera rays only then go without packets (CD_PACKETS 0).
#ifndef CD_MOTION_STEPS
#define CD_MOTION_STEPS 0
#endif
#if CD_MOTION_STEPS
void scene_prim_positions(const struct SceneData* sc, uint prim, float3* p0, float3* p1, float3* p2);
#endif

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
#if CD_MOTION_STEPS
  float3 v0, v1, v2;
  scene_prim_positions(sc, tris[i].prim, &v0, &v1, &v2);
  return intersect_triangle(wr, v0, v1, v2, tmax, t, b1, b2)
#else
  return bvh_leaf_triangle_hit(wr, &tris[i], tmax, t, b1, b2)
#endif
#if CD_FEATURE_ALPHA
         && (!(flags & BVH_TRI_ALPHA_TEST) || scene_alpha_passes(sc, tris[i].prim, *b1, *b2, ray))
#endif
      ;
}

// Pushes the farther hit children (d: entry distance, INFINITY: missed; c: reference) onto
// the closest-hit stack, the farthest deepest
CD_ALWAYS_INLINE void bvh_push_farther(int* stack, float* stack_entry, int* sp, float d1, int c1, float d2, int c2,
                                       float d3, int c3) {
  int n = *sp;
  stack[n] = c3;
  stack_entry[n] = d3;
  n += d3 != INFINITY;
  stack[n] = c2;
  stack_entry[n] = d2;
  n += d2 != INFINITY;
  stack[n] = c1;
  stack_entry[n] = d1;
  n += d1 != INFINITY;
  *sp = n;
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
        // Farther hit children onto the stack, the nearest next
        bvh_push_farther(stack, stack_entry, &sp, d[1], c[1], d[2], c[2], d[3], c[3]);
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

// ---- Packets of eight rays (CD_PACKETS: CPU devices) ------------------------------------
// Eight rays walk the tree together (Wald, Slusallek, Benthin and Wagner 2001, Interactive
// Rendering with Coherent Ray Tracing): a child is visited when any of the eight enters it,
// nearest first by the smallest entry over the rays, and each node and triangle is loaded once
// for all eight, whose tests run in float8 (eight SIMD lanes on a CPU, where a work-item
// otherwise runs scalar). Meant for coherent rays (the camera rays of neighbouring pixels):
// each ray's closest hit is found with bvh_intersect's arithmetic, among a superset of the
// triangles bvh_intersect tests for it.

float8 bvh_pick8(int8 k, float8 x, float8 y, float8 z) { return select(select(z, y, k == 1), x, k == 0); }

// edge_function on eight lanes
float8 edge_function8(float8 px, float8 py, float8 qx, float8 qy) {
  int8 swap = px < qx || (px == qx && py < qy);
  float8 ax = select(px, qx, swap), ay = select(py, qy, swap);
  float8 bx = select(qx, px, swap), by = select(qy, py, swap);
  float8 e = bx * ay - by * ax;
  return select(e, -e, swap);
}

float bvh_min8(float8 v) {
  float4 m = fmin(v.lo, v.hi);
  return fmin(fmin(m.x, m.y), fmin(m.z, m.w));
}

// Eight rays' constants for the eight-lane walks: bvh_ray's and watertight_ray's, per lane
typedef struct {
  float8 ox, oy, oz;  // origins
  float8 ix, iy, iz;  // safe_inverse of the directions
  float8 sx, sy, sz;  // the shear
  int8 kx, ky, kz;    // the permutation
} BvhRays8;

BvhRays8 bvh_rays8(const Ray* rays) {
  float c[6][8];
  for (int l = 0; l < 8; ++l) {
    c[0][l] = rays[l].org.x, c[1][l] = rays[l].org.y, c[2][l] = rays[l].org.z;
    c[3][l] = rays[l].dir.x, c[4][l] = rays[l].dir.y, c[5][l] = rays[l].dir.z;
  }
  BvhRays8 r;
  r.ox = vload8(0, c[0]), r.oy = vload8(0, c[1]), r.oz = vload8(0, c[2]);
  float8 dx = vload8(0, c[3]), dy = vload8(0, c[4]), dz = vload8(0, c[5]);
  float8 adx = fabs(dx), ady = fabs(dy), adz = fabs(dz);
  int8 kz = select(select((int8)(2), (int8)(1), ady >= adz), select((int8)(2), (int8)(0), adx >= adz), adx >= ady);
  int8 kx = select(kz + 1, (int8)(0), kz == 2);
  int8 ky = select(kx + 1, (int8)(0), kx == 2);
  float8 pdx = bvh_pick8(kx, dx, dy, dz), pdy = bvh_pick8(ky, dx, dy, dz), pdz = bvh_pick8(kz, dx, dy, dz);
  int8 swap_xy = pdz < 0.0f;  // keep the winding
  r.kx = select(kx, ky, swap_xy);
  r.ky = select(ky, kx, swap_xy);
  r.kz = kz;
  r.sx = select(pdx, pdy, swap_xy) / pdz, r.sy = select(pdy, pdx, swap_xy) / pdz, r.sz = 1.0f / pdz;
  const float tiny = 1e-30f;
  r.ix = 1.0f / select(copysign((float8)(tiny), dx), dx, fabs(dx) > tiny);
  r.iy = 1.0f / select(copysign((float8)(tiny), dy), dy, fabs(dy) > tiny);
  r.iz = 1.0f / select(copysign((float8)(tiny), dz), dz, fabs(dz) > tiny);
  return r;
}

// intersect_triangle on eight lanes, the vertices' coordinates v[0..8] (v0, v1, v2) per
// lane: the lanes that hit in (0, tmax), with t and the barycentrics of v1 and v2 set there
CD_ALWAYS_INLINE int8 intersect_triangle8(const BvhRays8* r, const float8* v, float8 tmax, float8* t, float8* b1,
                                          float8* b2) {
#pragma OPENCL FP_CONTRACT OFF
  float8 a0 = v[0] - r->ox, a1 = v[1] - r->oy, a2 = v[2] - r->oz;
  float8 q0 = v[3] - r->ox, q1 = v[4] - r->oy, q2 = v[5] - r->oz;
  float8 e0 = v[6] - r->ox, e1 = v[7] - r->oy, e2 = v[8] - r->oz;
  float8 az = bvh_pick8(r->kz, a0, a1, a2), bz = bvh_pick8(r->kz, q0, q1, q2), cz = bvh_pick8(r->kz, e0, e1, e2);
  float8 ax = bvh_pick8(r->kx, a0, a1, a2) - r->sx * az, ay = bvh_pick8(r->ky, a0, a1, a2) - r->sy * az;
  float8 bx = bvh_pick8(r->kx, q0, q1, q2) - r->sx * bz, by = bvh_pick8(r->ky, q0, q1, q2) - r->sy * bz;
  float8 cx = bvh_pick8(r->kx, e0, e1, e2) - r->sx * cz, cy = bvh_pick8(r->ky, e0, e1, e2) - r->sy * cz;
  float8 u = edge_function8(bx, by, cx, cy), w1 = edge_function8(cx, cy, ax, ay), w2 = edge_function8(ax, ay, bx, by);
  int8 outside = (u < 0.0f || w1 < 0.0f || w2 < 0.0f) && (u > 0.0f || w1 > 0.0f || w2 > 0.0f);
  float8 det = u + w1 + w2;
  float8 tt = u * (r->sz * az) + w1 * (r->sz * bz) + w2 * (r->sz * cz);
  int8 beyond = select(tt >= 0.0f || tt <= tmax * det, tt <= 0.0f || tt >= tmax * det, det > 0.0f);
  float8 inv_det = 1.0f / det;
  *t = tt * inv_det;
  *b1 = w1 * inv_det;
  *b2 = w2 * inv_det;
  return !outside && det != 0.0f && !beyond;
}

// Entry distances of eight rays into child j of the node at b (INFINITY: missed). Slabs by
// fmin/fmax, as the rays' directions may differ in sign; an unused slot (lo > hi) is missed.
float8 bvh_child_entry8(__global const float* b, int j, const BvhRays8* r, float8 tmax) {
  float8 ox = r->ox, oy = r->oy, oz = r->oz, ix = r->ix, iy = r->iy, iz = r->iz;
  float lx = b[j], hx = b[4 + j], ly = b[8 + j], hy = b[12 + j], lz = b[16 + j], hz = b[20 + j];
  float8 tx0 = (lx - ox) * ix, tx1 = (hx - ox) * ix, ty0 = (ly - oy) * iy, ty1 = (hy - oy) * iy;
  float8 tz0 = (lz - oz) * iz, tz1 = (hz - oz) * iz;
  float8 enter = fmax(fmax(fmin(tx0, tx1), fmin(ty0, ty1)), fmax(fmin(tz0, tz1), (float8)(0.0f)));
  float8 exit = fmin(fmin(fmax(tx0, tx1), fmax(ty0, ty1)), fmin(fmax(tz0, tz1), tmax));
  return select((float8)(INFINITY), enter, enter <= exit * 1.000001f && lx <= hx);
}

// Closest hits of rays[0..7] in (0, tmax[l]); a ray with tmax 0 finds nothing
void bvh_intersect8(const struct SceneData* sc, __global const BvhNode* nodes, __global const BvhTriangle* tris,
                    const Ray* rays, const float* tmax, Hit* hits) {
  BvhRays8 r = bvh_rays8(rays);
  float8 ht = vload8(0, tmax), hb1 = (float8)(0.0f), hb2 = (float8)(0.0f);
  int8 hprim = (int8)(-1);
  int stack[BVH_STACK_SIZE];
  float stack_entry[BVH_STACK_SIZE];
  int sp = 0;
  int ref = 0;  // >= 0: a node; < 0: a leaf starting at triangle ~ref
  while (true) {
    if (ref >= 0) {
      __global const float* b = (__global const float*)&nodes[ref];
      float d0 = bvh_min8(bvh_child_entry8(b, 0, &r, ht));
      float d1 = bvh_min8(bvh_child_entry8(b, 1, &r, ht));
      float d2 = bvh_min8(bvh_child_entry8(b, 2, &r, ht));
      float d3 = bvh_min8(bvh_child_entry8(b, 3, &r, ht));
      int4 k = vload4(0, nodes[ref].child);
      int c0 = k.s0, c1 = k.s1, c2 = k.s2, c3 = k.s3;
      BVH_SORT2(d0, c0, d1, c1);
      BVH_SORT2(d2, c2, d3, c3);
      BVH_SORT2(d0, c0, d2, c2);
      BVH_SORT2(d1, c1, d3, c3);
      BVH_SORT2(d1, c1, d2, c2);
      if (d0 != INFINITY) {
        bvh_push_farther(stack, stack_entry, &sp, d1, c1, d2, c2, d3, c3);
        ref = c0;
        continue;
      }
    } else {
      for (int i = ~ref;; ++i) {
        __global const BvhTriangle* tri = &tris[i];
        uint flags = tri->flags;
        float8 v[9] = {(float8)(tri->v0[0]), (float8)(tri->v0[1]), (float8)(tri->v0[2]),
                       (float8)(tri->v1[0]), (float8)(tri->v1[1]), (float8)(tri->v1[2]),
                       (float8)(tri->v2[0]), (float8)(tri->v2[1]), (float8)(tri->v2[2])};
        float8 t, b1, b2;
        int8 hit = intersect_triangle8(&r, v, ht, &t, &b1, &b2);
#if CD_FEATURE_ALPHA
        if ((flags & BVH_TRI_ALPHA_TEST) && any(hit)) {
          int h[8];
          float vb1[8], vb2[8];
          vstore8(hit, 0, h);
          vstore8(b1, 0, vb1);
          vstore8(b2, 0, vb2);
          for (int l = 0; l < 8; ++l)
            if (h[l]) h[l] = scene_alpha_passes(sc, tri->prim, vb1[l], vb2[l], rays[l]) ? -1 : 0;
          hit = vload8(0, h);
        }
#endif
        ht = select(ht, t, hit);
        hb1 = select(hb1, b1, hit);
        hb2 = select(hb2, b2, hit);
        hprim = select(hprim, (int8)(i), hit);
        if (flags & BVH_TRI_LAST) break;
      }
    }
    // Pop, skipping entries that start beyond every ray's closest hit
    float farthest = -bvh_min8(-ht);
    bool more = false;
    while (sp > 0 && !more) {
      --sp;
      ref = stack[sp];
      more = stack_entry[sp] <= farthest;
    }
    if (!more) break;
  }
  float t[8], b1[8], b2[8];
  int p[8];
  vstore8(ht, 0, t);
  vstore8(hb1, 0, b1);
  vstore8(hb2, 0, b2);
  vstore8(hprim, 0, p);
  for (int l = 0; l < 8; ++l) {
    hits[l].t = t[l];
    hits[l].b1 = b1[l];
    hits[l].b2 = b2[l];
    hits[l].prim = p[l] >= 0 ? (int)tris[p[l]].prim : -1;
  }
}
