// Surface data at a ray hit.

#ifndef CD_FEATURE_VERTEX_COLORS
#define CD_FEATURE_VERTEX_COLORS 1
#endif

typedef struct {
  float3 p;
  float3 ng;  // geometric normal, turned to the side the ray came from
  float3 ns;  // shading normal, on the same side as ng
  float2 uv;
  float3 vertex_color;  // COLOR_0, white without CD_FEATURE_VERTEX_COLORS
  uint material;
  bool front;  // the ray hit the front face (counter-clockwise winding)
} SurfaceHit;

// Texture coordinates at barycentric weights (b1, b2) of v1 and v2
float2 surface_uv(__global const TriangleShading* sh, float b1, float b2) {
  return (1.0f - b1 - b2) * (float2)(sh->uv0_u, sh->uv0_v) + b1 * (float2)(sh->uv1_u, sh->uv1_v) +
         b2 * (float2)(sh->uv2_u, sh->uv2_v);
}

SurfaceHit surface_at(__global const Triangle* tris, __global const TriangleShading* shading,
                      __global const TriangleColors* colors, Hit hit, float3 ray_dir) {
  __global const Triangle* tri = &tris[hit.tri];
  __global const TriangleShading* sh = &shading[tri->prim];
  float3 v0 = load3(tri->v0), v1 = load3(tri->v1), v2 = load3(tri->v2);
  float b0 = 1.0f - hit.b1 - hit.b2;
  SurfaceHit s;
  s.p = b0 * v0 + hit.b1 * v1 + hit.b2 * v2;
  s.ng = normalize(cross(v1 - v0, v2 - v0));
  s.front = dot(s.ng, ray_dir) < 0.0f;
  if (!s.front) s.ng = -s.ng;
  float3 n = b0 * load3(sh->n0) + hit.b1 * load3(sh->n1) + hit.b2 * load3(sh->n2);
  float len = length(n);
  s.ns = len > 0.0f && isfinite(len) ? n / len : s.ng;
  if (dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
  s.uv = surface_uv(sh, hit.b1, hit.b2);
#if CD_FEATURE_VERTEX_COLORS
  __global const TriangleColors* c = &colors[tri->prim];
  s.vertex_color = b0 * load3(c->c0) + hit.b1 * load3(c->c1) + hit.b2 * load3(c->c2);
#else
  s.vertex_color = (float3)(1.0f);
#endif
  s.material = tri->material;
  return s;
}

// Radiance a surface emits toward the side the ray came from
float3 surface_emission(__global const Material* m, bool front, const TextureSet* textures,
                        float2 uv) {
  if (!front && !m->double_sided) return (float3)(0.0f);
  return load3(m->emission) * textures_lookup(textures, m->emission_texture, uv).xyz;
}
