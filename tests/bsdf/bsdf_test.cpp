// BSDF tests through the kernels' own dispatch (bsdf_at, bsdf_sample, bsdf_eval, bsdf_pdf;
// tests/bsdf/test_bsdf.cl) for every material of kMaterials at every shading geometry of
// kGeometries (on rusticl those of kRusticlGeometries): sampled directions follow bsdf_pdf
// (chi-square, 1M samples, cells with expected count < 5 pooled, alpha = 0.01 with the Sidak
// correction over this file's chi-square tests), the pdf integrates to at most 1, sample
// weights agree with eval and pdf, no energy is created, eval is reciprocal (generalized for
// refraction) and matches a host-side reference lobe. Delta lobes are checked against their
// Fresnel weights and frequencies (BsdfDelta), albedos on a grid of incidence angles and
// roughnesses (BsdfEnergy). A new lobe is a new entry of kMaterials; a new shading situation
// a new entry of kGeometries. Known kernel bugs are listed per material (MaterialCase::bugs):
// their rows are skipped with a note, the rest runs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <glm/glm.hpp>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <tuple>

#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Samples per chi-square test: 1M on PoCL; rusticl (llvmpipe) runs the same checks at a
// quarter of that, as it is about 5x slower per work-item
constexpr size_t kSamples = 1 << 20;
size_t samples_on(const std::string& device) { return device == "rusticl" ? kSamples / 4 : kSamples; }
// Each device its own random numbers, for independent evidence
cl_uint seed_on(const std::string& device, cl_uint seed) { return device == "rusticl" ? seed + 1000 : seed; }

// The pdf is integrated over histogram cells on this grid over the sphere (rings x sectors
// of the cells' coordinates): 2-point Gauss-Legendre in cos theta per ring, which follows
// GGX's heavy tails where the midpoint rule loses 5e-4 of an alpha = 0.04 lobe, and the
// midpoint rule in phi. Its error over the sphere comes from the pdf's jumps at the
// horizons (about 1e-4 with ns 20 degrees off ng).
constexpr int kIntegrationRings = 160, kIntegrationSectors = 320;
constexpr double kIntegrationTolerance = 2e-4;

// --- Host reference model (double), in the local shading frame (z = ns on wo's side) ---

double luminance(glm::dvec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }
double max_component(glm::dvec3 c) { return std::max({c.x, c.y, c.z}); }
double schlick_weight(double c) { return std::pow(std::clamp(1.0 - c, 0.0, 1.0), 5.0); }
glm::dvec3 schlick(glm::dvec3 f0, glm::dvec3 f90, double c) { return f0 + (f90 - f0) * schlick_weight(c); }

// Dielectric Fresnel reflectance (the lecture's r_s, r_p), eta = eta_t / eta_i
double fresnel_dielectric(double cos_i, double eta) {
  double sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0) return 1.0;
  double cos_t = std::sqrt(1.0 - sin2_t);
  double r_p = (eta * cos_i - cos_t) / (eta * cos_i + cos_t), r_s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5 * (r_p * r_p + r_s * r_s);
}

// Conductor of complex index eta + i k: complex Snell's law, then r_s and r_p
double fresnel_conductor(double cos_i, double eta, double k) {
  std::complex<double> n(eta, k), cos_t = std::sqrt(1.0 - (1.0 - cos_i * cos_i) / (n * n));
  return 0.5 *
         (std::norm((cos_i - n * cos_t) / (cos_i + n * cos_t)) + std::norm((n * cos_i - cos_t) / (n * cos_i + cos_t)));
}

// Refraction of w (on n's side) through relative index eta; nullopt on total internal reflection
std::optional<glm::dvec3> refract(glm::dvec3 w, glm::dvec3 n, double eta) {
  double c = glm::dot(w, n), s2 = (1.0 - c * c) / (eta * eta);
  if (s2 >= 1.0) return std::nullopt;
  return -w / eta + (c / eta - std::sqrt(1.0 - s2)) * n;
}
glm::dvec3 mirror(glm::dvec3 w, glm::dvec3 n) { return 2.0 * glm::dot(w, n) * n - w; }

// Anisotropic Trowbridge-Reitz (the lecture's D, Smith Lambda, height-correlated G)
struct HostGgx {
  double ax, ay;
  // glTF roughness r: alpha = r^2; KHR_materials_anisotropy stretches ax toward 1 by strength^2
  static HostGgx from(double roughness, double anisotropy) {
    double a = roughness * roughness;
    return {a + (1.0 - a) * anisotropy * anisotropy, a};
  }
  bool delta() const { return std::max(ax, ay) < 1e-3; }
  double d(glm::dvec3 m) const {
    if (m.z <= 0.0) return 0.0;
    double s = m.x * m.x / (ax * ax) + m.y * m.y / (ay * ay) + m.z * m.z;
    return 1.0 / (kPi * ax * ay * s * s);
  }
  double lambda(glm::dvec3 w) const {
    return 0.5 * (std::sqrt(1.0 + (ax * ax * w.x * w.x + ay * ay * w.y * w.y) / (w.z * w.z)) - 1.0);
  }
  double g1(glm::dvec3 w) const { return 1.0 / (1.0 + lambda(w)); }
  double g(glm::dvec3 wo, glm::dvec3 wi) const { return 1.0 / (1.0 + lambda(wo) + lambda(wi)); }
  // D(h) G / (4 cos_o cos_i) and its visible-normal pdf G1(wo) D(h) / (4 cos_o), h = half vector
  std::pair<double, double> reflection(glm::dvec3 wo, glm::dvec3 wi) const {
    glm::dvec3 h = glm::normalize(wo + wi);
    return {d(h) * g(wo, wi) / (4.0 * wo.z * wi.z), g1(wo) * d(h) / (4.0 * wo.z)};
  }
};

struct Reference {
  glm::dvec3 f;
  double pdf;
};
const Reference kNothing{glm::dvec3(0.0), 0.0};

// Reflectance of a dielectric interface, or of a thin sheet of it with its inter-reflections
// R' = R + T^2 R / (1 - R^2) = 2R / (1 + R)
double dielectric_reflectance(double cos_i, double eta, bool thin) {
  double r = fresnel_dielectric(cos_i, eta);
  return thin ? 2.0 * r / (1.0 + r) : r;
}

// Rough dielectric transmission from wo (z > 0) to wi (z < 0), eta = eta_wi / eta_wo, for
// radiance: Walter et al. 2007 eq. 21 and 17 with the generalized half vector
// h ~ -(eta_wo wo + eta_wi wi); a thin sheet passes the reflection lobe mirrored through it
Reference dielectric_transmission(const HostGgx& g, double eta, bool thin, glm::dvec3 wo, glm::dvec3 wi) {
  if (thin) {
    glm::dvec3 wr(wi.x, wi.y, -wi.z);
    double t = 1.0 - dielectric_reflectance(glm::dot(wo, glm::normalize(wo + wr)), eta, true);
    auto [f, pdf] = g.reflection(wo, wr);
    return {glm::dvec3(t * f), t * pdf};
  }
  glm::dvec3 h = glm::normalize(wo + eta * wi);
  if (h.z < 0.0) h = -h;
  double oh = glm::dot(wo, h), ih = glm::dot(wi, h);
  if (oh <= 0.0 || ih >= 0.0) return kNothing;
  double t = 1.0 - fresnel_dielectric(oh, eta), denom = (ih + oh / eta) * (ih + oh / eta);
  double f = t * g.d(h) * g.g(wo, wi) * std::fabs(ih * oh / (wi.z * wo.z * denom)) / (eta * eta);
  return {glm::dvec3(f), t * g.g1(wo) * oh * g.d(h) / wo.z * std::fabs(ih) / denom};
}

// (wo, wi) in the local frame; `reflection`: wi on wo's geometric side; `front`: wo on the
// front face (outside a refracting solid)
using ReferenceLobe = std::function<Reference(glm::dvec3 wo, glm::dvec3 wi, bool reflection, bool front)>;

// Lambert: f = albedo / pi, pdf = cos theta / pi
ReferenceLobe lambert_reference(glm::dvec3 albedo) {
  return [albedo](glm::dvec3, glm::dvec3 wi, bool reflection, bool) {
    return reflection && wi.z > 0.0 ? Reference{albedo / kPi, wi.z / kPi} : kNothing;
  };
}

// Measured conductor: D G F / (4 cos cos) with the exact complex-index Fresnel term
ReferenceLobe conductor_reference(HostGgx g, glm::dvec3 eta, glm::dvec3 k) {
  return [=](glm::dvec3 wo, glm::dvec3 wi, bool reflection, bool) {
    if (!reflection || wo.z <= 0.0 || wi.z <= 0.0) return kNothing;
    double c = glm::dot(wo, glm::normalize(wo + wi));
    auto [f, pdf] = g.reflection(wo, wi);
    glm::dvec3 fr(fresnel_conductor(c, eta.x, k.x), fresnel_conductor(c, eta.y, k.y), fresnel_conductor(c, eta.z, k.z));
    return Reference{f * fr, pdf};
  };
}

// glTF metallic-roughness (glTF 2.0 Appendix B with KHR_materials_specular, _ior,
// _transmission, _clearcoat, _anisotropy) as a weighted sum of lobes: coat over
// metal + plastic (specular + Lambert) + glass. Its pdf is the kernel's mixture, with
// component probabilities estimated at wo (cl/bsdf/bsdf_gltf.cl, gltf_at_wo).
struct GltfReference {
  glm::dvec3 base, f0;
  double metallic, transmission, ior, f90, coat;
  bool thin;
  HostGgx ggx, coat_ggx;

