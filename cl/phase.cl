// Phase functions: the BSDFs of points in a medium (the lecture's f_p). Directions follow
// the BSDF convention: wo points back along the ray that arrived (toward the camera), wi
// toward where light comes from, and the path continues along wi. The phase function
// integrates to 1 over the sphere, and sampling is exact: weight f / pdf = 1.
//
// Henyey-Greenstein (the lecture's formula): with cos = dot(wo, wi),
//   f_p(wo, wi) = (1 - g^2) / (4 pi (1 + g^2 + 2 g cos)^(3/2)).
// g > 0 scatters forward: light keeps going, so wi lies near -wo and the mean of
// dot(-wo, wi) is g. g = 0 is the isotropic 1 / (4 pi). g lies in (-1, 1).

#define PHASE_ISOTROPIC_G 1e-3f  // |g| below this: the isotropic formulas (no 1/g cancellation)

float phase_hg(float g, float cos_theta) {
  float denom = 1.0f + g * g + 2.0f * g * cos_theta;
  return 0.25f * INV_PI_F * (1.0f - g * g) / (denom * sqrt(fmax(denom, 1e-12f)));
}

float phase_eval(float g, float3 wo, float3 wi) { return phase_hg(g, dot(wo, wi)); }

float phase_pdf(float g, float3 wo, float3 wi) { return phase_eval(g, wo, wi); }

// Samples wi for wo by inverting the cdf of cos = dot(wo, wi) (u.x) and a uniform azimuth
// (u.y); *pdf gets the solid-angle pdf, equal to f_p. The cdf of mu = -cos (the cosine
// between the old and new travel directions) is
//   P(mu) = (1 - g^2) / (2 g) [1 / (1 + g^2 - 2 g mu)^(1/2) - 1 / (1 + g)],
// so mu = (1 + g^2 - ((1 - g^2) / (1 - g + 2 g u))^2) / (2 g).
float3 phase_sample(float g, float3 wo, float2 u, float* pdf) {
  float mu;
  if (fabs(g) < PHASE_ISOTROPIC_G) {
    mu = 1.0f - 2.0f * u.x;
  } else {
    float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u.x);
    mu = (1.0f + g * g - s * s) / (2.0f * g);
  }
  mu = clamp(mu, -1.0f, 1.0f);
  float cos_theta = -mu;  // relative to wo
  float sin_theta = sqrt(fmax(0.0f, 1.0f - cos_theta * cos_theta));
  float cos_phi, sin_phi = sincos(2.0f * PI_F * u.y, &cos_phi);
  Frame f = frame_from_z(wo);
  float3 wi = frame_from_local(&f, (float3)(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta));
  *pdf = phase_hg(g, cos_theta);
  return wi;
}
