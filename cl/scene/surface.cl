// Surface data at a point of a primitive: position, normals, texture coordinates, tangent
// and vertex colour, interpolated from the per-vertex arrays.

typedef struct {
  float3 p;
  float3 ng;            // geometric normal, turned to the side the ray came from
  float3 ns;            // shading normal, on the same side as ng
  float3 tangent;       // shading tangent direction (TANGENT, else dp/du); 0 when unknown
  float tangent_sign;   // glTF bitangent = tangent_sign * (n x tangent), front face
  float4 uvs;           // TEXCOORD_0 in xy, TEXCOORD_1 in zw
  float3 vertex_color;  // COLOR_0, white without CD_FEATURE_VERTEX_COLORS
  uint prim;
  uint material;
  bool front;  // the ray hit the front face (counter-clockwise winding)
} SurfaceHit;

// Texture coordinates at barycentric weights (b1, b2) of the primitive's v1 and v2
float4 surface_uvs(const SceneData* sc, __global const Prim* pr, float b1, float b2) {
#if CD_FEATURE_UVS
  float b0 = 1.0f - b1 - b2;
  float2 a0 = vload2(pr->v[0], sc->uv0), a1 = vload2(pr->v[1], sc->uv0), a2 = vload2(pr->v[2], sc->uv0);
  float2 c0 = vload2(pr->v[0], sc->uv1), c1 = vload2(pr->v[1], sc->uv1), c2 = vload2(pr->v[2], sc->uv1);
  return (float4)(b0 * a0 + b1 * a1 + b2 * a2, b0 * c0 + b1 * c1 + b2 * c2);
#else
  return (float4)(0.0f);
#endif
}

// Tangent (xyz) and bitangent sign (w) from glTF TANGENT when the vertices have one, else
// dp/du from TEXCOORD_0 with sign +1 (as the glTF sample viewer derives them)
float4 surface_tangent(const SceneData* sc, __global const Prim* pr, float b1, float b2, float3 p0, float3 p1,
                       float3 p2) {
  float b0 = 1.0f - b1 - b2;
#if CD_FEATURE_TANGENTS
  float4 t0 = vload4(pr->v[0], sc->tangents);
  float4 t = b0 * t0 + b1 * vload4(pr->v[1], sc->tangents) + b2 * vload4(pr->v[2], sc->tangents);
  if (dot(t.xyz, t.xyz) > 0.0f) return (float4)(t.xyz, t0.w < 0.0f ? -1.0f : 1.0f);
#endif
#if CD_FEATURE_UVS
  // dp/du from the triangle's edges and UV differences (pbrt-v4, Triangle::InteractionFromIntersection)
  float2 a0 = vload2(pr->v[0], sc->uv0), a1 = vload2(pr->v[1], sc->uv0), a2 = vload2(pr->v[2], sc->uv0);
  float2 d02 = a0 - a2, d12 = a1 - a2;
  float det = d02.x * d12.y - d02.y * d12.x;
  if (fabs(det) > 1e-12f) return (float4)((d12.y * (p0 - p2) - d02.y * (p1 - p2)) / det, 1.0f);
#endif
  return (float4)(0.0f, 0.0f, 0.0f, 1.0f);
}

SurfaceHit surface_at(const SceneData* sc, uint prim, float b1, float b2, float3 ray_dir) {
  __global const Prim* pr = &sc->prims[prim];
  float3 v0, v1, v2;
  scene_prim_positions(sc, prim, &v0, &v1, &v2);
  float b0 = 1.0f - b1 - b2;
  SurfaceHit s;
  s.p = b0 * v0 + b1 * v1 + b2 * v2;
  float area;
  s.ng = triangle_normal_area(v0, v1, v2, &area);
  s.front = dot(s.ng, ray_dir) < 0.0f;
  if (!s.front) s.ng = -s.ng;
#if CD_MOTION_STEPS
  float3 n = b0 * scene_motion_vertex(sc, sc->normals, pr->v[0]) + b1 * scene_motion_vertex(sc, sc->normals, pr->v[1]) +
             b2 * scene_motion_vertex(sc, sc->normals, pr->v[2]);
#else
  float3 n =
      b0 * vload3(pr->v[0], sc->normals) + b1 * vload3(pr->v[1], sc->normals) + b2 * vload3(pr->v[2], sc->normals);
#endif
  float len = length(n);
  s.ns = len > 0.0f && isfinite(len) ? n / len : s.ng;
  if (dot(s.ns, s.ng) < 0.0f) s.ns = -s.ns;
  s.uvs = surface_uvs(sc, pr, b1, b2);
  float4 tangent = surface_tangent(sc, pr, b1, b2, v0, v1, v2);
  s.tangent = tangent.xyz;
  s.tangent_sign = tangent.w;
#if CD_FEATURE_VERTEX_COLORS
  s.vertex_color =
      b0 * vload3(pr->v[0], sc->colors) + b1 * vload3(pr->v[1], sc->colors) + b2 * vload3(pr->v[2], sc->colors);
#else
  s.vertex_color = (float3)(1.0f);
#endif
  s.prim = prim;
  s.material = pr->material;
  return s;
}

// Radiance a surface emits toward the side `front` names, at texture coordinates uvs
float3 surface_emission(const SceneData* sc, __global const Material* m, bool front, float4 uvs) {
  if (!front && !(m->flags & MATERIAL_DOUBLE_SIDED)) return (float3)(0.0f);
  return load3(m->emission) * textures_lookup(sc, &m->textures[TEX_EMISSION], uvs).xyz;
}