  explicit GltfReference(const dev::Material& m)
      : base(m.base_color[0], m.base_color[1], m.base_color[2]),
        metallic(m.params.gltf.metallic),
        transmission(m.params.gltf.transmission),
        ior(m.params.gltf.ior),
        f90(m.params.gltf.specular_color[3]),
        coat(m.params.gltf.clearcoat),
        thin((m.flags & MATERIAL_THIN_WALLED) != 0u),
        ggx(HostGgx::from(m.params.gltf.roughness, m.params.gltf.anisotropy_strength)),
        coat_ggx(HostGgx::from(m.params.gltf.clearcoat_roughness, 0.0)) {
    double r = (ior - 1.0) / (ior + 1.0);
    const float* tint = m.params.gltf.specular_color;
    f0 = glm::min(r * r * glm::dvec3(tint[0], tint[1], tint[2]), 1.0) * f90;
  }
  double coat_fresnel(double c) const { return coat * (0.04 + 0.96 * schlick_weight(c)); }
  // Without the albedo table a layer's albedo is its Schlick term at mu; what lies below
  // gets (1 - A(mu_o)) (1 - A(mu_i)) of reflected light, 1 - A(mu outside) of transmitted
  double spec_albedo(double mu) const { return max_component(schlick(f0, glm::dvec3(f90), mu)); }
  double below_spec(double mu_o, double mu_i) const { return (1.0 - spec_albedo(mu_o)) * (1.0 - spec_albedo(mu_i)); }
  double below_coat(double mu_o, double mu_i) const { return (1.0 - coat_fresnel(mu_o)) * (1.0 - coat_fresnel(mu_i)); }

  // Component probabilities: coat, metal, specular, diffuse, glass
  std::array<double, 5> lobes(double cos_o) const {
    double m = metallic, t = transmission, fc = coat_fresnel(cos_o),
           fs = luminance(schlick(f0, glm::dvec3(f90), cos_o));
    std::array<double, 5> w = {fc, (1 - fc) * m, (1 - fc) * (1 - m) * (1 - t) * fs,
                               (1 - fc) * (1 - m) * (1 - t) * (1 - spec_albedo(cos_o)) * luminance(base),
                               (1 - fc) * (1 - m) * t};
    double sum = w[0] + w[1] + w[2] + w[3] + w[4];
    for (double& x : w) x = sum > 0.0 ? x / sum : 0.0;
    return w;
  }

  Reference operator()(glm::dvec3 wo, glm::dvec3 wi, bool reflection, bool front) const {
    if (wo.z <= 0.0 || wi.z == 0.0 || reflection != (wi.z > 0.0)) return kNothing;
    const double m = metallic, t = transmission;
    const double eta = thin || front ? ior : 1.0 / ior;  // a thin sheet has air on both sides
    std::array<double, 5> w = lobes(wo.z);
    if (wi.z < 0.0) {
      if (t == 0.0 || m == 1.0 || ggx.delta()) return kNothing;
      Reference tr = dielectric_transmission(ggx, eta, thin, wo, wi);
      // Transmitted light crosses the coat once, at the outside direction's angle
      double c_out = front ? wo.z : -wi.z;
      return {(1.0 - coat_fresnel(c_out)) * (1.0 - m) * t * base * tr.f, w[4] * tr.pdf};
    }
    glm::dvec3 h = glm::normalize(wo + wi);
    double c = glm::dot(wo, h);
    auto [spec, spec_pdf] = ggx.delta() ? std::pair{0.0, 0.0} : ggx.reflection(wo, wi);
    bool glossy = m > 0.0 || f90 > 0.0 || coat > 0.0;
    glm::dvec3 fd = glossy ? schlick(f0, glm::dvec3(f90), c) : glm::dvec3(0.0);
    glm::dvec3 under = (1 - m) * (1 - t) * below_spec(wo.z, wi.z) * base / kPi;
    double pdf = w[3] * wi.z / kPi;
    if (glossy) {
      under += (m * schlick(base, glm::dvec3(1.0), c) + (1 - m) * (1 - t) * fd) * spec;
      pdf += (w[1] + w[2]) * spec_pdf;
    }
    if (t > 0.0) {
      double fr = dielectric_reflectance(c, eta, thin);
      under += (1 - m) * t * fr * spec;
      pdf += w[4] * fr * spec_pdf;
    }
    glm::dvec3 f = below_coat(wo.z, wi.z) * under;
    if (coat > 0.0 && !coat_ggx.delta()) {
      auto [cf, cpdf] = coat_ggx.reflection(wo, wi);
      f += coat_fresnel(c) * cf;
      pdf += w[0] * cpdf;
    }
    return {f, pdf};
  }
};

// Histogram cells: which axis they are centred on (per geometry) and their resolution
enum class Focus { Normal, Mirror, Refraction, Straight };
struct CellSpec {
  // `rings` around an axis x `sectors` in phi (dividing kIntegrationRings and
  // kIntegrationSectors). warp 0: rings of equal solid angle, uniform in cos theta, for
  // broad lobes. warp c in (0, 1): polar angle theta(t) = pi (t - c sin(2 pi t) / (2 pi)),
  // t uniform, so rings are (1 - c) times a uniform angular step at both poles and (1 + c)
  // times it at the equator: a narrow lobe on the axis spans many rings (and the
  // integration's sub-rings resolve its peak), and so does one straight opposite (the
  // reflection when the cells follow the refraction at normal incidence)
  int rings = 20, sectors = 40;
  double warp = 0.0;
  Focus reflection = Focus::Normal, transmission = Focus::Normal;  // axes of the two sides
};
// Lobes a few degrees wide (alpha <= 0.1): rings of 0.2 degrees at the axis
const CellSpec kNarrow{80, 32, 0.9, Focus::Mirror, Focus::Refraction};
const CellSpec kGlossy{32, 32, 0.6, Focus::Mirror, Focus::Refraction};

struct MaterialCase {
  std::string name;
  dev::Material material;
  bool pdf_normalized;  // the pdf integrates to 1 when ns == ng (no delta, nothing lost)
  // The exact albedo (eta^2-weighted, see energy_weights) when ns == ng, where known, for
  // wo at cosine cos_o
  std::function<std::optional<glm::dvec3>(double cos_o)> albedo;
  ReferenceLobe reference;  // where one exists (not for delta lobes)
  CellSpec cells;
  // Known kernel bugs: "check/geometry" -> the bug, check = albedo, reciprocity or
  // reference; those rows are skipped and the test then marked skipped with the note
  // (remove the entry once fixed; the albedo check fails if the bug no longer reproduces)
  std::map<std::string, std::string> bugs;
};

void PrintTo(const MaterialCase& m, std::ostream* os) { *os << m.name; }

dev::Material make_material(unsigned type, glm::dvec3 base_color) {
  dev::Material m{};
  m.type = type;
  for (int c = 0; c < 3; ++c) m.base_color[c] = float(base_color[c]);
  m.base_color[3] = 1.0f;
  if (type == MATERIAL_GLTF) {
    m.params.gltf.ior = 1.5f;
    for (float& s : m.params.gltf.specular_color) s = 1.0f;  // KHR_materials_specular defaults
  }
  m.normal_scale = 1.0f;
  for (dev::TextureRef& t : m.textures) {
    t.index = NO_TEXTURE;
    t.m[0] = t.m[4] = 1.0f;
  }
  return m;
}

// glTF metallic-roughness with the given factors; the rest default
dev::Material gltf(glm::dvec3 base, double metallic, double roughness, double transmission = 0.0, bool thin = false) {
  dev::Material m = make_material(MATERIAL_GLTF, base);
  m.params.gltf.metallic = float(metallic);
  m.params.gltf.roughness = float(roughness);
  m.params.gltf.transmission = float(transmission);
  if (thin) m.flags |= MATERIAL_THIN_WALLED;
  return m;
}

// The loader's gold preset
const glm::dvec3 kGoldEta(0.143119, 0.374957, 1.44248), kGoldK(3.98316, 2.38572, 1.60322);
dev::Material gold(double roughness, double anisotropy = 0.0) {
  dev::Material m = make_material(MATERIAL_CONDUCTOR, glm::dvec3(1.0));
  for (int c = 0; c < 3; ++c) {
    m.params.conductor.eta[c] = float(kGoldEta[c]);
    m.params.conductor.k[c] = float(kGoldK[c]);
  }
  m.params.conductor.roughness = float(roughness);
  m.params.conductor.anisotropy_strength = float(anisotropy);
  return m;
}

// A glTF material's index of refraction; 1.5 for the other types (make_material's default)
float ior(const dev::Material& m) { return m.type == MATERIAL_GLTF ? m.params.gltf.ior : 1.5f; }

MaterialCase diffuse(glm::dvec3 albedo) {
  return {"diffuse",
          make_material(MATERIAL_DIFFUSE, albedo),
          true,
          [albedo](double) { return albedo; },
          lambert_reference(albedo),
          {},
          {}};
}

// Microfacet lobes lose the samples reflected below the horizon: their pdf integrates to less than 1
MaterialCase conductor_case(std::string name, dev::Material m, CellSpec cells) {
  HostGgx g = HostGgx::from(m.params.conductor.roughness, m.params.conductor.anisotropy_strength);
  return {name, m, false, {}, conductor_reference(g, kGoldEta, kGoldK), cells, {}};
}

MaterialCase gltf_case(std::string name, dev::Material m, CellSpec cells) {
  return {name, m, false, {}, GltfReference(m), cells, {}};
}

// Delta lobes: eval and pdf are 0 everywhere; `albedo` where it is known
MaterialCase delta_case(std::string name, dev::Material m,
                        std::function<std::optional<glm::dvec3>(double)> albedo = {}) {
  return {name, m, false, albedo, {}, {}, {}};
}

