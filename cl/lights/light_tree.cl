// Light tree (Conty Estevez & Kulla 2018, Importance Sampling of Many Lights with Adaptive
// Tree Splitting): selection descends from the root, taking each child with probability
// proportional to its importance at the shading point, an estimate of the irradiance its
// lights can send there; the selection pmf is the product of those probabilities. A child's
// importance is I cos(theta') cos(theta_i') / d^2: I its summed peak intensity, d the
// distance to the centre of its bounding sphere (the sphere's radius r when ctx.p lies
// inside it, where both cosines are 1), theta' the smallest angle its emission cone can make
// with the direction to ctx.p (the angle from the cone's axis less theta_o and less the angle
// theta_b the sphere subtends; 0 importance beyond theta_e: no light of the child emits
// toward ctx.p), and theta_i' the smallest angle between the shading normal and a direction
// into the sphere (the |cos| the estimator weighs by; 1 in a medium, n = 0). Both cosines
// are kept at least LIGHT_TREE_MIN_COS and the cut-off has a margin of the same size, so
// float rounding never gives 0 to a light that can contribute. A node's four children are
// weighed at once, one child per float4 lane. Every child of nonzero importance is given a
// weight of at least the root's `min_prob` times the sum of the importances before the
// weights are normalized, so a probability of at least min_prob / (1 + 4 min_prob) (also
// when another child's importance is infinite); the host sets min_prob so that the product
// over the deepest trail, times the tree's share, stays above 2^-124: no light's pmf
// underflows (to 0 on devices that flush denormals). Sampling and the pmf of a given light
// (lights_tree_pmf, along its trail) run the same arithmetic, contraction off, so
// STRATEGY_AUTO's two evaluations of a light's selection probability agree exactly.
// Inside a planar emitter of several triangles (cluster nodes) the children are taken by
// their share of the intensity, with no importance to evaluate.
#define LIGHT_TREE_MIN_COS 1e-3f

// The importances of node's four children at ctx (0 in empty slots)
float4 lights_tree_importance(__global const LightTreeNode* node, const LightSampleContext* ctx) {
#pragma OPENCL FP_CONTRACT OFF
  float4 intensity = vload4(0, node->intensity), r = vload4(0, node->radius);
  float4 dx = ctx->p.x - vload4(0, node->centre[0]), dy = ctx->p.y - vload4(0, node->centre[1]),
         dz = ctx->p.z - vload4(0, node->centre[2]);
  float4 dist2 = dx * dx + dy * dy + dz * dz, r2 = r * r;
  int4 outside = isgreater(dist2, r2);
  // 1 / max(d, r): one reciprocal square root serves the direction to ctx.p (outside the
  // sphere, the only place it is used) and the importance's 1 / max(d^2, r^2)
  float4 inv_d = rsqrt(fmax(fmax(dist2, r2), 1e-30f));
  // theta_b, the angle the sphere subtends: its sine r / d and its cosine; the sine of each
  // difference of angles below comes from the addition formula, not from a square root of
  // its cosine
  float4 sin_b = select((float4)(1.0f), fmin(r * inv_d, 1.0f), outside);
  float4 cos_b = sqrt(fmax(1.0f - sin_b * sin_b, 0.0f));
  float4 wx = dx * inv_d, wy = dy * inv_d, wz = dz * inv_d;  // from the child to ctx.p
  // Emitter side: theta' = max(0, theta_w - theta_o - theta_b)
  float4 cos_o = vload4(0, node->cos_o), sin_o = vload4(0, node->sin_o);
  float4 cos_w = vload4(0, node->axis[0]) * wx + vload4(0, node->axis[1]) * wy + vload4(0, node->axis[2]) * wz;
  cos_w = clamp(cos_w, -1.0f, 1.0f);
  float4 sin_w = sqrt(fmax(1.0f - cos_w * cos_w, 0.0f));
  int4 in_cone = isgreaterequal(cos_w, cos_o);  // theta_w <= theta_o
  float4 cos_x = select(cos_w * cos_o + sin_w * sin_o, (float4)(1.0f), in_cone);
  float4 sin_x = select(fmax(sin_w * cos_o - cos_w * sin_o, 0.0f), (float4)(0.0f), in_cone);
  float4 cos_p = select(cos_x * cos_b + sin_x * sin_b, (float4)(1.0f), isgreaterequal(cos_x, cos_b));
  float4 importance = intensity * fmax(cos_p, LIGHT_TREE_MIN_COS);
  importance = select(importance, (float4)(0.0f), isless(cos_p, vload4(0, node->cos_e) - LIGHT_TREE_MIN_COS));
  // Receiver side: theta_i' = max(0, theta_i - theta_b), |cos| to the shading normal
  if (dot(ctx->ns, ctx->ns) > 0.0f) {
    float4 cos_i = fmin(fabs(ctx->ns.x * wx + ctx->ns.y * wy + ctx->ns.z * wz), 1.0f);
    float4 sin_i = sqrt(fmax(1.0f - cos_i * cos_i, 0.0f));
    float4 cos_r = select(cos_i * cos_b + sin_i * sin_b, (float4)(1.0f), isgreaterequal(cos_i, cos_b));
    importance *= fmax(cos_r, LIGHT_TREE_MIN_COS);
  }
  // I cos cos / d^2 outside the sphere, I / r^2 inside
  importance = select(intensity, importance, outside) * (inv_d * inv_d);
  return select((float4)(0.0f), importance, isgreater(intensity, (float4)(0.0f)));
}

