#include "support/reference.hpp"

#include <algorithm>
#include <cmath>
#include <complex>

namespace candela::test {

double luminance(glm::dvec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }
double max_component(glm::dvec3 c) { return std::max({c.x, c.y, c.z}); }

double fresnel_dielectric(double cos_i, double eta) {
  double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  double cos_t = std::sqrt(1.0 - sin2_t);
  double r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t), r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5 * (r_p * r_p + r_s * r_s);
}

double fresnel_conductor(double cos_i, double eta, double k) {
  std::complex<double> n(eta, k), cos_t = std::sqrt(1.0 - (1.0 - cos_i * cos_i) / (n * n));
  std::complex<double> r_s = (cos_i - n * cos_t) / (cos_i + n * cos_t), r_p = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  return 0.5 * (std::norm(r_s) + std::norm(r_p));
}

glm::dvec3 fresnel_conductor(double cos_i, glm::dvec3 eta, glm::dvec3 k) {
  return {fresnel_conductor(cos_i, eta.x, k.x), fresnel_conductor(cos_i, eta.y, k.y),
          fresnel_conductor(cos_i, eta.z, k.z)};
}

double schlick_weight(double c) { return std::pow(std::clamp(1.0 - c, 0.0, 1.0), 5.0); }
glm::dvec3 schlick(glm::dvec3 f0, glm::dvec3 f90, double c) { return f0 + (f90 - f0) * schlick_weight(c); }

glm::dvec3 gold_eta() { return {0.143119, 0.374957, 1.44248}; }
glm::dvec3 gold_k() { return {3.98316, 2.38572, 1.60322}; }

glm::dvec3 mirror(glm::dvec3 w, glm::dvec3 n) { return 2.0 * glm::dot(w, n) * n - w; }

std::optional<glm::dvec3> refract(glm::dvec3 w, glm::dvec3 n, double eta) {
  double c = glm::dot(w, n), s2 = (1.0 - c * c) / (eta * eta);
  if (s2 >= 1.0) return std::nullopt;
  return -w / eta + (c / eta - std::sqrt(1.0 - s2)) * n;
}

GgxReference GgxReference::from(double roughness, double anisotropy) {
  double a = roughness * roughness;
  return {a + (1.0 - a) * anisotropy * anisotropy, a};
}

bool GgxReference::delta() const { return std::max(ax, ay) < 1e-3; }

double GgxReference::d(glm::dvec3 m) const {
  if (m.z <= 0.0) return 0.0;
  double s = m.x * m.x / (ax * ax) + m.y * m.y / (ay * ay) + m.z * m.z;
  return 1.0 / (kPi * ax * ay * s * s);
}

double GgxReference::lambda(glm::dvec3 w) const {
  return 0.5 * (std::sqrt(1.0 + (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / (w.z * w.z)) - 1.0);
}

std::pair<double, double> GgxReference::reflection(glm::dvec3 wo, glm::dvec3 wi) const {
  glm::dvec3 h = glm::normalize(wo + wi);
  return {d(h) * g(wo, wi) / (4.0 * wo.z * wi.z), g1(wo) * d(h) / (4.0 * wo.z)};
}

double ggx_d_angular(double ax, double ay, glm::dvec3 m) {
  m = glm::normalize(m);
  if (m.z <= 0.0) return 0.0;
  double phi = std::atan2(m.y, m.x), cos2 = m.z * m.z, tan2 = (1.0 - cos2) / cos2;
  double cp = std::cos(phi), sp = std::sin(phi);
  double e = 1.0 + tan2 * (cp * cp / (ax * ax) + sp * sp / (ay * ay));
  return 1.0 / (kPi * ax * ay * cos2 * cos2 * e * e);
}

double ggx_lambda_angular(double ax, double ay, glm::dvec3 w) {
  w = glm::normalize(w);
  double phi = std::atan2(w.y, w.x), cp = std::cos(phi), sp = std::sin(phi);
  double alpha2 = ax * ax * cp * cp + ay * ay * sp * sp;
  double tan2 = (1.0 - w.z * w.z) / (w.z * w.z);
  return 0.5 * (std::sqrt(1.0 + alpha2 * tan2) - 1.0);
}

double cosine_hemisphere_pdf(double cos_theta) { return cos_theta / kPi; }
double uniform_sphere_pdf() { return 1.0 / (4.0 * kPi); }
double uniform_hemisphere_pdf() { return 1.0 / (2.0 * kPi); }

double henyey_greenstein(double g, double c) {
  return (1.0 - g * g) / (4.0 * kPi * std::pow(1.0 + g * g + 2.0 * g * c, 1.5));
}

double henyey_greenstein_deflection(double g, double x) {
  return (1.0 - g * g) / (4.0 * kPi * std::pow((1.0 - g) * (1.0 - g) + 2.0 * g * x, 1.5));
}

double henyey_greenstein_deflection_cdf(double g, double x) {
  double p_mu = (1.0 - g * g) / (2.0 * g) * (1.0 / std::sqrt((1.0 - g) * (1.0 - g) + 2.0 * g * x) - 1.0 / (1.0 + g));
  return 1.0 - p_mu;
}

}  // namespace candela::test