std::vector<MaterialCase> make_materials() {
  const glm::dvec3 orange(0.8, 0.5, 0.2), brass(0.95, 0.64, 0.54), white(1.0);
  dev::Material metal_aniso = gltf(brass, 1.0, 0.4);
  metal_aniso.params.gltf.anisotropy_strength = 0.7f;
  metal_aniso.params.gltf.anisotropy_rotation = 0.6f;
  dev::Material coat = gltf(orange, 0.0, 0.6);
  coat.params.gltf.clearcoat = 1.0f;
  coat.params.gltf.clearcoat_roughness = 0.2f;
  dev::Material smooth_coat = gltf(brass, 1.0, 0.5);
  smooth_coat.params.gltf.clearcoat = 1.0f;
  dev::Material smooth_plastic = gltf(orange, 0.0, 0.0);
  dev::Material mixture = gltf({0.9, 0.7, 0.5}, 0.5, 0.4, 0.5);
  dev::Material coat_glass = gltf(white, 0.0, 0.3, 1.0);
  coat_glass.params.gltf.clearcoat = 1.0f;
  coat_glass.params.gltf.clearcoat_roughness = 0.3f;
  auto gold_mirror = [](double c) {
    return glm::dvec3(fresnel_conductor(c, kGoldEta.x, kGoldK.x), fresnel_conductor(c, kGoldEta.y, kGoldK.y),
                      fresnel_conductor(c, kGoldEta.z, kGoldK.z));
  };
  auto one = [](double) { return glm::dvec3(1.0); };  // R + T (eta^2-weighted)
  CellSpec straight = kNarrow;
  straight.transmission = Focus::Straight;
  MaterialCase thin = gltf_case("thin_glass_r03", gltf(white, 0.0, 0.3, 1.0, true), straight);
  MaterialCase aniso = conductor_case("conductor_aniso", gold(0.5, 0.8), kGlossy);
  MaterialCase coat_glass_case = gltf_case("coat_glass", coat_glass, kNarrow);
  MaterialCase smooth_thin = delta_case("smooth_thin_glass", gltf(white, 0.0, 0.0, 1.0, true), one);
  MaterialCase plastic = gltf_case("plastic_r03", gltf(orange, 0.0, 0.3), kNarrow);
  MaterialCase smooth_plastic_case = gltf_case("smooth_plastic", smooth_plastic, {});
  MaterialCase coat_case = gltf_case("coat_plastic", coat, kNarrow);
  MaterialCase smooth_coat_case = gltf_case("smooth_coat_metal", smooth_coat, kGlossy);
  return {
      diffuse(orange),
      conductor_case("conductor_r02", gold(0.2), kNarrow),
      conductor_case("conductor_r06", gold(0.6), kGlossy),
      conductor_case("conductor_r1", gold(1.0), {}),
      aniso,
      gltf_case("metal_r05", gltf(brass, 1.0, 0.5), kGlossy),
      gltf_case("metal_aniso", metal_aniso, kGlossy),
      plastic,
      gltf_case("plastic_r1", gltf(orange, 0.0, 1.0), {}),
      gltf_case("glass_r03", gltf(white, 0.0, 0.3, 1.0), kNarrow),
      thin,
      coat_case,
      gltf_case("mixture", mixture, {40, 40, 0.8, Focus::Mirror, Focus::Refraction}),
      coat_glass_case,
      delta_case("smooth_conductor", gold(0.0), gold_mirror),
      delta_case("smooth_glass", gltf(white, 0.0, 0.0, 1.0), one),
      smooth_thin,
      smooth_plastic_case,
      smooth_coat_case,
  };
}
const std::vector<MaterialCase> kMaterials = make_materials();

// A shading point as a mesh gives it: normals unoriented, tangent not orthogonal to ns
struct Geometry {
  std::string name;
  glm::dvec3 ng, ns, tangent, wo;
};

// Any orthonormal frame (t, b, n) around unit n
struct Frame {
  glm::dvec3 t, b, n;
  glm::dvec3 local(glm::dvec3 v) const { return {glm::dot(v, t), glm::dot(v, b), glm::dot(v, n)}; }
  glm::dvec3 world(glm::dvec3 v) const { return v.x * t + v.y * b + v.z * n; }
};
Frame frame_around(glm::dvec3 n) {
  glm::dvec3 a = std::fabs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  glm::dvec3 t = glm::normalize(a - glm::dot(a, n) * n);
  return {t, glm::cross(n, t), n};
}

// Unit direction at polar angle theta from n, azimuth phi (degrees) in frame_around(n)
glm::dvec3 around(glm::dvec3 n, double theta_deg, double phi_deg) {
  double th = theta_deg * kPi / 180.0, ph = phi_deg * kPi / 180.0;
  return frame_around(glm::normalize(n))
      .world({std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
}

const glm::dvec3 kTilted = glm::normalize(glm::dvec3(1.0, 2.0, 3.0));
const glm::dvec3 kBumpedNs = around({0, 0, 1}, 20.0, 0.0);
const std::vector<Geometry> kGeometries = {
    {"normal", {0, 0, 1}, {0, 0, 1}, {1, 0, 0}, {0, 0, 1}},
    {"grazing", kTilted, kTilted, {1, 0, 0.5}, around(kTilted, 85.0, 30.0)},
    {"backfacing", {0, 0, 1}, {0, 0, 1}, {1, 0.2, 0.3}, around({0, 0, -1}, 40.0, 200.0)},
    {"bumped", {0, 0, 1}, kBumpedNs, {0, 1, 0}, around({0, 0, 1}, 40.0, 150.0)},
    // wo between ns and ng: dot(wo, ns) < 0 < dot(wo, ng); glossy lobes give nothing here
    {"belowshading", {0, 0, 1}, kBumpedNs, {0, 1, 0}, around({0, 0, 1}, 80.0, 180.0)},
    // From inside a refracting solid beyond the critical angle asin(1 / 1.5) = 41.8 degrees
    {"backgrazing", {0, 0, 1}, {0, 0, 1}, {1, 0, 0}, around({0, 0, -1}, 70.0, 60.0)},
};

// rusticl runs the material tests at these geometries only (front at grazing incidence,
// back face, bumped shading normal): it is about 5x slower a work-item than PoCL
const std::vector<std::string> kRusticlGeometries = {"grazing", "backfacing", "bumped"};
bool runs_on(const std::string& device, const Geometry& g) {
  return device != "rusticl" ||
         std::find(kRusticlGeometries.begin(), kRusticlGeometries.end(), g.name) != kRusticlGeometries.end();
}

// The file's chi-square tests: one per device x material x geometry it runs at
const double kAlpha = sidak_alpha(0.01, int(kMaterials.size() * (kGeometries.size() + kRusticlGeometries.size())));

// Two-sided normal quantile of kAlpha, for the binomial checks that go with each chi-square
double normal_quantile(double alpha) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) (std::erfc((lo + hi) / 2.0 / std::sqrt(2.0)) > alpha ? lo : hi) = (lo + hi) / 2.0;
  return lo;
}
const double kZ = normal_quantile(kAlpha);

// Normals turned as surface_at turns them (ng to wo's side, ns to ng's)
struct Oriented {
  glm::dvec3 ng, ns;
  bool front;  // wo on the side ng points to (outside)
  bool shading_is_geometric;
};
Oriented orient(const Geometry& g) {
  Oriented o;
  o.front = glm::dot(g.ng, g.wo) > 0.0;
  o.ng = o.front ? g.ng : -g.ng;
  o.ns = glm::dot(g.ns, o.ng) >= 0.0 ? g.ns : -g.ns;
  o.shading_is_geometric = glm::length(g.ns - g.ng) < 1e-12;
  return o;
}

// The kernels' shading frame (bsdf_shading_frame, bsdf_gltf_params): t from the tangent by
// Gram-Schmidt against ns, b = ns x t mirrored on back faces, t turned by the anisotropy
// rotation toward b. (The lobes are even in b, so b's sign after that does not matter.)
Frame shading_frame(const Geometry& g, const Oriented& o, const dev::Material& m) {
  glm::dvec3 n = o.ns, t = glm::normalize(g.tangent - glm::dot(g.tangent, n) * n);
  glm::dvec3 b = glm::cross(n, t) * (o.front ? 1.0 : -1.0);
  float strength = 0.0f, rotation = 0.0f;  // KHR_materials_anisotropy of a glTF or conductor material
  if (m.type == MATERIAL_GLTF) {
    strength = m.params.gltf.anisotropy_strength;
    rotation = m.params.gltf.anisotropy_rotation;
  } else if (m.type == MATERIAL_CONDUCTOR) {
    strength = m.params.conductor.anisotropy_strength;
    rotation = m.params.conductor.anisotropy_rotation;
  }
  if (strength > 0.0f) {
    double r = rotation;
    t = glm::normalize(std::cos(r) * t + std::sin(r) * b);
  }
  return {t, glm::cross(n, t), n};
}

cl_float4 f4(glm::dvec3 v) { return {{float(v.x), float(v.y), float(v.z), 0.0f}}; }
glm::dvec3 d3(const cl_float4& v) { return {v.s[0], v.s[1], v.s[2]}; }

// One device's test program, shared by the suite
std::map<std::string, std::unique_ptr<KernelRig>>& rigs() {
  static std::map<std::string, std::unique_ptr<KernelRig>> r;
  return r;
}
KernelRig& rig_for(const std::string& name, const DeviceEntry& device) {
  auto& r = rigs()[name];
  if (!r) r = std::make_unique<KernelRig>(device);
  return *r;
}

cl::Buffer upload_materials(KernelRig& rig, const std::vector<dev::Material>& m) {
  return cl::Buffer(rig.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, m.size() * sizeof(dev::Material),
                    const_cast<dev::Material*>(m.data()));
}

// bsdf_sample output, per sample: (wi, pdf), (f, eta), (eval f, eval pdf) and
// info (returned, delta, reflection, flags valid)
struct Samples {
  std::vector<cl_float4> out;
  std::vector<cl_uint4> info;
  size_t size() const { return info.size(); }
  bool returned(size_t i) const { return info[i].s[0] != 0u; }
  bool delta(size_t i) const { return info[i].s[1] != 0u; }
  bool reflection(size_t i) const { return info[i].s[2] != 0u; }
  glm::dvec3 wi(size_t i) const { return d3(out[3 * i]); }
  double pdf(size_t i) const { return out[3 * i].s[3]; }
  glm::dvec3 f(size_t i) const { return d3(out[3 * i + 1]); }
  double eta(size_t i) const { return out[3 * i + 1].s[3]; }
};

// A material on a shading point of one device, and what its kernels return
struct BsdfRun {
  KernelRig& rig;
  const dev::Material material;
  const Geometry geo;
  cl::Buffer materials;

  BsdfRun(KernelRig& r, const dev::Material& m, const Geometry& g)
      : rig(r), material(m), geo(g), materials(upload_materials(r, {m})) {}

  void set_shading_point(cl::Kernel& k) const {
    k.setArg(0, materials);
    k.setArg(1, f4(geo.ng));
    k.setArg(2, f4(geo.ns));
    k.setArg(3, f4(geo.tangent));
  }