// The weights of taking each of node's children at ctx, unnormalized, each nonzero one
// floored at min_prob times their sum (a child is taken with probability q / (q.x + q.y +
// q.z + q.w)); false when none can light ctx.p
bool lights_tree_children(const SceneData* sc, uint node, const LightSampleContext* ctx, float min_prob, float4* q) {
#pragma OPENCL FP_CONTRACT OFF
  __global const LightTreeNode* n = &sc->light_tree[node];
  float4 w = n->cluster ? vload4(0, n->intensity) : lights_tree_importance(n, ctx);
  int4 can_light = isgreater(w, (float4)(0.0f));  // before any rescaling below can flush a lane
  int4 infinite = isinf(w);
  if (any(infinite)) w = select((float4)(0.0f), (float4)(1.0f), infinite);  // the finite get the floor
  float sum = w.x + w.y + w.z + w.w;
  // Weights scaled so that their sum lies in [2^-100, 2^100]: the floors below add at most
  // 4 min_prob times the sum (min_prob is at most about 6, the host's bound), so the total the caller
  // divides by neither overflows (also when finite weights overflow their sum) nor loses
  // bits to denormals; lanes flushed by the scaling keep their floor (can_light)
  if (!(sum <= 0x1p100f)) {
    w *= 0x1p-30f;
    sum = w.x + w.y + w.z + w.w;
  } else if (sum > 0.0f && sum < 0x1p-100f) {
    w *= 0x1p100f;
    sum = w.x + w.y + w.z + w.w;
  }
  if (!(sum > 0.0f)) return false;
  *q = select((float4)(0.0f), fmax(w, min_prob * sum), can_light);
  return true;
}

// Whether selection uses the tree (the kernel has it, it has lights, and the scene was
// compiled for it)
bool lights_tree_used(const SceneData* sc) { return CD_FEATURE_LIGHT_TREE && sc->light_tree[0].share > 0.0f; }

// Whether the tree is used and holds every light: lights_select then needs no draw from the
// alias table (x_select is ignored)
bool lights_tree_holds_all(const SceneData* sc) { return lights_tree_used(sc) && sc->light_tree[0].holds_all; }

// A light of the tree chosen with u, and its probability within the tree; false when no
// light of the tree can light ctx.p
bool lights_tree_sample(const SceneData* sc, const LightSampleContext* ctx, float u, uint* light, float* pmf) {
#pragma OPENCL FP_CONTRACT OFF
  uint node = 0u;
  float prob = 1.0f, min_prob = sc->light_tree[0].min_prob;
  for (uint level = 0u; level < LIGHT_TREE_MAX_DEPTH; ++level) {
    __global const LightTreeNode* n = &sc->light_tree[node];
    // The next node is one of these: its loads overlap this node's arithmetic
    for (uint k = 0u; k < LIGHT_TREE_WIDTH; ++k)
      if (n->leaf[k] == LIGHT_TREE_INTERIOR && n->intensity[k] > 0.0f)
        prefetch((__global const float*)&sc->light_tree[n->child[k]], sizeof(LightTreeNode) / sizeof(float));
    float4 q;
    if (!lights_tree_children(sc, node, ctx, min_prob, &q)) return false;
    // The slot whose interval of the running sum holds t = u x the sum; the last nonzero
    // one when rounding leaves t past them all (slots of weight 0 have empty intervals)
    float c1 = q.x, c2 = c1 + q.y, c3 = c2 + q.z, total = c3 + q.w, t = u * total;
    uint slot = (t >= c1 ? 1u : 0u) + (t >= c2 ? 1u : 0u) + (t >= c3 ? 1u : 0u);
    uint last = q.w > 0.0f ? 3u : (q.z > 0.0f ? 2u : (q.y > 0.0f ? 1u : 0u));
    slot = min(slot, last);
    float below = slot == 0u ? 0.0f : (slot == 1u ? c1 : (slot == 2u ? c2 : c3));
    float taken = slot == 0u ? q.x : (slot == 1u ? q.y : (slot == 2u ? q.z : q.w));
    u = fmin(fmax(t - below, 0.0f) / taken, 0x1.fffffep-1f);
    prob *= taken / total;
    if (n->leaf[slot] == LIGHT_TREE_LEAF) {
      *light = n->child[slot];
      *pmf = prob;
      return prob > 0.0f;
    }
    node = n->child[slot];
  }
  return false;
}

// The probability with which lights_tree_sample picks `light` (one of the tree's) at ctx
float lights_tree_pmf(const SceneData* sc, const LightSampleContext* ctx, uint light) {
#pragma OPENCL FP_CONTRACT OFF
  __global const LightTreeTrail* trail = &sc->light_trails[light];
  uint node = 0u;
  float prob = 1.0f, min_prob = sc->light_tree[0].min_prob;
  for (uint k = 0u; k < trail->depth; ++k) {
    float4 q;
    if (!lights_tree_children(sc, node, ctx, min_prob, &q)) return 0.0f;
    uint slot = (trail->bits[k >> 4] >> (2u * (k & 15u))) & 3u;
    float c1 = q.x, c2 = c1 + q.y, c3 = c2 + q.z, total = c3 + q.w;
    prob *= (slot == 0u ? q.x : (slot == 1u ? q.y : (slot == 2u ? q.z : q.w))) / total;
    node = sc->light_tree[node].child[slot];
  }
  return prob;
}
