// Anisotropic Trowbridge-Reitz (GGX) microfacet distribution in the local shading frame
// (z = normal): D, Smith Lambda and G1 (Walter et al. 2007), the height-correlated G (Heitz
// 2014, Understanding the Masking-Shadowing Function in Microfacet-Based BRDFs), and sampling
// of visible normals (Heitz 2018, Sampling the GGX Distribution of Visible Normals).

// Below this roughness a lobe is treated as a perfect mirror or window (a delta lobe)
#define GGX_DELTA_ALPHA 1e-3f

typedef struct {
  float ax, ay;  // roughness along the frame's tangent and bitangent
} Ggx;

bool ggx_is_delta(Ggx g) { return fmax(g.ax, g.ay) < GGX_DELTA_ALPHA; }

// D(m) = 1 / (pi ax ay cos^4 (1 + tan^2 (cos^2 phi / ax^2 + sin^2 phi / ay^2))^2), written
// without angles: 1 / (pi ax ay ((mx/ax)^2 + (my/ay)^2 + mz^2)^2)
float ggx_d(Ggx g, float3 m) {
  if (m.z <= 0.0f) return 0.0f;
  float x = m.x / g.ax, y = m.y / g.ay;
  float s = x * x + y * y + m.z * m.z;
  return 1.0f / (PI_F * g.ax * g.ay * s * s);
}

// Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2 with
// alpha^2 tan^2 theta = (ax^2 wx^2 + ay^2 wy^2) / wz^2
float ggx_lambda(Ggx g, float3 w) {
  float z2 = w.z * w.z;
  if (z2 == 0.0f) return INFINITY;
  float a2t2 = (g.ax * g.ax * w.x * w.x + g.ay * g.ay * w.y * w.y) / z2;
  return 0.5f * (sqrt(1.0f + a2t2) - 1.0f);
}

float ggx_g1(Ggx g, float3 w) { return 1.0f / (1.0f + ggx_lambda(g, w)); }

// Height-correlated masking-shadowing G(wo, wi) = 1 / (1 + Lambda(wo) + Lambda(wi))
float ggx_g(Ggx g, float3 wo, float3 wi) { return 1.0f / (1.0f + ggx_lambda(g, wo) + ggx_lambda(g, wi)); }

// Density of visible normals seen from w: D_w(m) = G1(w) max(0, w.m) D(m) / |w.z|
float ggx_visible_d(Ggx g, float3 w, float3 m) {
  return ggx_g1(g, w) * fmax(0.0f, dot(w, m)) * ggx_d(g, m) / fabs(w.z);
}

// A visible normal seen from w (w.z > 0) with density ggx_visible_d: stretch w to the
// hemisphere configuration, sample the projected disk, unstretch
float3 ggx_sample_visible(Ggx g, float3 w, float2 u) {
  float3 wh = normalize((float3)(g.ax * w.x, g.ay * w.y, w.z));
  float len2 = wh.x * wh.x + wh.y * wh.y;
  float3 t1 = len2 > 0.0f ? (float3)(-wh.y, wh.x, 0.0f) * rsqrt(len2) : (float3)(1.0f, 0.0f, 0.0f);
  float3 t2 = cross(wh, t1);
  float r = sqrt(u.x);
  float cos_phi, sin_phi = sincos_turn(u.y, &cos_phi);
  float p1 = r * cos_phi, p2 = r * sin_phi;
  float s = 0.5f * (1.0f + wh.z);
  p2 = (1.0f - s) * sqrt(fmax(0.0f, 1.0f - p1 * p1)) + s * p2;
  float3 nh = p1 * t1 + p2 * t2 + sqrt(fmax(0.0f, 1.0f - p1 * p1 - p2 * p2)) * wh;
  return normalize((float3)(g.ax * nh.x, g.ay * nh.y, fmax(1e-7f, nh.z)));
}

// glTF roughness r to alpha = r^2, and KHR_materials_anisotropy's stretch of the tangent
// direction: ax = mix(alpha, 1, strength^2), ay = alpha (the frame's tangent is turned
// to the anisotropy direction beforehand). A lobe that is no mirror (ax >= GGX_DELTA_ALPHA)
// keeps ay >= GGX_DELTA_ALPHA: at roughness 0 with anisotropy, ay = 0 would make D and
// Lambda divide by zero; the floor makes it the narrowest line-shaped lobe that is not a mirror
Ggx ggx_from_roughness(float roughness, float anisotropy) {
  float alpha = roughness * roughness;
  Ggx g;
  g.ax = mix(alpha, 1.0f, anisotropy * anisotropy);
  g.ay = g.ax < GGX_DELTA_ALPHA ? alpha : fmax(alpha, GGX_DELTA_ALPHA);
  return g;
}

// Microfacet reflection without its Fresnel factor, wo and wi above the surface:
// returns D(h) G(wo, wi) / (4 cos_o cos_i); *pdf is the density of ggx_reflection_sample,
// D_wo(h) / (4 wo.h), and *cos_oh = wo.h for the caller's Fresnel term
float ggx_reflection_eval(Ggx g, float3 wo, float3 wi, float* pdf, float* cos_oh) {
  *pdf = 0.0f;
  *cos_oh = 0.0f;
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  float3 h = normalize(wo + wi);
  *cos_oh = dot(wo, h);
  if (*cos_oh <= 0.0f) return 0.0f;
  *pdf = ggx_visible_d(g, wo, h) / (4.0f * *cos_oh);
  return ggx_d(g, h) * ggx_g(g, wo, wi) / (4.0f * wo.z * wi.z);
}

// Reflects wo about a visible normal; false when the reflection points below the surface
bool ggx_reflection_sample(Ggx g, float3 wo, float2 u, float3* wi) {
  if (wo.z <= 0.0f) return false;
  *wi = fresnel_reflect(wo, ggx_sample_visible(g, wo, u));
  return wi->z > 0.0f;
}