  // n calls of bsdf_sample from wo
  Samples sample(cl_uint seed, size_t n = kSamples) const {
    cl::Buffer out(rig.context, CL_MEM_WRITE_ONLY, 3 * n * sizeof(cl_float4));
    cl::Buffer info(rig.context, CL_MEM_WRITE_ONLY, n * sizeof(cl_uint4));
    cl::Kernel k(rig.program, "test_bsdf_sample");
    set_shading_point(k);
    k.setArg(4, f4(geo.wo));
    k.setArg(5, seed);
    k.setArg(6, out);
    k.setArg(7, info);
    rig.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n));
    Samples s{std::vector<cl_float4>(3 * n), std::vector<cl_uint4>(n)};
    rig.queue.enqueueReadBuffer(out, CL_TRUE, 0, s.out.size() * sizeof(cl_float4), s.out.data());
    rig.queue.enqueueReadBuffer(info, CL_TRUE, 0, s.info.size() * sizeof(cl_uint4), s.info.data());
    return s;
  }

  // (f, pdf) for each pair (wo, wi), the hit oriented by that wo
  std::vector<cl_float4> eval(const std::vector<std::pair<glm::dvec3, glm::dvec3>>& pairs) const {
    std::vector<cl_float4> in;
    in.reserve(2 * pairs.size());
    for (const auto& [wo, wi] : pairs) {
      in.push_back(f4(wo));
      in.push_back(f4(wi));
    }
    cl::Buffer pb(rig.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, in.size() * sizeof(cl_float4), in.data());
    cl::Buffer out(rig.context, CL_MEM_WRITE_ONLY, pairs.size() * sizeof(cl_float4));
    cl::Kernel k(rig.program, "test_bsdf_eval");
    set_shading_point(k);
    k.setArg(4, pb);
    k.setArg(5, out);
    rig.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(pairs.size()));
    std::vector<cl_float4> v(pairs.size());
    rig.queue.enqueueReadBuffer(out, CL_TRUE, 0, v.size() * sizeof(cl_float4), v.data());
    return v;
  }

  // bsdf_pdf(wo, wi) for each wi
  std::vector<double> pdf(const std::vector<glm::dvec3>& wis) const {
    std::vector<std::pair<glm::dvec3, glm::dvec3>> pairs;
    pairs.reserve(wis.size());
    for (const auto& wi : wis) pairs.emplace_back(geo.wo, wi);
    std::vector<double> p;
    p.reserve(wis.size());
    for (const auto& r : eval(pairs)) p.push_back(r.s[3]);
    return p;
  }
};

using PdfFunction = std::function<std::vector<double>(const std::vector<glm::dvec3>&)>;

// Histogram cells: the directions on wo's geometric side (reflection) binned around one
// axis, those on the other side (transmission) around another, each over a sphere of
// rings (CellSpec's warp) x sectors (uniform in phi). The pdf jumps at the horizons of ng
// and ns; the integration refines where they cross its sub-cells.
struct SphereCells {
  glm::dvec3 ng, ns;
  Frame frames[2];  // reflection, transmission
  CellSpec spec;

  SphereCells(glm::dvec3 ng_, glm::dvec3 ns_, Frame reflection, Frame transmission, CellSpec c)
      : ng(ng_), ns(ns_), frames{reflection, transmission}, spec(c) {
    for (int i = 0; i <= spec.rings; ++i) ring_theta.push_back(theta(double(i) / spec.rings));
  }

  size_t per_side() const { return size_t(spec.rings) * spec.sectors; }
  size_t size() const { return 2 * per_side(); }
  int side(glm::dvec3 w) const { return glm::dot(w, ng) > 0.0 ? 0 : 1; }

  // Polar angle at ring coordinate t in [0, 1]
  double theta(double t) const {
    if (spec.warp == 0.0) return std::acos(std::clamp(1.0 - 2.0 * t, -1.0, 1.0));
    return kPi * (t - spec.warp * std::sin(2.0 * kPi * t) / (2.0 * kPi));
  }

  size_t index(glm::dvec3 w) const {
    int k = side(w);
    glm::dvec3 l = frames[k].local(w);
    double phi = std::atan2(l.y, l.x), th = std::acos(std::clamp(l.z / glm::length(l), -1.0, 1.0));
    if (phi < 0.0) phi += 2.0 * kPi;
    int i = int(std::upper_bound(ring_theta.begin(), ring_theta.end(), th) - ring_theta.begin()) - 1;
    i = std::clamp(i, 0, spec.rings - 1);
    int j = std::clamp(int(phi / (2.0 * kPi) * spec.sectors), 0, spec.sectors - 1);
    return k * per_side() + size_t(i) * spec.sectors + j;
  }

  // Integral of the pdf over each cell, dw = dcos dphi, on sub-cells of kIntegrationRings x
  // kIntegrationSectors: two Gauss-Legendre nodes in cos theta, the midpoint in phi; the
  // sub-cells a horizon crosses are split kRefine x kRefine times more
  std::vector<double> integrals(const PdfFunction& pdf) const {
    const int n = kIntegrationRings, m = kIntegrationSectors, sub_t = n / spec.rings, sub_phi = m / spec.sectors;
    EXPECT_TRUE(n % spec.rings == 0 && m % spec.sectors == 0) << "cells must divide the integration grid";
    struct Node {
      size_t cell;
      double weight;
    };
    std::vector<glm::dvec3> dirs;
    std::vector<Node> nodes;
    for (int k = 0; k < 2; ++k) {
      const Frame& f = frames[k];
      auto at = [&](double th, double phi) {
        return f.world({std::sin(th) * std::cos(phi), std::sin(th) * std::sin(phi), std::cos(th)});
      };
      // Nodes of the region [t0, t1] x [phi0, phi1] split r x r, on side k only
      auto add = [&](size_t cell, double t0, double t1, double phi0, double phi1, int r) {
        const double gauss = 0.5 / std::sqrt(3.0), dphi = (phi1 - phi0) / r;
        for (int i = 0; i < r; ++i) {
          double z0 = std::cos(theta(t0 + (t1 - t0) * i / r)), z1 = std::cos(theta(t0 + (t1 - t0) * (i + 1) / r));
          for (double z : {0.5 * (z0 + z1) + gauss * (z0 - z1), 0.5 * (z0 + z1) - gauss * (z0 - z1)})
            for (int j = 0; j < r; ++j) {
              glm::dvec3 w = at(std::acos(z), phi0 + (j + 0.5) * dphi);
              if (side(w) != k) continue;
              dirs.push_back(w);
              nodes.push_back({cell, 0.5 * (z0 - z1) * dphi});
            }
        }
      };
      const double dphi = 2.0 * kPi / m;
      for (int a = 0; a < n; ++a) {
        double t0 = double(a) / n, t1 = double(a + 1) / n, th0 = theta(t0), th1 = theta(t1);
        for (int b = 0; b < m; ++b) {
          double phi0 = b * dphi, phi1 = phi0 + dphi;
          glm::dvec3 corners[4] = {at(th0, phi0), at(th0, phi1), at(th1, phi0), at(th1, phi1)};
          bool crossed = false, on_side = false;
          for (glm::dvec3 h : {ng, ns}) {
            double lo = INFINITY, hi = -INFINITY;
            for (const auto& c : corners) {
              lo = std::min(lo, glm::dot(c, h));
              hi = std::max(hi, glm::dot(c, h));
            }
            crossed = crossed || (lo < 0.0 && hi > 0.0);
          }
          for (const auto& c : corners) on_side = on_side || side(c) == k;
          if (!on_side && !crossed) continue;
          add(k * per_side() + size_t(a / sub_t) * spec.sectors + b / sub_phi, t0, t1, phi0, phi1,
              crossed ? kRefine : 1);
        }
      }
    }
    std::vector<double> p = pdf(dirs), cells(size(), 0.0);
    for (size_t i = 0; i < nodes.size(); ++i) cells[nodes[i].cell] += p[i] * nodes[i].weight;
    return cells;
  }

 private:
  static constexpr int kRefine = 4;
  std::vector<double> ring_theta;  // ring edges, increasing
};

// The axis of one side's cells: ns, wo mirrored or refracted about ns, or straight
// through (-wo)
glm::dvec3 focus_axis(Focus focus, const Geometry& g, const Oriented& o, const dev::Material& m) {
  double eta = o.front ? ior(m) : 1.0 / ior(m);
  switch (focus) {
    case Focus::Mirror:
      return mirror(g.wo, o.ns);
    case Focus::Refraction:
      return refract(g.wo, o.ns, eta).value_or(-o.ns);
    case Focus::Straight:
      return -g.wo;
    case Focus::Normal:
    default:
      return o.ns;
  }
}

SphereCells cells_for(const CellSpec& spec, const Geometry& g, const Oriented& o, const dev::Material& m) {
  return SphereCells(o.ng, o.ns, frame_around(glm::normalize(focus_axis(spec.reflection, g, o, m))),
                     frame_around(glm::normalize(focus_axis(spec.transmission, g, o, m))), spec);
}

// Non-delta samples, histogrammed, against the pdf's cell integrals scaled to their count;
// *returned gets that count
ChiSquare direction_chi_square(const Samples& s, const SphereCells& grid, const std::vector<double>& cells,
                               size_t* returned) {
  std::vector<double> observed(cells.size(), 0.0), expected(cells.size());
  size_t n = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    if (!s.returned(i) || s.delta(i)) continue;
    observed[grid.index(s.wi(i))] += 1.0;
    ++n;
  }
  double total = 0.0;
  for (double c : cells) total += c;
  for (size_t c = 0; c < cells.size(); ++c) expected[c] = total > 0.0 ? n * cells[c] / total : 0.0;
  *returned = n;
  return chi_square_test(observed, expected);
}

// Mean and standard error of per-sample values
struct SampleMean {
  glm::dvec3 mean, se;
};
SampleMean estimate(const std::vector<glm::dvec3>& v) {
  glm::dvec3 sum(0.0), sum2(0.0);
  for (const auto& x : v) {
    sum += x;
    sum2 += x * x;
  }
  double n = double(v.size());
  glm::dvec3 mean = sum / n;
  return {mean, glm::sqrt(glm::max(sum2 / n - mean * mean, 0.0) / n)};
}

