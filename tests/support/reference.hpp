// Reference formulas in double precision, written from their sources, which the tests
// compare the kernels with: one definition each.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <utility>

namespace candela::test {

constexpr double kPi = 3.14159265358979323846;

// ---- Colour -------------------------------------------------------------------------------

// Luminance of linear Rec. 709 RGB (ITU-R BT.709)
double luminance(glm::dvec3 c);
double max_component(glm::dvec3 c);

// ---- Fresnel (Born & Wolf, Principles of Optics) -------------------------------------------

// Unpolarized reflectance of a dielectric interface, the mean of r_s^2 and r_p^2;
// eta = eta_t / eta_i; 1 beyond the critical angle (total internal reflection)
double fresnel_dielectric(double cos_i, double eta);

// Of a conductor of complex index eta + i k seen from vacuum: complex Snell's law
// cos_t = sqrt(1 - sin_i^2 / n^2), then r_s and r_p as for a dielectric
double fresnel_conductor(double cos_i, double eta, double k);
glm::dvec3 fresnel_conductor(double cos_i, glm::dvec3 eta, glm::dvec3 k);  // per channel

// Schlick 1994: (1 - c)^5 (c clamped to [0, 1]) and F0 + (F90 - F0) (1 - c)^5
double schlick_weight(double c);
glm::dvec3 schlick(glm::dvec3 f0, glm::dvec3 f90, double c);

// Measured gold (the loader's preset): complex index eta + i k per channel
glm::dvec3 gold_eta();
glm::dvec3 gold_k();

// ---- Reflection and refraction ------------------------------------------------------------

// Mirror direction of w about unit n
glm::dvec3 mirror(glm::dvec3 w, glm::dvec3 n);
// Refraction of w (on n's side) through relative index eta = eta_t / eta_i (Snell's law);
// nullopt on total internal reflection
std::optional<glm::dvec3> refract(glm::dvec3 w, glm::dvec3 n, double eta);

// ---- Trowbridge-Reitz (GGX) microfacets --------------------------------------------------

// Anisotropic GGX in the local frame (z the normal): D (Walter et al. 2007, anisotropic as
// in Heitz 2014, Understanding the masking-shadowing function), Smith Lambda and G1, the
// height-correlated G (Heitz 2014)
struct GgxReference {
  double ax, ay;
  // glTF roughness r: alpha = r^2; KHR_materials_anisotropy stretches ax toward 1 by strength^2
  static GgxReference from(double roughness, double anisotropy);
  bool delta() const;  // both alphas below 1e-3: a mirror
  double d(glm::dvec3 m) const;
  double lambda(glm::dvec3 w) const;
  double g1(glm::dvec3 w) const { return 1.0 / (1.0 + lambda(w)); }
  double g(glm::dvec3 wo, glm::dvec3 wi) const { return 1.0 / (1.0 + lambda(wo) + lambda(wi)); }
  // D(h) G / (4 cos_o cos_i) and its visible-normal pdf G1(wo) D(h) / (4 cos_o), h the half vector
  std::pair<double, double> reflection(glm::dvec3 wo, glm::dvec3 wi) const;
};

// The same D and Lambda in spherical coordinates of m and w (Walter et al. 2007's angular forms:
// D = 1 / (pi ax ay cos^4 (1 + tan^2 (cos^2 phi / ax^2 + sin^2 phi / ay^2))^2), Lambda with
// alpha^2 = ax^2 cos^2 phi + ay^2 sin^2 phi); m and w need not be unit
double ggx_d_angular(double ax, double ay, glm::dvec3 m);
double ggx_lambda_angular(double ax, double ay, glm::dvec3 w);

// ---- Sampling densities -------------------------------------------------------------------

double cosine_hemisphere_pdf(double cos_theta);  // cos theta / pi
double uniform_sphere_pdf();                     // 1 / (4 pi)
double uniform_hemisphere_pdf();                 // 1 / (2 pi)

// ---- Henyey & Greenstein 1941 ---------------------------------------------------------------

// The phase function at c = dot(wo, wi), wo pointing back along the incoming travel
// direction: (1 - g^2) / (4 pi (1 + g^2 + 2 g c)^(3/2))
double henyey_greenstein(double g, double c);
// The same at the deflection x = 1 - mu (mu the cosine between the old and new travel
// directions), where 1 + g^2 - 2 g mu = (1 - g)^2 + 2 g x keeps its precision near |g| = 1,
// and its cdf P(1 - mu <= x) = 1 - (1 - g^2) / (2 g) [((1 - g)^2 + 2 g x)^(-1/2) - 1 / (1 + g)]
double henyey_greenstein_deflection(double g, double x);
double henyey_greenstein_deflection_cdf(double g, double x);

}  // namespace candela::test
