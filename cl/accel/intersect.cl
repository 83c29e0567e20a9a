// Watertight ray-triangle intersection (Woop, Benthin and Wald 2013, Watertight
// Ray/Triangle Intersection): shear the triangle into the ray's frame, then decide
// inside/outside with 2D edge functions whose signs agree on shared edges.

typedef struct {
  float3 org;
  uint4 perm;    // (kx, ky, kz, 3): the ray direction's largest axis goes to z
  float3 shear;  // (Sx, Sy, Sz)
} WatertightRay;

// A ray hit: distance, barycentric weights of the triangle's second and third vertices
// (the point is (1 - b1 - b2) v0 + b1 v1 + b2 v2), and the stable primitive index
typedef struct {
  float t;
  float b1, b2;
  int prim;  // -1: no hit
} Hit;

float3 permute3(float3 v, uint4 perm) { return shuffle((float4)(v, 0.0f), perm).xyz; }

WatertightRay watertight_ray(Ray ray) {
  float3 a = fabs(ray.dir);
  uint kz = a.x >= a.y ? (a.x >= a.z ? 0u : 2u) : (a.y >= a.z ? 1u : 2u);
  uint kx = kz == 2u ? 0u : kz + 1u;
  uint ky = kx == 2u ? 0u : kx + 1u;
  float3 d = permute3(ray.dir, (uint4)(kx, ky, kz, 3u));
  if (d.z < 0.0f) {  // keep the winding: swap x and y
    uint tmp = kx;
    kx = ky;
    ky = tmp;
    d = (float3)(d.y, d.x, d.z);
  }
  WatertightRay w;
  w.org = ray.org;
  w.perm = (uint4)(kx, ky, kz, 3u);
  w.shear = (float3)(d.x / d.z, d.y / d.z, 1.0f / d.z);
  return w;
}

// 2D edge function q x p (Woop et al.'s U = Cx By - Cy Bx for p = B, q = C), evaluated
// with its two vertices in a canonical order so that the two triangles sharing an edge
// get exactly opposite values even where the compiler fuses multiply-adds.
float edge_function(float px, float py, float qx, float qy) {
  bool swap = px < qx || (px == qx && py < qy);
  float ax = swap ? qx : px, ay = swap ? qy : py;
  float bx = swap ? px : qx, by = swap ? py : qy;
  float e = bx * ay - by * ax;
  return swap ? -e : e;
}

// Always inlined where the compiler takes Clang's attribute (PoCL, rusticl and most
// others): a call in the BVH's leaf loop spills every vector register of the traversal
#ifdef __clang__
#define CD_ALWAYS_INLINE __attribute__((always_inline))
#else
#define CD_ALWAYS_INLINE
#endif

// Hit in (0, tmax)? On a hit sets *t and the barycentric weights of v1 and v2.
CD_ALWAYS_INLINE bool intersect_triangle(const WatertightRay* r, float3 v0, float3 v1, float3 v2, float tmax, float* t,
                                         float* b1, float* b2) {
  // No fused multiply-adds: keeps the edge values and t as the paper rounds them
#pragma OPENCL FP_CONTRACT OFF
  float3 a = permute3(v0 - r->org, r->perm);
  float3 b = permute3(v1 - r->org, r->perm);
  float3 c = permute3(v2 - r->org, r->perm);
  float ax = a.x - r->shear.x * a.z, ay = a.y - r->shear.y * a.z;
  float bx = b.x - r->shear.x * b.z, by = b.y - r->shear.y * b.z;
  float cx = c.x - r->shear.x * c.z, cy = c.y - r->shear.y * c.z;
  // Edge functions (2D cross products); U, V, W weight v0, v1, v2
  float u = edge_function(bx, by, cx, cy);
  float v = edge_function(cx, cy, ax, ay);
  float w = edge_function(ax, ay, bx, by);
  if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
  float det = u + v + w;
  if (det == 0.0f) return false;
  float tt = u * (r->shear.z * a.z) + v * (r->shear.z * b.z) + w * (r->shear.z * c.z);
  if (det > 0.0f ? (tt <= 0.0f || tt >= tmax * det) : (tt >= 0.0f || tt <= tmax * det)) return false;
  float inv_det = 1.0f / det;
  *t = tt * inv_det;
  *b1 = v * inv_det;
  *b2 = w * inv_det;
  return true;
}