// The weight f |cos| / pdf of each sample times eta^2 (0 where none returned): eta =
// eta_wi / eta_wo undoes refraction's 1 / eta^2 radiance scaling (pbrt's etaScale), so that
// the mean is the fraction of energy scattered, at most 1
std::vector<glm::dvec3> energy_weights(const Samples& s, glm::dvec3 ns) {
  std::vector<glm::dvec3> w(s.size(), glm::dvec3(0.0));
  for (size_t i = 0; i < s.size(); ++i)
    if (s.returned(i)) w[i] = s.f(i) * std::fabs(glm::dot(s.wi(i), ns)) / s.pdf(i) * s.eta(i) * s.eta(i);
  return w;
}

// Relative tolerance between float computations of a lobe: rounding through the local
// frame grows as 1 / cos theta toward the horizon
double float_tolerance(double cos_theta) { return 1e-4 + 1e-6 / std::fabs(cos_theta); }

// What a dielectric lobe adds to that, at (wo, wi) in the local frame with the kernel's
// eta = eta_wi / eta_wo: the microfacet cosines' rounding, amplified where they vanish, and
// Fresnel's infinite slope at the critical angle (R and 1 - R ~ sqrt of the distance to it)
double dielectric_tolerance(double eta, bool thin, glm::dvec3 wo, glm::dvec3 wi) {
  glm::dvec3 h = wi.z > 0.0 ? wo + wi : thin ? wo + glm::dvec3(wi.x, wi.y, -wi.z) : wo + eta * wi;
  h = glm::normalize(h);
  double co = std::fabs(glm::dot(wo, h)), ci = std::fabs(glm::dot(wi, h));
  double to_critical = eta < 1.0 ? std::fabs(co * co - (1.0 - eta * eta)) : 1.0;
  return 1e-6 / co + 1e-6 / ci + 1e-7 / to_critical;
}

bool near_rel(double a, double b, double rel) { return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)); }

// Colours equal channel by channel, relative to their largest channel
bool near_vec(glm::dvec3 a, glm::dvec3 b, double rel) {
  double scale =
      std::max({std::fabs(a.x), std::fabs(a.y), std::fabs(a.z), std::fabs(b.x), std::fabs(b.y), std::fabs(b.z)});
  return glm::all(glm::lessThanEqual(glm::abs(a - b), glm::dvec3(rel * scale)));
}

Geometry seen_from(Geometry g, glm::dvec3 wo) {
  g.wo = wo;
  return g;
}

bool has_transmission(const dev::Material& m) {
  return m.type == MATERIAL_GLTF && m.params.gltf.transmission > 0.0f && m.params.gltf.metallic < 1.0f;
}

// Known kernel bugs met by a test: bug -> the rows it kept out. A row is
// "<material> <check>/<geometry>", listed in MaterialCase::bugs.
struct KnownBugs {
  std::map<std::string, std::string> rows;
  const std::string* find(const MaterialCase& mat, const std::string& check, const Geometry& g) {
    auto it = mat.bugs.find(check + "/" + g.name);
    if (it == mat.bugs.end()) return nullptr;
    rows[it->second] += " " + mat.name + " " + it->first;
    return &it->second;
  }
  std::string note() const {
    std::string note;
    for (const auto& [bug, where] : rows) note += "skipped" + where + ": " + bug + "\n";
    return note;
  }
};

// Marks the test skipped when known kernel bugs kept rows out (the others ran)
#define BSDF_SKIP_KNOWN_BUGS(bugs) \
  if (!bugs.rows.empty()) GTEST_SKIP() << bugs.note()

// Tolerance of the kernels' f and pdf at (wo, wi) against each other or a reference
double tolerance(const MaterialCase& mat, const Geometry& g, const Oriented& o, glm::dvec3 wo, glm::dvec3 wi) {
  double tol = float_tolerance(std::min(std::fabs(glm::dot(wo, o.ns)), std::fabs(glm::dot(wi, o.ns))));
  const dev::Material& m = mat.material;
  if (!has_transmission(m)) return tol;
  Frame f = shading_frame(g, o, m);
  double eta = o.front ? ior(m) : 1.0 / ior(m);
  return tol + dielectric_tolerance(eta, m.flags & MATERIAL_THIN_WALLED, f.local(wo), f.local(wi));
}

// Sampled directions and their weights at one geometry: the pdf integrates to at most 1
// (to 1 for a normalized lobe at ns == ng); non-delta samples are returned as often as
// that integral says and are distributed as bsdf_pdf (chi-square); every returned sample
// is a valid direction whose f, pdf and weight f |cos| / pdf are what bsdf_eval and
// bsdf_pdf give (delta samples: validity only); the eta^2-weighted albedo is at most 1 + 4 SE
// (the known albedo where there is one).
void check_sampling(const std::string& device, const BsdfRun& r, const MaterialCase& mat, KnownBugs& bugs) {
  Oriented o = orient(r.geo);
  Samples s = r.sample(seed_on(device, 4321), samples_on(device));
  SphereCells grid = cells_for(mat.cells, r.geo, o, r.material);
  std::vector<double> cells = grid.integrals([&](const auto& w) { return r.pdf(w); });
  double integral = 0.0;
  for (double c : cells) integral += c;
  EXPECT_LE(integral, 1.0 + kIntegrationTolerance) << "pdf integral";
  if (mat.pdf_normalized && o.shading_is_geometric) {
    EXPECT_NEAR(integral, 1.0, 1e-3) << "pdf integral";
  }
  size_t n = 0;
  ChiSquare chi2 = direction_chi_square(s, grid, cells, &n);
  double fraction = double(n) / s.size();
  double sigma = std::sqrt(std::max(integral * (1.0 - integral), 0.0) / s.size());
  EXPECT_NEAR(fraction, integral, kZ * sigma + kIntegrationTolerance) << "returned non-delta samples vs pdf integral";
  if (n > 0) {
    EXPECT_GT(chi2.p_value, kAlpha) << "chi2 " << chi2.statistic << " dof " << chi2.dof;
  }

  size_t bad = 0;
  auto fail = [&](size_t i, const std::string& what) {
    if (++bad <= 5)
      ADD_FAILURE() << "sample " << i << ": " << what << "; wi " << s.out[3 * i].s[0] << " " << s.out[3 * i].s[1] << " "
                    << s.out[3 * i].s[2] << " pdf " << s.pdf(i) << " eval pdf " << s.out[3 * i + 2].s[3];
  };
  for (size_t i = 0; i < s.size(); ++i) {
    if (!s.returned(i)) continue;
    if (!s.info[i].s[3]) fail(i, "flags outside bsdf_flags or not one of reflection, transmission");
    glm::dvec3 wi = s.wi(i), f = s.f(i), fe = d3(s.out[3 * i + 2]);
    double pdf = s.pdf(i), pdf_e = s.out[3 * i + 2].s[3];
    if (std::fabs(glm::length(wi) - 1.0) > 1e-5) fail(i, "wi not unit");
    if (!(pdf > 0.0) || !std::isfinite(pdf)) fail(i, "pdf not positive and finite");
    if (!(std::isfinite(f.x) && std::isfinite(f.y) && std::isfinite(f.z)) || glm::min(f.x, glm::min(f.y, f.z)) < 0.0)
      fail(i, "f negative or not finite");
    if (s.reflection(i) != (glm::dot(wi, o.ng) > 0.0)) fail(i, "reflection flag disagrees with the geometric side");
    if (s.reflection(i) && s.eta(i) != 1.0) fail(i, "eta != 1 on reflection");
    if (s.delta(i)) continue;
    double cos_i = std::fabs(glm::dot(wi, o.ns)), tol = tolerance(mat, r.geo, o, r.geo.wo, wi);
    if (!near_rel(pdf, pdf_e, tol)) fail(i, "pdf != bsdf_pdf");
    if (!near_vec(f, fe, tol)) fail(i, "f != bsdf_eval");
    if (!(pdf_e > 0.0) || !near_vec(f * cos_i / pdf, fe * cos_i / pdf_e, tol))
      fail(i, "weight != bsdf_eval |cos| / bsdf_pdf");
  }
  EXPECT_EQ(bad, 0u) << "inconsistent samples";

  SampleMean a = estimate(energy_weights(s, o.ns));
  bool created = false;
  for (int c = 0; c < 3; ++c) created = created || a.mean[c] > 1.0 + 4.0 * a.se[c] + 1e-5;
  if (const std::string* bug = bugs.find(mat, "albedo", r.geo)) {
    EXPECT_TRUE(created) << "no longer reproduces, remove the entry: " << *bug;
  } else {
    EXPECT_FALSE(created) << "albedo " << a.mean.x << " " << a.mean.y << " " << a.mean.z << " SE " << a.se.x << " "
                          << a.se.y << " " << a.se.z;
  }
  std::optional<glm::dvec3> exact =
      mat.albedo && o.shading_is_geometric ? mat.albedo(std::fabs(glm::dot(r.geo.wo, o.ns))) : std::nullopt;
  for (int c = 0; exact && c < 3; ++c)
    EXPECT_NEAR(a.mean[c], (*exact)[c], 4.0 * a.se[c] + 1e-5) << "albedo, channel " << c << " SE " << a.se[c];
}

