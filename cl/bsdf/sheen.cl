// The "Charlie" sheen lobe of KHR_materials_sheen (Estevez & Kulla 2017, Production Friendly
// Microfacet Sheen BRDF), in the local frame (z = normal), with colour 1:
//   f = D(h) / ((1 + Lambda(wo) + Lambda(wi)) 4 cos_o cos_i),
//   D(h) = (2 + 1 / alpha) sin^(1 / alpha) theta_h / (2 pi),  alpha = sheen roughness^2,
// Lambda from the paper's fit (the extension's visibility term). Sampled uniformly over the
// hemisphere: the lobe lies at grazing angles, where a cosine would rarely go. Its directional
// albedo E(mu), which scales the layers below (sheen_albedo_table), is a table each device
// computes with these functions (host/device/energy.cpp), like the GGX table of energy.cl.

// Below this alpha (sheen roughness about 0.03) the lobe is taken at this alpha: D's exponent
// 1 / alpha stays within float range, and the lobe is then a thin rim at grazing angles
#define SHEEN_MIN_ALPHA 1e-3f

float sheen_alpha(float roughness) { return fmax(roughness * roughness, SHEEN_MIN_ALPHA); }

// D(h) from cos theta_h
float sheen_d(float alpha, float cos_h) {
  float sin2 = fmax(1.0f - cos_h * cos_h, 0.0f);
  float inv = 1.0f / alpha;
  return (2.0f + inv) * pow(sin2, 0.5f * inv) * (0.5f * INV_PI_F);
}

// The fitted exponent of Lambda, l(x) = a / (1 + b x^c) + d x + e, its parameters interpolated
// between their values at alpha = 1 and alpha = 0 by (1 - alpha)^2
float sheen_l(float x, float alpha) {
  float t = (1.0f - alpha) * (1.0f - alpha);
  float a = mix(21.5473f, 25.3245f, t), b = mix(3.82987f, 3.32435f, t), c = mix(0.19823f, 0.16801f, t);
  float d = mix(-1.97760f, -1.27393f, t), e = mix(-4.32054f, -4.85967f, t);
  return a / (1.0f + b * pow(x, c)) + d * x + e;
}

// Lambda(theta) = exp(l(cos)) below cos 0.5, mirrored about it above
float sheen_lambda(float cos_t, float alpha) {
  float c = fabs(cos_t);
  return c < 0.5f ? exp(sheen_l(c, alpha)) : exp(2.0f * sheen_l(0.5f, alpha) - sheen_l(1.0f - c, alpha));
}

// f(wo, wi) with colour 1; 0 unless both lie above the surface
float sheen_eval(float alpha, float3 wo, float3 wi) {
  if (wo.z <= 0.0f || wi.z <= 0.0f) return 0.0f;
  float denom = (1.0f + sheen_lambda(wo.z, alpha) + sheen_lambda(wi.z, alpha)) * 4.0f * wo.z * wi.z;
  if (!(denom > 0.0f)) return 0.0f;
  return sheen_d(alpha, normalize(wo + wi).z) / denom;
}

// A direction uniform over the upper hemisphere, density 1 / (2 pi)
float3 sheen_sample(float2 u) {
  float cos_phi, sin_phi = sincos_turn(u.y, &cos_phi);
  float r = sqrt(fmax(0.0f, 1.0f - u.x * u.x));
  return (float3)(r * cos_phi, r * sin_phi, u.x);
}

float sheen_sample_pdf(float3 wi) { return wi.z > 0.0f ? 0.5f * INV_PI_F : 0.0f; }

// E(mu) = integral of f cos_i over the hemisphere, by an n x n midpoint rule in (t, phi) with
// cos theta_i = t^2 (nodes crowd toward the horizon, where the lobe lies) and phi in (0, pi)
// (the lobe is symmetric about the plane of incidence)
float sheen_albedo_quadrature(float alpha, float mu, uint n) {
  float3 wo = (float3)(sqrt(fmax(0.0f, 1.0f - mu * mu)), 0.0f, mu);
  float sum = 0.0f;
  for (uint a = 0u; a < n; ++a) {
    float t = ((float)a + 0.5f) / (float)n, z = t * t;
    float r = sqrt(fmax(0.0f, 1.0f - z * z)), row = 0.0f;
    for (uint b = 0u; b < n; ++b) {
      float cos_phi, sin_phi = sincos(PI_F * ((float)b + 0.5f) / (float)n, &cos_phi);
      row += sheen_eval(alpha, wo, (float3)(r * cos_phi, r * sin_phi, z));
    }
    sum += row * z * 2.0f * t;  // f cos_i, d(cos theta) = 2 t dt
  }
  return sum * 2.0f * PI_F / ((float)n * (float)n);  // phi over (0, pi), twice
}

// Table entry (i, j): E(mu_i, r_j), mu_i = (i / (N - 1))^2 (nodes crowd toward grazing angles,
// where E varies fastest; mu_0 taken at 1e-3), r_j = j / (N - 1). E exceeds 1 toward grazing
// angles at low roughness (6 at mu = 1e-3, r = 0): the lobe is not energy conserving there,
// and bsdf_gltf.cl divides it by E. Global size (N, N).
#if CD_TABLE_KERNELS
__kernel void sheen_albedo_table(__global float* table, uint n) {
  int i = (int)get_global_id(0), j = (int)get_global_id(1);
  if (i >= SHEEN_ALBEDO_N || j >= SHEEN_ALBEDO_N) return;
  float x = (float)i / (float)(SHEEN_ALBEDO_N - 1), mu = fmax(x * x, 1e-3f);
  float r = (float)j / (float)(SHEEN_ALBEDO_N - 1);
  table[j * SHEEN_ALBEDO_N + i] = sheen_albedo_quadrature(sheen_alpha(r), mu, n);
}
#endif

// E(mu) at sheen roughness r, bilinear in (sqrt(mu), r); 0 without a table
float sheen_albedo(__global const float* table, float mu, float roughness) {
  if (!table) return 0.0f;
  float x = sqrt(clamp(mu, 0.0f, 1.0f)) * (float)(SHEEN_ALBEDO_N - 1);
  float y = clamp(roughness, 0.0f, 1.0f) * (float)(SHEEN_ALBEDO_N - 1);
  int i = min((int)x, SHEEN_ALBEDO_N - 2), j = min((int)y, SHEEN_ALBEDO_N - 2);
  float s = x - (float)i, t = y - (float)j;
  __global const float* lo = table + j * SHEEN_ALBEDO_N + i;
  __global const float* hi = lo + SHEEN_ALBEDO_N;
  return mix(mix(lo[0], lo[1], s), mix(hi[0], hi[1], s), t);
}
