// Phase functions: the BSDFs of points in a medium (f_p in the radiative transfer equation). Directions follow
// the BSDF convention: wo points back along the ray that arrived (toward the camera), wi
// toward where light comes from, and the path continues along wi. The phase function
// integrates to 1 over the sphere, and sampling is exact: weight f / pdf = 1.
//
// Henyey-Greenstein (Henyey and Greenstein 1941): with cos = dot(wo, wi),
//   f_p(wo, wi) = (1 - g^2) / (4 pi (1 + g^2 + 2 g cos)^(3/2)).
// g > 0 scatters forward: light keeps going, so wi lies near -wo and the mean of
// dot(-wo, wi) is g. g = 0 is the isotropic 1 / (4 pi). g lies in (-1, 1).

#define PHASE_ISOTROPIC_G 1e-3f  // |g| below this: the isotropic formulas (no 1/g cancellation)

// Henyey-Greenstein from 1 + cos and 1 - cos (cos = dot(wo, wi)): the denominator
// 1 + g^2 + 2 g cos is (1 - g)^2 + 2 g (1 + cos) = (1 + g)^2 - 2 g (1 - cos), evaluated in the
// form without cancellation at the peak (cos -> -1 for g > 0, +1 for g < 0), where the peak
// is (1 - |g|)^2 deep: at |g| = 0.999 the cosine's own rounding would be 10 % of it
float phase_hg_from(float g, float one_plus_cos, float one_minus_cos) {
  float denom = g >= 0.0f ? (1.0f - g) * (1.0f - g) + 2.0f * g * one_plus_cos
                          : (1.0f + g) * (1.0f + g) - 2.0f * g * one_minus_cos;
  return 0.25f * INV_PI_F * (1.0f - g * g) / (denom * sqrt(fmax(denom, 1e-12f)));
}

float phase_hg(float g, float cos_theta) { return phase_hg_from(g, 1.0f + cos_theta, 1.0f - cos_theta); }

// 1 + cos and 1 - cos from the vectors: the small one as sin^2 / (the large one), sin from
// the cross product, which keeps angles far below sqrt(float epsilon) ~ 3e-4 rad
float phase_eval(float g, float3 wo, float3 wi) {
  float c = dot(wo, wi);
  float3 x = cross(wo, wi);
  float sin2 = dot(x, x) / (dot(wo, wo) * dot(wi, wi));
  float one_plus_cos = c < 0.0f ? sin2 / (1.0f - c) : 1.0f + c;
  float one_minus_cos = c > 0.0f ? sin2 / (1.0f + c) : 1.0f - c;
  return phase_hg_from(g, one_plus_cos, one_minus_cos);
}

float phase_pdf(float g, float3 wo, float3 wi) { return phase_eval(g, wo, wi); }

// Samples wi for wo by inverting the cdf of cos = dot(wo, wi) (u.x) and a uniform azimuth
// (u.y); *pdf gets the solid-angle pdf, equal to f_p. The cdf of mu = -cos (the cosine
// between the old and new travel directions) is
//   P(mu) = (1 - g^2) / (2 g) [1 / (1 + g^2 - 2 g mu)^(1/2) - 1 / (1 + g)],
// so with d = 1 - g + 2 g u and s = (1 - g^2) / d, mu = (1 + g^2 - s^2) / (2 g). Near the peak
// that difference cancels (at |g| = 0.999 the deflection is ~1e-3 rad and 1 - mu ~ 5e-7, a
// few float steps of mu), so the small one of 1 -+ mu is computed in factored form:
//   1 - mu = (1 - g)(1 - u)(s + 1 - g) / d   (g > 0: the peak at mu = 1)
//   1 + mu = (1 + g) u (1 + g + s) / d       (g < 0: the peak at mu = -1)
// and sin = sqrt((1 - mu)(1 + mu)).
float3 phase_sample(float g, float3 wo, float2 u, float* pdf) {
  float one_minus_mu, one_plus_mu;
  if (fabs(g) < PHASE_ISOTROPIC_G) {
    one_minus_mu = 2.0f * u.x;
    one_plus_mu = 2.0f - one_minus_mu;
  } else {
    float d = 1.0f - g + 2.0f * g * u.x;
    float s = (1.0f - g * g) / d;
    if (g > 0.0f) {
      one_minus_mu = clamp((1.0f - g) * (1.0f - u.x) * (s + 1.0f - g) / d, 0.0f, 2.0f);
      one_plus_mu = 2.0f - one_minus_mu;
    } else {
      one_plus_mu = clamp((1.0f + g) * u.x * (1.0f + g + s) / d, 0.0f, 2.0f);
      one_minus_mu = 2.0f - one_plus_mu;
    }
  }
  // relative to wo: cos = -mu, so 1 + cos = 1 - mu and 1 - cos = 1 + mu
  float cos_theta = g > 0.0f ? one_minus_mu - 1.0f : 1.0f - one_plus_mu;
  float sin_theta = sqrt(fmax(0.0f, one_minus_mu * one_plus_mu));
  float cos_phi, sin_phi = sincos_turn(u.y, &cos_phi);
  Frame f = frame_from_z(wo);
  float3 wi = frame_from_local(&f, (float3)(sin_theta * cos_phi, sin_theta * sin_phi, cos_theta));
  *pdf = phase_hg_from(g, one_minus_mu, one_plus_mu);
  return wi;
}