// Reflection: f(wo, wi) = f(wi, wo) for pairs above both normals. Refraction, by the
// generalized reciprocity of radiance BTDFs (Veach 1997, sec. 5.2; pbrt-v4 sec. 9.5.2):
// with eta_o and eta_i the indices of the media that wo and wi lie in, Walter 2007 eq. 21
// with the radiance scaling 1 / eta^2 (eta = eta_i / eta_o) is f(wo, wi) = eta_o^2 S(wo, wi)
// with S symmetric (its half vector, D, G, 1 - F and the Jacobian are), so
//   f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2,
// i.e. radiance seen from the dense side is eta^2 brighter. A thin sheet has air on both
// sides: plain reciprocity.
void check_reciprocity(const BsdfRun& run, const MaterialCase& mat, KnownBugs& bugs) {
  const Geometry& g = run.geo;
  const dev::Material& m = mat.material;
  Oriented o = orient(g);
  std::mt19937_64 gen(7);
  std::normal_distribution<double> normal;
  // Random directions on one side of both normals, 0.01 off their horizons
  auto on_side = [&](double side) {
    for (;;) {
      glm::dvec3 w = glm::normalize(glm::dvec3(normal(gen), normal(gen), normal(gen)));
      if (side * glm::dot(w, o.ng) > 0.01 && side * glm::dot(w, o.ns) > 0.01) return w;
    }
  };
  const size_t n = 4096;
  std::vector<std::pair<glm::dvec3, glm::dvec3>> pairs(2 * n);
  for (size_t i = 0; i < n; ++i) {
    pairs[i] = {on_side(1.0), on_side(1.0)};
    pairs[n + i] = {pairs[i].second, pairs[i].first};
  }
  std::vector<cl_float4> v = run.eval(pairs);
  size_t bad = 0;
  for (size_t i = 0; i < n; ++i) {
    // Rounding of wo.h grows as the half vector's length |wo + wi| = 2 wo.h vanishes
    double cos_h = std::max(1e-3, 0.5 * glm::length(pairs[i].first + pairs[i].second));
    double tol = has_transmission(m) ? tolerance(mat, g, o, pairs[i].first, pairs[i].second) : 1e-5 + 3e-6 / cos_h;
    for (int c = 0; c < 3; ++c)
      if (!near_rel(v[i].s[c], v[n + i].s[c], tol) && ++bad <= 5)
        ADD_FAILURE() << "reflection pair " << i << " channel " << c << ": " << v[i].s[c] << " vs " << v[n + i].s[c];
  }
  EXPECT_EQ(bad, 0u);
  if (!has_transmission(m) || m.params.gltf.roughness == 0.0f || bugs.find(mat, "reciprocity", g)) return;
  // (outside, inside) pairs and their reverses
  glm::dvec3 outward = o.front ? o.ng : -o.ng;
  double eta_in = (m.flags & MATERIAL_THIN_WALLED) ? 1.0 : ior(m);
  for (size_t i = 0; i < n; ++i) {
    glm::dvec3 a = on_side(1.0), b = on_side(-1.0);
    if (glm::dot(a, outward) < 0.0) std::swap(a, b);
    pairs[i] = {a, b};
    pairs[n + i] = {b, a};
  }
  v = run.eval(pairs);
  size_t transmitted = 0;
  bad = 0;
  for (size_t i = 0; i < n; ++i) {
    // Each direction of the pair is evaluated with the hit oriented by its wo
    auto [a, b] = pairs[i];
    Geometry ga = seen_from(g, a), gb = seen_from(g, b);
    double tol = std::max(tolerance(mat, ga, orient(ga), a, b), tolerance(mat, gb, orient(gb), b, a));
    transmitted += v[i].s[0] > 0.0f;
    for (int c = 0; c < 3; ++c) {
      double out_in = v[i].s[c], in_out = v[n + i].s[c] / (eta_in * eta_in);
      // (1e-6 absolute: where one side rounds to the edge of the refraction lobe)
      if (!near_rel(out_in, in_out, tol) && std::fabs(out_in - in_out) > 1e-6 && ++bad <= 5)
        ADD_FAILURE() << "transmission pair " << i << " channel " << c << ": f(outside, inside) = " << out_in
                      << ", f(inside, outside) / eta^2 = " << in_out;
    }
  }
  EXPECT_EQ(bad, 0u);
  EXPECT_GT(transmitted, n / 8) << "transmission must be exercised";
}

// f and pdf equal the reference lobe's over the sphere, away from the horizons
void check_reference(const BsdfRun& run, const MaterialCase& mat, KnownBugs& bugs) {
  const Geometry& g = run.geo;
  if (bugs.find(mat, "reference", g)) return;
  Oriented o = orient(g);
  Frame shading = shading_frame(g, o, mat.material);
  std::mt19937_64 gen(11);
  std::normal_distribution<double> normal;
  std::vector<std::pair<glm::dvec3, glm::dvec3>> pairs;
  while (pairs.size() < 4096) {
    glm::dvec3 wi = glm::normalize(glm::dvec3(normal(gen), normal(gen), normal(gen)));
    if (std::fabs(glm::dot(wi, o.ng)) > 1e-3 && std::fabs(glm::dot(wi, o.ns)) > 1e-3) pairs.emplace_back(g.wo, wi);
  }
  std::vector<cl_float4> v = run.eval(pairs);
  size_t bad = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    glm::dvec3 wi = pairs[i].second;
    Reference ref = mat.reference(shading.local(g.wo), shading.local(wi), glm::dot(wi, o.ng) > 0.0, o.front);
    double tol = tolerance(mat, g, o, g.wo, wi);
    if ((!near_rel(v[i].s[3], ref.pdf, tol) || !near_vec(d3(v[i]), ref.f, tol)) && ++bad <= 5)
      ADD_FAILURE() << "wi " << wi.x << " " << wi.y << " " << wi.z << ": f " << v[i].s[0] << " " << v[i].s[1] << " "
                    << v[i].s[2] << " pdf " << v[i].s[3] << ", reference f " << ref.f.x << " " << ref.f.y << " "
                    << ref.f.z << " pdf " << ref.pdf;
  }
  EXPECT_EQ(bad, 0u);
}

// The device's rig, or null when the device is absent
KernelRig* rig_or_null(const std::string& device) {
  auto d = device_by_name(device);
  return d ? &rig_for(device, *d) : nullptr;
}

using Param = std::tuple<std::string, MaterialCase>;

// Sampling: one test per device x material, every geometry inside
class BsdfTest : public ::testing::TestWithParam<Param> {
 protected:
  static void TearDownTestSuite() { rigs().clear(); }
};

// Evaluation: one test per device, every material x geometry inside (cheap)
class BsdfEval : public ::testing::TestWithParam<std::string> {
 protected:
  static void TearDownTestSuite() { rigs().clear(); }
};

}  // namespace

// Every sampling check (check_sampling) at every geometry
TEST_P(BsdfTest, Sampling) {
  const auto& [device, mat] = GetParam();
  KernelRig* r = rig_or_null(device);
  if (!r) GTEST_SKIP() << device << " OpenCL device is not available";
  KnownBugs bugs;
  for (const Geometry& g : kGeometries) {
    if (!runs_on(device, g)) continue;
    SCOPED_TRACE(g.name);
    check_sampling(device, BsdfRun(*r, mat.material, g), mat, bugs);
  }
  BSDF_SKIP_KNOWN_BUGS(bugs);
}

INSTANTIATE_TEST_SUITE_P(Lobes, BsdfTest,
                         ::testing::Combine(::testing::Values("pocl", "rusticl"), ::testing::ValuesIn(kMaterials)),
                         [](const ::testing::TestParamInfo<Param>& info) {
                           return std::get<0>(info.param) + "_" + std::get<1>(info.param).name;
                         });

// check_reciprocity for every material at every geometry
TEST_P(BsdfEval, IsReciprocal) {
  KernelRig* r = rig_or_null(GetParam());
  if (!r) GTEST_SKIP() << GetParam() << " OpenCL device is not available";
  KnownBugs bugs;
  for (const MaterialCase& mat : kMaterials)
    for (const Geometry& g : kGeometries) {
      if (!runs_on(GetParam(), g)) continue;
      SCOPED_TRACE(mat.name + " " + g.name);
      check_reciprocity(BsdfRun(*r, mat.material, g), mat, bugs);
    }
  BSDF_SKIP_KNOWN_BUGS(bugs);
}

// check_reference for every material with a reference lobe, at every geometry
TEST_P(BsdfEval, MatchesReference) {
  KernelRig* r = rig_or_null(GetParam());
  if (!r) GTEST_SKIP() << GetParam() << " OpenCL device is not available";
  KnownBugs bugs;
  for (const MaterialCase& mat : kMaterials)
    for (const Geometry& g : kGeometries) {
      if (!mat.reference || !runs_on(GetParam(), g)) continue;
      SCOPED_TRACE(mat.name + " " + g.name);
      check_reference(BsdfRun(*r, mat.material, g), mat, bugs);
    }
  BSDF_SKIP_KNOWN_BUGS(bugs);
}

