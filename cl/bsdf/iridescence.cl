// KHR_materials_iridescence: the reflectance of a thin dielectric film over a base, by
// Belcour & Barla 2017 ("A practical extension to microfacet theory for the modeling of
// varying iridescence"), in the form the extension describes: Schlick's reflectances at the
// two interfaces (air -> film at the outside angle, film -> base inside the film), the base
// a dielectric whose index follows from its F0, and the Airy sum of the film's inter-
// reflections written as a Fourier series in the optical path difference, integrated against
// Gaussian fits of the XYZ colour matching functions in closed form. The extension's sample
// code stops at the order m = 2; the series here runs (a rolled loop) until its amplitude
// falls under 1e-4, at most IRIDESCENCE_ORDERS terms: towards grazing angles R12 R23 nears 1
// and two orders miss the reflectance by up to 0.4.
// Unlike the extension's sample code, the colour matching is normalized so that a film of
// zero optical path gives each RGB channel exactly its DC term: as the thickness goes to 0
// (with the film's index held) the film tends to the Airy sum at zero phase, which at normal
// incidence is exactly the base's F0 ((a + b) / (1 + ab) of the two interfaces' amplitudes).
// Compiled only with CD_FEATURE_IRIDESCENCE; bsdf_gltf.cl calls it for the metal and the
// plastic (gltf_fresnel) and, through bsdf_dielectric.cl's dielectric_film_fresnel, for the
// glass. A base of index 1 (F0 = 0) is no special case: the film alone reflects.
#if CD_FEATURE_IRIDESCENCE

#define IRIDESCENCE_ORDERS 8

// The sensitivity of the three RGB channels to a cosine of the wavenumber with optical path
// difference opd (nm) and phase shift `shift`: each XYZ colour matching function is a sum of
// Gaussians in wavenumber (val, mean pos, variance var, in 1/m), whose Fourier transforms
// are Gaussians; XYZ -> linear sRGB (Rec. 709, D65), then divided by the channels' response
// at opd = 0 (the white of the fits)
float3 iridescence_sensitivity(float opd, float3 shift) {
  const float3 val = (float3)(5.4856e-13f, 4.4201e-13f, 5.2481e-13f);
  const float3 pos = (float3)(1.6810e+06f, 1.7953e+06f, 2.2084e+06f);
  const float3 var = (float3)(4.3278e+09f, 9.3046e+09f, 6.6121e+09f);
  const float val_x2 = 9.7470e-14f, pos_x2 = 2.2399e+06f, var_x2 = 4.5282e+09f;  // X's second lobe
  float phase = 2.0f * M_PI_F * opd * 1e-9f;
  float3 amp = val * sqrt(2.0f * M_PI_F * var);
  float amp_x2 = val_x2 * sqrt(2.0f * M_PI_F * var_x2);
  float3 xyz = amp * cos(pos * phase + shift) * exp(-phase * phase * var);
  xyz.x += amp_x2 * cos(pos_x2 * phase + shift.x) * exp(-phase * phase * var_x2);
  float3 white = amp + (float3)(amp_x2, 0.0f, 0.0f);
  float3 r = (float3)(3.2404542f, -1.5371385f, -0.4985314f), g = (float3)(-0.9692660f, 1.8760108f, 0.0415560f),
         b = (float3)(0.0556434f, -0.2040259f, 1.0572252f);
  return (float3)(dot(r, xyz) / dot(r, white), dot(g, xyz) / dot(g, white), dot(b, xyz) / dot(b, white));
}

// Schlick's reflectance with F90 = 1, per channel
float3 iridescence_schlick(float3 f0, float cos_i) {
  float m = clamp(1.0f - cos_i, 0.0f, 1.0f);
  float m2 = m * m;
  return f0 + (1.0f - f0) * (m2 * m2 * m);
}

// The film's RGB reflectance: film of index film_ior and thickness `thickness` (nm) in air
// over a base of normal-incidence reflectance base_f0 (in air), seen at cosine cos1; in [0, 1]
float3 iridescence_fresnel(float film_ior, float thickness, float3 base_f0, float cos1) {
  cos1 = clamp(cos1, 0.0f, 1.0f);
  float sin2_2 = (1.0f - cos1 * cos1) / (film_ior * film_ior);  // Snell's law into the film
  if (sin2_2 >= 1.0f) return (float3)(1.0f);                    // total internal reflection (film_ior < 1)
  float cos2 = sqrt(1.0f - sin2_2);
  // Air -> film: reflectance R12 (= R21), transmittance there and back T121, phase shifts
  float r0 = (film_ior - 1.0f) / (film_ior + 1.0f);
  float r12 = iridescence_schlick((float3)(r0 * r0), cos1).x;
  float t121 = 1.0f - r12;
  float phi21 = film_ior > 1.0f ? M_PI_F : 0.0f;  // phi12 = pi - phi21
  // Film -> base: the base's index from its F0 in air, its reflectance R23 inside the film
  float3 sf0 = sqrt(clamp(base_f0, 0.0f, 0.9999f));
  float3 base_ior = (1.0f + sf0) / (1.0f - sf0);
  float3 r1 = (base_ior - film_ior) / (base_ior + film_ior);
  float3 r23 = iridescence_schlick(r1 * r1, cos2);
  float3 phi23 = select((float3)(0.0f), (float3)(M_PI_F), isless(base_ior, (float3)(film_ior)));
  // The Airy sum: DC term R12 + T121^2 R23 / (1 - R12 R23), then the orders m of amplitude
  // (Rs - T121) (R12 R23)^(m/2) at optical path m opd and phase m (phi21 + phi23), each
  // weighed by the channels' sensitivity (Belcour & Barla 2017, eq. 10 and sec. 4)
  float3 r123 = clamp(r12 * r23, 0.0f, 0.9999f);
  float3 rs = t121 * t121 * r23 / (1.0f - r123);
  float3 film = r12 + rs;
  float3 cm = rs - t121, ratio = sqrt(r123), phi = phi21 + phi23;
  float opd = 2.0f * film_ior * thickness * cos2;
  for (int m = 1; m <= IRIDESCENCE_ORDERS; ++m) {
    cm *= ratio;
    if (max_component(fabs(cm)) < 1e-4f) break;
    film += 2.0f * cm * iridescence_sensitivity((float)m * opd, (float)m * phi);
  }
  return clamp(film, 0.0f, 1.0f);
}

#endif
