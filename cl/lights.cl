// Light sampling through one light-selection table (probability proportional to power).
// Directions and pdfs are measured from the shading point p; the shadow ray runs from
// p's offset origin to `target`, which sits off the light's surface on p's side.

typedef struct {
  float3 wi;  // unit direction from the shading point toward the light
  float3 radiance;  // emitted radiance arriving along -wi
  float pdf;  // solid-angle pdf of wi, including the selection probability
  bool at_infinity;  // shadow ray along wi without end (the background)
  float3 target;  // finite lights: the sampled point, moved off the light toward p
} LightSample;

// Uniform point on an emissive triangle, converted to a solid-angle pdf at p
bool lights_sample_triangle(__global const Light* light, __global const Triangle* tris,
                            __global const TriangleShading* shading,
                            __global const Material* materials, const TextureSet* textures,
                            float3 p, float2 u, LightSample* ls) {
  __global const Triangle* tri = &tris[light->index];
  float3 v0 = load3(tri->v0), v1 = load3(tri->v1), v2 = load3(tri->v2);
  float2 st = sample_triangle(u.x, u.y);
  float3 y = st.x * v0 + st.y * v1 + (1.0f - st.x - st.y) * v2;
  float3 n = normalize(cross(v1 - v0, v2 - v0));
  float3 d = y - p;
  float dist2 = dot(d, d);
  if (!(dist2 > 0.0f)) return false;
  float dist = sqrt(dist2);
  ls->wi = d / dist;
  float cos_light = dot(n, -ls->wi);
  bool front = cos_light > 0.0f;
  // y = s v0 + t v1 + (1-s-t) v2: barycentric weights of v1 and v2 are t and 1-s-t
  float2 uv = surface_uv(&shading[tri->prim], st.y, 1.0f - st.x - st.y);
  ls->radiance = surface_emission(&materials[tri->material], front, textures, uv);
  // Area measure to solid angle: dw/dA = cos(theta_y) / r^2
  ls->pdf = dist2 / (fabs(cos_light) * light->area);
  ls->at_infinity = false;
  ls->target = offset_ray_origin(y, front ? n : -n);
  return fabs(cos_light) > 0.0f && isfinite(ls->pdf);
}

// Cosine-weighted direction around the shading normal toward the constant background
bool lights_sample_background(__global const Light* light, float3 ns, float2 u,
                              LightSample* ls) {
  float3 dir_local = sample_cosine_hemisphere(u.x, u.y);
  ls->wi = frame_to_world(dir_local, ns);
  ls->pdf = sample_cosine_hemisphere_pdf(dir_local.z);
  ls->at_infinity = true;
  ls->radiance = load3(light->radiance);
  return ls->pdf > 0.0f;
}

bool lights_sample(__global const Light* lights, __global const uint* light_thresholds,
                   uint num_lights, __global const Triangle* tris,
                   __global const TriangleShading* shading, __global const Material* materials,
                   const TextureSet* textures, float3 p, float3 ns, uint x_select, float2 u,
                   LightSample* ls) {
  if (num_lights == 0u) return false;
  __global const Light* light = &lights[sample_discrete_thresholds(light_thresholds, num_lights, x_select)];
  float p_select = light->pmf;
  bool ok;
  switch (light->type) {
    case LIGHT_TRIANGLE:
      ok = lights_sample_triangle(light, tris, shading, materials, textures, p, u, ls);
      break;
    case LIGHT_BACKGROUND:
      ok = lights_sample_background(light, ns, u, ls);
      break;
    default:
      ok = false;
  }
  ls->pdf *= p_select;
  return ok && p_select > 0.0f;
}