INSTANTIATE_TEST_SUITE_P(Lobes, BsdfEval, ::testing::Values("pocl", "rusticl"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

namespace {

// The harness's checks must be able to fail
class BsdfHarness : public ::testing::Test {
 protected:
  static void TearDownTestSuite() { rigs().clear(); }
  KernelRig& rig() { return rig_for("pocl", pocl_device()); }
};

// Samples of `sampled` against the pdf of `hypothesis` on the cells of `spec`
ChiSquare mismatched_chi_square(KernelRig& rig, const dev::Material& sampled, const dev::Material& hypothesis,
                                const Geometry& g, const CellSpec& spec) {
  BsdfRun s(rig, sampled, g), h(rig, hypothesis, g);
  Oriented o = orient(g);
  SphereCells grid = cells_for(spec, g, o, hypothesis);
  size_t n = 0;
  return direction_chi_square(s.sample(4321), grid, grid.integrals([&](const auto& w) { return h.pdf(w); }), &n);
}

}  // namespace

// Lambert samples against a uniform hemisphere pdf
TEST_F(BsdfHarness, ChiSquareRejectsAWrongPdf) {
  BsdfRun r(rig(), kMaterials[0].material, kGeometries[0]);
  Oriented o = orient(r.geo);
  Samples s = r.sample(4321);
  auto uniform_hemisphere = [&](const std::vector<glm::dvec3>& w) {
    std::vector<double> p;
    for (const auto& d : w) p.push_back(glm::dot(d, o.ns) > 0.0 ? 0.5 / kPi : 0.0);
    return p;
  };
  size_t n = 0;
  SphereCells grid = cells_for(kMaterials[0].cells, r.geo, o, r.material);
  ChiSquare chi2 = direction_chi_square(s, grid, grid.integrals(uniform_hemisphere), &n);
  EXPECT_GT(n, 0u);
  EXPECT_LT(chi2.p_value, 1e-6);
}

// The narrow-lobe cells tell alpha = 0.04 (roughness 0.2) from alpha = 0.0441 (0.21)
TEST_F(BsdfHarness, NarrowCellsRejectAWrongRoughness) {
  ChiSquare chi2 = mismatched_chi_square(rig(), gold(0.2), gold(0.21), kGeometries[3], kNarrow);
  EXPECT_LT(chi2.p_value, 1e-6) << "chi2 " << chi2.statistic << " dof " << chi2.dof;
}

// ... and a refracted lobe from one refracted with another index
TEST_F(BsdfHarness, RefractionCellsRejectAWrongIor) {
  dev::Material glass = gltf(glm::dvec3(1.0), 0.0, 0.3, 1.0), other = glass;
  other.params.gltf.ior = 1.45f;
  ChiSquare chi2 = mismatched_chi_square(rig(), glass, other, kGeometries[3], kNarrow);
  EXPECT_LT(chi2.p_value, 1e-6) << "chi2 " << chi2.statistic << " dof " << chi2.dof;
}

namespace {

// A Dirac lobe expected among bsdf_sample's delta samples: its direction, flags and eta,
// its per-sample weight f |cos| / pdf (where it is one value), its frequency (where the
// lobe choice is the Fresnel term, not a heuristic) and its contribution E[weight]
struct DeltaLobe {
  std::string name;
  glm::dvec3 wi;
  bool reflection;
  double eta;
  std::optional<glm::dvec3> weight;
  std::optional<double> probability;
  glm::dvec3 contribution;
};

// A shading point with ng = ns = z, wo at theta from +z (front) or -z (back)
Geometry flat(double theta_deg, bool back) {
  glm::dvec3 n(0.0, 0.0, back ? -1.0 : 1.0);
  return {"flat", {0, 0, 1}, {0, 0, 1}, {1, 0, 0}, around(n, theta_deg, 30.0)};
}

// Every delta sample belongs to one of `lobes` with its flags, eta and weight; the lobes'
// frequencies and contributions match within kZ standard errors; `pure`: no non-delta
// sample either
void check_delta(const Samples& s, const std::vector<DeltaLobe>& lobes, bool pure) {
  std::vector<std::vector<glm::dvec3>> contributions(lobes.size(), std::vector<glm::dvec3>(s.size(), glm::dvec3(0.0)));
  std::vector<size_t> counts(lobes.size(), 0);
  size_t bad = 0, nondelta = 0;
  auto fail = [&](size_t i, const std::string& what) {
    if (++bad <= 5)
      ADD_FAILURE() << "sample " << i << ": " << what << "; wi " << s.wi(i).x << " " << s.wi(i).y << " " << s.wi(i).z
                    << " f " << s.f(i).x << " pdf " << s.pdf(i) << " eta " << s.eta(i);
  };
  for (size_t i = 0; i < s.size(); ++i) {
    if (!s.returned(i)) continue;
    if (!s.delta(i)) {
      ++nondelta;
      continue;
    }
    auto lobe = std::find_if(lobes.begin(), lobes.end(), [&](const DeltaLobe& l) {
      return glm::length(s.wi(i) - l.wi) < 1e-5 && s.reflection(i) == l.reflection;
    });
    if (lobe == lobes.end()) {
      fail(i, "a delta sample in no expected lobe");
      continue;
    }
    size_t k = size_t(lobe - lobes.begin());
    ++counts[k];
    glm::dvec3 w = s.f(i) * std::fabs(s.wi(i).z) / s.pdf(i);
    contributions[k][i] = w;
    if (!s.info[i].s[3]) fail(i, "flags outside bsdf_flags or not one of reflection, transmission");
    if (std::fabs(s.eta(i) - lobe->eta) > 1e-6 * lobe->eta) fail(i, lobe->name + ": eta");
    if (lobe->weight && !near_vec(w, *lobe->weight, 1e-4)) fail(i, lobe->name + ": weight");
  }
  EXPECT_EQ(bad, 0u);
  if (pure) {
    EXPECT_EQ(nondelta, 0u) << "non-delta samples from a purely specular surface";
  }
  const double n = double(s.size());
  for (size_t k = 0; k < lobes.size(); ++k) {
    if (lobes[k].probability) {
      double p = *lobes[k].probability;
      EXPECT_NEAR(counts[k] / n, p, kZ * std::sqrt(p * (1.0 - p) / n) + 1e-6) << lobes[k].name << " frequency";
    }
    SampleMean e = estimate(contributions[k]);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(e.mean[c], lobes[k].contribution[c], kZ * e.se[c] + 1e-4 * lobes[k].contribution[c] + 1e-7)
          << lobes[k].name << " contribution, channel " << c;
  }
}

glm::dvec3 gold_fresnel(double c) {
  return {fresnel_conductor(c, kGoldEta.x, kGoldK.x), fresnel_conductor(c, kGoldEta.y, kGoldK.y),
          fresnel_conductor(c, kGoldEta.z, kGoldK.z)};
}

// Smooth glass seen from wo: reflection with probability R and weight 1, refraction with
// 1 - R and weight 1 / eta^2 (radiance), or a thin sheet's straight transmission with
// R' = 2R / (1 + R) (inter-reflections in the sheet) and weight 1
std::vector<DeltaLobe> glass_lobes(const Geometry& g, double ior, bool thin, glm::dvec3 tint) {
  Oriented o = orient(g);
  double eta = o.front || thin ? ior : 1.0 / ior, c = glm::dot(g.wo, o.ns), r = fresnel_dielectric(c, eta);
  if (thin) r = 2.0 * r / (1.0 + r);
  std::vector<DeltaLobe> lobes = {{"reflection", mirror(g.wo, o.ns), true, 1.0, glm::dvec3(1.0), r, glm::dvec3(r)}};
  if (thin) {
    lobes.push_back({"straight", -g.wo, false, 1.0, tint, 1.0 - r, tint * (1.0 - r)});
  } else if (auto t = refract(g.wo, o.ns, eta)) {
    lobes.push_back({"refraction", *t, false, eta, tint / (eta * eta), 1.0 - r, tint * (1.0 - r) / (eta * eta)});
  }
  return lobes;
}

class BsdfDelta : public ::testing::TestWithParam<std::string> {
 protected:
  static void TearDownTestSuite() { rigs().clear(); }
  KernelRig* rig() {
    auto d = device_by_name(GetParam());
    return d ? &rig_for(GetParam(), *d) : nullptr;
  }
  Samples sample(KernelRig& r, const dev::Material& m, const Geometry& g) {
    return BsdfRun(r, m, g).sample(seed_on(GetParam(), 99), 1 << 16);
  }
};

#define DELTA_RIG_OR_SKIP(r) \
  KernelRig* r = rig();      \
  if (!r) GTEST_SKIP() << GetParam() << " OpenCL device is not available"

}  // namespace

// A smooth conductor is a mirror of weight F(cos theta), the exact complex Fresnel term
TEST_P(BsdfDelta, SmoothConductor) {
  DELTA_RIG_OR_SKIP(r);
  for (double theta : {0.0, 45.0, 80.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    Geometry g = flat(theta, false);
    glm::dvec3 f = gold_fresnel(g.wo.z);
    check_delta(sample(*r, gold(0.0), g), {{"mirror", mirror(g.wo, g.ns), true, 1.0, f, 1.0, f}}, true);
  }
}

// Smooth glass from outside and from inside, below and beyond the critical angle (total
// internal reflection: all reflected, weight 1)
TEST_P(BsdfDelta, SmoothGlass) {
  DELTA_RIG_OR_SKIP(r);
  dev::Material glass = gltf(glm::dvec3(1.0), 0.0, 0.0, 1.0);
  for (auto [theta, back] : std::vector<std::pair<double, bool>>{
           {0, false}, {45, false}, {80, false}, {20, true}, {40, true}, {60, true}, {80, true}}) {
    SCOPED_TRACE("theta " + std::to_string(theta) + (back ? " inside" : " outside"));
    Geometry g = flat(theta, back);
    check_delta(sample(*r, glass, g), glass_lobes(g, 1.5, false, glm::dvec3(1.0)), true);
  }
}

// A thin sheet: straight through with the tint, or reflected, R' = 2R / (1 + R)
TEST_P(BsdfDelta, SmoothThinSheet) {
  DELTA_RIG_OR_SKIP(r);
  glm::dvec3 tint(0.9, 0.6, 0.3);
  dev::Material sheet = gltf(tint, 0.0, 0.0, 1.0, true);
  for (double theta : {0.0, 60.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    Geometry g = flat(theta, false);
    check_delta(sample(*r, sheet, g), glass_lobes(g, 1.5, true, tint), true);
  }
}

// A thin-walled sheet has air on both sides: seen from behind it reflects and transmits as
// from the front (no total internal reflection), smooth or rough
TEST_P(BsdfDelta, ThinSheetLooksTheSameFromBothSides) {
  DELTA_RIG_OR_SKIP(r);
  glm::dvec3 tint(0.9, 0.6, 0.3);
  for (double theta : {30.0, 60.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    Geometry g = flat(theta, true);
    check_delta(sample(*r, gltf(tint, 0.0, 0.0, 1.0, true), g), glass_lobes(g, 1.5, true, tint), true);
    // Rough: f(wo, wi) from behind equals f of the mirrored pair in front
    dev::Material rough = gltf(tint, 0.0, 0.3, 1.0, true);
    auto flip = [](glm::dvec3 w) { return glm::dvec3(w.x, w.y, -w.z); };  // through the sheet
    Geometry front = seen_from(g, flip(g.wo));
    BsdfRun back_run(*r, rough, g), front_run(*r, rough, front);
    std::mt19937_64 gen(5);
    std::normal_distribution<double> normal;
    std::vector<std::pair<glm::dvec3, glm::dvec3>> back_pairs, front_pairs;
    for (int i = 0; i < 1024; ++i) {
      glm::dvec3 wi = glm::normalize(glm::dvec3(normal(gen), normal(gen), normal(gen)));
      if (std::fabs(wi.z) < 0.01) continue;
      back_pairs.emplace_back(g.wo, wi);
      front_pairs.emplace_back(front.wo, flip(wi));
    }
    std::vector<cl_float4> b = back_run.eval(back_pairs), f = front_run.eval(front_pairs);
    size_t bad = 0;
    for (size_t i = 0; i < b.size(); ++i)
      if (!near_vec(d3(b[i]), d3(f[i]), 1e-3) && ++bad <= 5)
        ADD_FAILURE() << "pair " << i << ": behind " << b[i].s[0] << ", in front " << f[i].s[0];
    EXPECT_EQ(bad, 0u);
  }
}

// glTF mirrors: metal of weight Schlick(base, 1); plastic and a coat over a rough metal,
// whose delta lobe is chosen by a heuristic, contribute Schlick(F0, 1) on average; a
// smooth mixture of metal, plastic and glass sums its components' mirrors and refracts (1 - m) t (1 - R)
TEST_P(BsdfDelta, SmoothGltf) {
  DELTA_RIG_OR_SKIP(r);
  const glm::dvec3 base(0.9, 0.6, 0.3);
  for (double theta : {0.0, 60.0, 85.0}) {
    SCOPED_TRACE("theta " + std::to_string(theta));
    Geometry g = flat(theta, false);
    double c = g.wo.z;
    glm::dvec3 wr = mirror(g.wo, g.ns), metal = schlick(base, glm::dvec3(1.0), c);
    {
      SCOPED_TRACE("metal");
      check_delta(sample(*r, gltf(base, 1.0, 0.0), g), {{"mirror", wr, true, 1.0, metal, 1.0, metal}}, true);
    }
    {
      SCOPED_TRACE("plastic");
      glm::dvec3 spec = schlick(glm::dvec3(0.04), glm::dvec3(1.0), c);
      check_delta(sample(*r, gltf(base, 0.0, 0.0), g), {{"mirror", wr, true, 1.0, {}, {}, spec}}, false);
    }
    {
      SCOPED_TRACE("coat over rough metal");
      dev::Material m = gltf(base, 1.0, 0.5);
      m.params.gltf.clearcoat = 1.0f;
      glm::dvec3 coat(0.04 + 0.96 * schlick_weight(c));
      check_delta(sample(*r, m, g), {{"mirror", wr, true, 1.0, {}, {}, coat}}, false);
    }
    {
      // m = 0.5, t = 0.5: metal 1/2, plastic (1 - m)(1 - t) = 1/4, glass (1 - m) t = 1/4
      SCOPED_TRACE("metal, plastic and glass");
      double fr = fresnel_dielectric(c, 1.5);
      glm::dvec3 t = refract(g.wo, g.ns, 1.5).value(), spec = schlick(glm::dvec3(0.04), glm::dvec3(1.0), c);
      check_delta(sample(*r, gltf(base, 0.5, 0.0, 0.5), g),
                  {{"mirror", wr, true, 1.0, {}, {}, 0.5 * metal + 0.25 * spec + 0.25 * fr},
                   {"refraction", t, false, 1.5, {}, {}, 0.25 * base * (1.0 - fr) / 2.25}},
                  false);
    }
  }
}

namespace {

// Energy reflected and transmitted (eta^2-weighted) by `m` from wo, by sampling
std::pair<SampleMean, SampleMean> split_energy(KernelRig& r, const dev::Material& m, const Geometry& g, cl_uint seed) {
  Samples s = BsdfRun(r, m, g).sample(seed, 1 << 16);
  std::vector<glm::dvec3> w = energy_weights(s, g.ns), reflected(w.size(), glm::dvec3(0.0)), transmitted = reflected;
  for (size_t i = 0; i < w.size(); ++i) (s.returned(i) && s.reflection(i) ? reflected : transmitted)[i] = w[i];
  return {estimate(reflected), estimate(transmitted)};
}

// A rough dielectric just above GGX_DELTA_ALPHA (roughness 0.035, alpha 0.0012) splits
// energy as the smooth one just below it: no jump at the threshold
void check_continuity(KernelRig& r, cl_uint seed, bool thin) {
  for (auto [theta, back] : std::vector<std::pair<double, bool>>{{0, false}, {45, false}, {30, true}}) {
    if (thin && back) continue;
    SCOPED_TRACE("theta " + std::to_string(theta) + (back ? " inside" : " outside"));
    Geometry g = flat(theta, back);
    auto [rough_r, rough_t] = split_energy(r, gltf(glm::dvec3(1.0), 0.0, 0.035, 1.0, thin), g, seed);
    auto [smooth_r, smooth_t] = split_energy(r, gltf(glm::dvec3(1.0), 0.0, 0.0, 1.0, thin), g, seed);
    EXPECT_NEAR(rough_r.mean.x, smooth_r.mean.x, 0.01 * smooth_r.mean.x + kZ * (rough_r.se.x + smooth_r.se.x))
        << "reflected";
    EXPECT_NEAR(rough_t.mean.x, smooth_t.mean.x, 0.01 * smooth_t.mean.x + kZ * (rough_t.se.x + smooth_t.se.x))
        << "transmitted";
  }
}

}  // namespace

TEST_P(BsdfDelta, RoughGlassApproachesSmooth) {
  DELTA_RIG_OR_SKIP(r);
  check_continuity(*r, seed_on(GetParam(), 5), false);
}

// A thin sheet's reflectance, 2R / (1 + R) with inter-reflections, does not jump as its
// roughness crosses GGX_DELTA_ALPHA (rough and smooth sheets agree)
TEST_P(BsdfDelta, RoughThinSheetApproachesSmooth) {
  DELTA_RIG_OR_SKIP(r);
  check_continuity(*r, seed_on(GetParam(), 5), true);
}

INSTANTIATE_TEST_SUITE_P(Devices, BsdfDelta, ::testing::Values("pocl", "rusticl"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

namespace {

// A lobe family for the energy grid, by roughness; `back`: wo inside the solid
struct EnergyLobe {
  std::string name;
  std::function<dev::Material(double roughness)> material;
  bool back;
  std::string bug;  // a known kernel bug that creates energy: those rows are noted, not failed
};

const std::vector<double> kEnergyRoughness = {0.05, 0.3, 0.6, 1.0};
const std::vector<double> kEnergyTheta = {0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0};

std::vector<EnergyLobe> energy_lobes() {
  const glm::dvec3 white(1.0);
  auto coat = [=](double r) {
    dev::Material m = gltf(white, 0.0, r);
    m.params.gltf.clearcoat = 1.0f;
    m.params.gltf.clearcoat_roughness = float(r);
    return m;
  };
  return {
      {"conductor_gold", [](double r) { return gold(r); }, false, ""},
      {"metal_white", [=](double r) { return gltf(white, 1.0, r); }, false, ""},
      {"plastic_white", [=](double r) { return gltf(white, 0.0, r); }, false, ""},
      {"glass_outside", [=](double r) { return gltf(white, 0.0, r, 1.0); }, false, ""},
      {"glass_inside", [=](double r) { return gltf(white, 0.0, r, 1.0); }, true, ""},
      {"thin_glass", [=](double r) { return gltf(white, 0.0, r, 1.0, true); }, false, ""},
      {"coat_plastic_white", coat, false, ""},
      {"smooth_coat_metal_white",
       [=](double r) {
         dev::Material m = coat(r);
         m.params.gltf.metallic = 1.0f;
         m.params.gltf.clearcoat_roughness = 0.0f;
         return m;
       },
       false, ""},
      {"mixture_white", [=](double r) { return gltf(white, 0.5, r, 0.5); }, false, ""},
  };
}

class BsdfEnergy : public ::testing::TestWithParam<std::string> {
 protected:
  static void TearDownTestSuite() { rigs().clear(); }
};

}  // namespace

// The eta^2-weighted albedo (energy_weights) is at most 1 + 4 SE for every lobe on a grid of
// incidence angles x roughness: one launch per lobe, 64K samples a cell (8K on rusticl)
TEST_P(BsdfEnergy, AlbedoAtMostOne) {
  auto d = device_by_name(GetParam());
  if (!d) GTEST_SKIP() << GetParam() << " OpenCL device is not available";
  KernelRig& rig = rig_for(GetParam(), *d);
  const cl_uint per = GetParam() == "rusticl" ? 1u << 13 : 1u << 16;
  const size_t configs = kEnergyRoughness.size() * kEnergyTheta.size();
  std::string noted;
  for (const EnergyLobe& lobe : energy_lobes()) {
    SCOPED_TRACE(lobe.name);
    std::vector<dev::Material> mats;
    for (double r : kEnergyRoughness) mats.push_back(lobe.material(r));
    std::vector<cl_float4> wos;
    for (double t : kEnergyTheta) wos.push_back(f4(flat(t, lobe.back).wo));
    cl::Buffer mb = upload_materials(rig, mats);
    cl::Buffer wb(rig.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, wos.size() * sizeof(cl_float4), wos.data());
    cl::Buffer out(rig.context, CL_MEM_WRITE_ONLY, configs * per * sizeof(cl_float4));
    cl::Kernel k(rig.program, "test_bsdf_albedo");
    k.setArg(0, mb);
    k.setArg(1, f4({0, 0, 1}));
    k.setArg(2, f4({0, 0, 1}));
    k.setArg(3, f4({1, 0, 0}));
    k.setArg(4, wb);
    k.setArg(5, cl_uint(wos.size()));
    k.setArg(6, per);
    k.setArg(7, seed_on(GetParam(), 17));
    k.setArg(8, out);
    rig.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(configs * per));
    std::vector<cl_float4> w(configs * per);
    rig.queue.enqueueReadBuffer(out, CL_TRUE, 0, w.size() * sizeof(cl_float4), w.data());
    std::string created;
    for (size_t c = 0; c < configs; ++c) {
      std::vector<glm::dvec3> v;
      for (size_t i = c * per; i < (c + 1) * per; ++i) v.push_back(d3(w[i]));
      SampleMean e = estimate(v);
      double r = kEnergyRoughness[c / wos.size()], t = kEnergyTheta[c % wos.size()];
      std::string where = "roughness " + std::to_string(r) + " theta " + std::to_string(t);
      if (lobe.name == "metal_white" && t == 0.0)
        RecordProperty("albedo_metal_white_r" + std::to_string(r),
                       std::to_string(e.mean.x) + " SE " + std::to_string(e.se.x));
      for (int ch = 0; ch < 3; ++ch)
        if (e.mean[ch] > 1.0 + 4.0 * e.se[ch] + 1e-5) {
          created += " " + where + ": " + std::to_string(e.mean[ch]) + " (SE " + std::to_string(e.se[ch]) + ");";
          break;
        }
    }
    if (!lobe.bug.empty()) {
      EXPECT_FALSE(created.empty()) << "no longer reproduces, remove the note: " << lobe.bug;
      noted += lobe.name + " creates energy at" + created + " " + lobe.bug + "\n";
    } else {
      EXPECT_TRUE(created.empty()) << "albedo above 1 at" << created;
    }
  }
  if (!noted.empty()) GTEST_SKIP() << noted;
}

INSTANTIATE_TEST_SUITE_P(Devices, BsdfEnergy, ::testing::Values("pocl", "rusticl"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return info.param; });

}  // namespace candela::test
