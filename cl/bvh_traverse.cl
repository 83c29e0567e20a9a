// BVH traversal: a short stack, nearer child first, any-hit early exit for shadow rays.

#define BVH_STACK_SIZE 64

// Slab test; returns the entry distance or INFINITY on a miss.
float bvh_box_entry(__global const BvhNode* node, float3 org, float3 inv_dir, float tmax) {
  float3 t0 = (load3(node->bmin) - org) * inv_dir;
  float3 t1 = (load3(node->bmax) - org) * inv_dir;
  float3 lo = fmin(t0, t1), hi = fmax(t0, t1);
  float enter = fmax(fmax(lo.x, lo.y), fmax(lo.z, 0.0f));
  // Robust exit (Ize 2013, Robust BVH Ray Traversal): widen by 2 gamma(3)
  float exit = fmin(fmin(hi.x, hi.y), fmin(hi.z, tmax)) * 1.00000036f;
  return enter <= exit ? enter : INFINITY;
}

float3 safe_inverse(float3 d) {
  const float tiny = 1e-30f;
  return (float3)(1.0f / (fabs(d.x) > tiny ? d.x : copysign(tiny, d.x)),
                  1.0f / (fabs(d.y) > tiny ? d.y : copysign(tiny, d.y)),
                  1.0f / (fabs(d.z) > tiny ? d.z : copysign(tiny, d.z)));
}

// Closest hit in (0, tmax), or with any_hit the first hit found.
Hit bvh_intersect(__global const BvhNode* nodes, __global const Triangle* tris, Ray ray,
                  float tmax, bool any_hit) {
  Hit hit;
  hit.t = tmax;
  hit.tri = -1;
  hit.b1 = hit.b2 = 0.0f;
  WatertightRay wr = watertight_ray(ray);
  float3 inv_dir = safe_inverse(ray.dir);
  if (bvh_box_entry(&nodes[0], ray.org, inv_dir, tmax) == INFINITY) return hit;

  int stack[BVH_STACK_SIZE];
  int sp = 0;
  int index = 0;
  while (true) {
    __global const BvhNode* node = &nodes[index];
    if (node->right < 0) {
      int end = node->left - node->right;
      for (int i = node->left; i < end; ++i) {
        float t, b1, b2;
        if (intersect_triangle_at(&wr, &tris[i], hit.t, &t, &b1, &b2)) {
          hit.t = t;
          hit.b1 = b1;
          hit.b2 = b2;
          hit.tri = i;
          if (any_hit) return hit;
        }
      }
    } else {
      float d0 = bvh_box_entry(&nodes[node->left], ray.org, inv_dir, hit.t);
      float d1 = bvh_box_entry(&nodes[node->right], ray.org, inv_dir, hit.t);
      int near = d0 <= d1 ? node->left : node->right;
      int far = d0 <= d1 ? node->right : node->left;
      float d_near = fmin(d0, d1), d_far = fmax(d0, d1);
      if (d_near != INFINITY) {
        if (d_far != INFINITY && sp < BVH_STACK_SIZE) stack[sp++] = far;
        index = near;
        continue;
      }
    }
    // Pop, skipping nodes whose box now starts beyond the closest hit
    bool found = false;
    while (sp > 0 && !found) {
      index = stack[--sp];
      found = bvh_box_entry(&nodes[index], ray.org, inv_dir, hit.t) != INFINITY;
    }
    if (!found) return hit;
  }
}

bool bvh_occluded(__global const BvhNode* nodes, __global const Triangle* tris, Ray ray,
                  float tmax) {
  return bvh_intersect(nodes, tris, ray, tmax, true).tri >= 0;
}
