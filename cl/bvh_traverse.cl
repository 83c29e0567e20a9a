// BVH traversal: a short stack, nearer child first, any-hit early exit for shadow rays.
// The node and leaf layout (BvhNode, BvhTriangle) is private to this file and
// host/bvh_builder.cpp; everything else sees hits by stable primitive index.
// Hits on triangles flagged BVH_TRI_ALPHA_TEST count only where the scene's alpha test
// says so (cut-outs, stochastic opacity): that code is compiled in with CD_FEATURE_ALPHA.

#define BVH_STACK_SIZE 64

#ifndef CD_FEATURE_ALPHA
#define CD_FEATURE_ALPHA 1
#endif

// Does the hit at barycentrics (b1, b2) of primitive `prim` along `ray` count? Defined by
// the scene (cl/alpha.cl); the traversal passes `sc` through without reading it.
struct SceneData;
bool scene_alpha_passes(const struct SceneData* sc, uint prim, float b1, float b2, Ray ray);

// Plain compares instead of fmin/fmax: the slab distances below are never NaN
float max4_f(float a, float b, float c, float d) {
  float ab = a > b ? a : b, cd = c > d ? c : d;
  return ab > cd ? ab : cd;
}

float min4_f(float a, float b, float c, float d) {
  float ab = a < b ? a : b, cd = c < d ? c : d;
  return ab < cd ? ab : cd;
}

bool bvh_leaf_triangle_hit(const WatertightRay* r, __global const BvhTriangle* tri, float tmax,
                           float* t, float* b1, float* b2) {
  return intersect_triangle(r, load3(tri->v0), load3(tri->v1), load3(tri->v2), tmax, t, b1, b2);
}

// Leaf position of a hit to its stable primitive index
Hit bvh_hit_to_prim(Hit hit, __global const BvhTriangle* tris) {
  if (hit.prim >= 0) hit.prim = (int)tris[hit.prim].prim;
  return hit;
}

// Slab test; returns the entry distance or INFINITY on a miss
float bvh_box_entry(__global const BvhNode* node, float3 org, float3 inv_dir, float tmax) {
  float3 t0 = (load3(node->bmin) - org) * inv_dir;
  float3 t1 = (load3(node->bmax) - org) * inv_dir;
  float enter = max4_f(t0.x < t1.x ? t0.x : t1.x, t0.y < t1.y ? t0.y : t1.y,
                       t0.z < t1.z ? t0.z : t1.z, 0.0f);
  float exit = min4_f(t0.x > t1.x ? t0.x : t1.x, t0.y > t1.y ? t0.y : t1.y,
                      t0.z > t1.z ? t0.z : t1.z, tmax);
  // Robust exit (Ize 2013, Robust BVH Ray Traversal): widen by 2 gamma(3), with room
  // for OpenCL's 2.5 ulp division in inv_dir
  return enter <= exit * 1.000001f ? enter : INFINITY;
}

// 1/d with zero components replaced by a tiny value of the same sign: finite, never NaN
float3 safe_inverse(float3 d) {
  const float tiny = 1e-30f;
  return (float3)(1.0f / (fabs(d.x) > tiny ? d.x : copysign(tiny, d.x)),
                  1.0f / (fabs(d.y) > tiny ? d.y : copysign(tiny, d.y)),
                  1.0f / (fabs(d.z) > tiny ? d.z : copysign(tiny, d.z)));
}

// Closest hit in (0, tmax), or with any_hit the first hit found; `sc` goes to the alpha test
Hit bvh_intersect(const struct SceneData* sc, __global const BvhNode* nodes,
                  __global const BvhTriangle* tris, Ray ray, float tmax, bool any_hit) {
  Hit hit;
  hit.t = tmax;
  hit.prim = -1;
  hit.b1 = hit.b2 = 0.0f;
  WatertightRay wr = watertight_ray(ray);
  float3 inv_dir = safe_inverse(ray.dir);
  if (bvh_box_entry(&nodes[0], ray.org, inv_dir, tmax) == INFINITY) return hit;

  int stack[BVH_STACK_SIZE];
  float stack_entry[BVH_STACK_SIZE];
  int sp = 0;
  int index = 0;
  while (true) {
    __global const BvhNode* node = &nodes[index];
    if (node->right < 0) {
      int end = node->left - node->right;
      for (int i = node->left; i < end; ++i) {
        float t, b1, b2;
        if (bvh_leaf_triangle_hit(&wr, &tris[i], hit.t, &t, &b1, &b2)) {
#if CD_FEATURE_ALPHA
          if ((tris[i].flags & BVH_TRI_ALPHA_TEST) && !scene_alpha_passes(sc, tris[i].prim, b1, b2, ray))
            continue;
#endif
          hit.t = t;
          hit.b1 = b1;
          hit.b2 = b2;
          hit.prim = i;  // leaf position until the end
          if (any_hit) return bvh_hit_to_prim(hit, tris);
        }
      }
    } else {
      float d0 = bvh_box_entry(&nodes[node->left], ray.org, inv_dir, hit.t);
      float d1 = bvh_box_entry(&nodes[node->right], ray.org, inv_dir, hit.t);
      bool left_first = d0 <= d1;
      float d_near = left_first ? d0 : d1, d_far = left_first ? d1 : d0;
      if (d_near != INFINITY) {
        if (d_far != INFINITY) {
          stack[sp] = left_first ? node->right : node->left;
          stack_entry[sp++] = d_far;
        }
        index = left_first ? node->left : node->right;
        continue;
      }
    }
    // Pop, skipping nodes that start beyond the closest hit found since the push
    do {
      if (sp == 0) return bvh_hit_to_prim(hit, tris);
      index = stack[--sp];
    } while (stack_entry[sp] > hit.t);
  }
}

bool bvh_occluded(const struct SceneData* sc, __global const BvhNode* nodes,
                  __global const BvhTriangle* tris, Ray ray, float tmax) {
  return bvh_intersect(sc, nodes, tris, ray, tmax, true).prim >= 0;
}
