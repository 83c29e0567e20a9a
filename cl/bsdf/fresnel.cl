// Fresnel reflectance for unpolarized light (the Fresnel equations as in Pharr, Jakob and
// Humphreys, Physically Based Rendering, 4th ed., 2023, sec. 9.3).

// Dielectric interface: cos_i = cosine of the incident direction to the normal on its
// side, eta = eta_t / eta_i (the far side over the near side). Total internal reflection
// gives 1. F = (r_p^2 + r_s^2) / 2 with
//   r_p = (eta_t cos_i - eta_i cos_t) / (eta_t cos_i + eta_i cos_t),
//   r_s = (eta_i cos_i - eta_t cos_t) / (eta_i cos_i + eta_t cos_t).
float fresnel_dielectric(float cos_i, float eta) {
  cos_i = clamp(cos_i, 0.0f, 1.0f);
  float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);  // Snell's law
  if (sin2_t >= 1.0f) return 1.0f;
  float cos_t = sqrt(1.0f - sin2_t);
  float r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (r_p * r_p + r_s * r_s);
}

// Refracts w (pointing away from the surface, on the side of n) through a surface of
// relative index eta = eta_t / eta_i; false on total internal reflection. Snell's law in
// vector form (PBRT 4th ed. sec. 9.3): w_t = -w / eta + (cos_i / eta - cos_t) n.
bool fresnel_refract(float3 w, float3 n, float eta, float3* wt) {
  float cos_i = dot(w, n);
  float sin2_t = fmax(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return false;
  float cos_t = sqrt(1.0f - sin2_t);
  *wt = -w / eta + (cos_i / eta - cos_t) * n;
  return true;
}

float3 fresnel_reflect(float3 w, float3 n) { return 2.0f * dot(w, n) * n - w; }

// Conductor of complex index eta + i k, per RGB channel, exact for unpolarized light:
// with a^2 + b^2 = sqrt((eta^2 - k^2 - sin^2)^2 + 4 eta^2 k^2) and a = sqrt((that +
// eta^2 - k^2 - sin^2) / 2),
//   r_s^2 = (a^2 + b^2 - 2 a cos + cos^2) / (a^2 + b^2 + 2 a cos + cos^2),
//   r_p^2 = r_s^2 (cos^2 (a^2 + b^2) - 2 a cos sin^2 + sin^4) /
//                 (cos^2 (a^2 + b^2) + 2 a cos sin^2 + sin^4).
// (Pharr and Humphreys' simpler form, PBRT 2nd ed. 2010, approximates this where
// eta^2 + k^2 >> 1.)
float3 fresnel_conductor(float cos_i, float3 eta, float3 k) {
  cos_i = clamp(cos_i, 0.0f, 1.0f);
  float cos2 = cos_i * cos_i, sin2 = 1.0f - cos2;
  float3 t0 = eta * eta - k * k - sin2;
  float3 a2b2 = sqrt(t0 * t0 + 4.0f * eta * eta * k * k);
  float3 a = sqrt(fmax(0.5f * (a2b2 + t0), 0.0f));
  float3 t1 = a2b2 + cos2, t2 = 2.0f * cos_i * a;
  float3 rs = (t1 - t2) / (t1 + t2);
  float3 t3 = cos2 * a2b2 + sin2 * sin2, t4 = t2 * sin2;
  float3 rp = rs * (t3 - t4) / (t3 + t4);
  return 0.5f * (rp + rs);
}

// Schlick's approximation, as the glTF specification prescribes for its BRDF
float3 fresnel_schlick(float3 f0, float3 f90, float cos_i) {
  float m = clamp(1.0f - cos_i, 0.0f, 1.0f);
  float m2 = m * m;
  return f0 + (f90 - f0) * (m2 * m2 * m);
}
