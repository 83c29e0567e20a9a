#include "bsdf/bsdf_checks.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "device/energy.hpp"
#include "device/sheen_albedo.hpp"

namespace candela::test {

size_t samples_on(const std::string& device, size_t n) { return device == "rusticl" ? n / 4 : n; }
size_t samples_on(const std::string& device) { return samples_on(device, kSamples); }
cl_uint seed_on(const std::string& device, cl_uint seed) { return device == "rusticl" ? seed + 1000 : seed; }

namespace {

// The pdf is integrated over histogram cells on this grid over the sphere (rings x sectors
// of the cells' coordinates): 2-point Gauss-Legendre in cos theta per ring, which follows
// GGX's heavy tails where the midpoint rule loses 5e-4 of an alpha = 0.04 lobe, and the
// midpoint rule in phi. Its error over the sphere comes from the pdf's jumps at the
// horizons (about 1e-4 with ns 20 degrees off ng).
constexpr int kIntegrationRings = 160, kIntegrationSectors = 320;
constexpr double kIntegrationTolerance = 2e-4;

}  // namespace

// ---- Host reference lobes ----

const Reference kNothing{glm::dvec3(0.0), 0.0};

double dielectric_reflectance(double cos_i, double eta, bool thin) {
  double r = fresnel_dielectric(cos_i, eta);
  return thin ? 2.0 * r / (1.0 + r) : r;
}

Reference dielectric_transmission(const GgxReference& g, double eta, bool thin, glm::dvec3 wo, glm::dvec3 wi) {
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

namespace {

// Fujii's single-scattering albedo in closed form: A (1 + r G(mu) / pi) with
// G(mu) = S (acos mu - S mu) + 2/3 (S / mu (1 - S^3) - S), S = sin theta
constexpr double kEonC1 = 0.5 - 2.0 / (3.0 * kPi), kEonC2 = 2.0 / 3.0 - 28.0 / (15.0 * kPi);
double fon_albedo(double mu, double r) {
  double s = std::sqrt(std::max(1.0 - mu * mu, 0.0));
  double g = s * (std::acos(mu) - s * mu) + 2.0 / 3.0 * (s / mu * (1.0 - s * s * s) - s);
  return (1.0 + r * g / kPi) / (1.0 + kEonC1 * r);
}
double fon_average(double r) { return (1.0 + kEonC2 * r) / (1.0 + kEonC1 * r); }
glm::dvec3 eon_rho_ms(glm::dvec3 rho, double r) {
  double e = fon_average(r);
  return rho * rho * e / (1.0 - rho * (1.0 - e));
}

}  // namespace

glm::dvec3 eon_reference(glm::dvec3 rho, double r, glm::dvec3 wo, glm::dvec3 wi) {
  double s = glm::dot(wo, wi) - wo.z * wi.z, t = s > 0.0 ? std::max(wo.z, wi.z) : 1.0;
  glm::dvec3 single = rho / kPi * (1.0 + r * s / t) / (1.0 + kEonC1 * r);
  double multiple = (1.0 - fon_albedo(wo.z, r)) * (1.0 - fon_albedo(wi.z, r)) / (1.0 - fon_average(r));
  return single + eon_rho_ms(rho, r) / kPi * multiple;
}

glm::dvec3 eon_albedo(glm::dvec3 rho, double r, double cos_o) {
  double e = fon_albedo(cos_o, r);
  return rho * e + eon_rho_ms(rho, r) * (1.0 - e);
}

GltfReference::GltfReference(const dev::Material& m)
    : base(m.base_color[0], m.base_color[1], m.base_color[2]),
      metallic(m.params.gltf.metallic),
      transmission(m.params.gltf.transmission),
      ior(m.params.gltf.ior),
      f90(m.params.gltf.specular),
      coat(m.params.gltf.clearcoat),
      diffuse_roughness(m.params.gltf.diffuse_roughness),
      thin((m.flags & MATERIAL_THIN_WALLED) != 0u),
      ggx(GgxReference::from(m.params.gltf.roughness, m.params.gltf.anisotropy_strength)),
      coat_ggx(GgxReference::from(m.params.gltf.clearcoat_roughness, 0.0)) {
  double r = (ior - 1.0) / (ior + 1.0);
  const float* tint = m.params.gltf.specular_color;
  f0 = glm::min(r * r * glm::dvec3(tint[0], tint[1], tint[2]), 1.0) * f90;
}

double GltfReference::coat_fresnel(double c) const { return coat * (0.04 + 0.96 * schlick_weight(c)); }
double GltfReference::spec_albedo(double mu) const { return max_component(schlick(f0, glm::dvec3(f90), mu)); }
double GltfReference::below_spec(double mu_o, double mu_i) const {
  return (1.0 - spec_albedo(mu_o)) * (1.0 - spec_albedo(mu_i));
}
double GltfReference::below_coat(double mu_o, double mu_i) const {
  return (1.0 - coat_fresnel(mu_o)) * (1.0 - coat_fresnel(mu_i));
}

std::array<double, 5> GltfReference::lobes(double cos_o) const {
  double m = metallic, t = transmission, fc = coat_fresnel(cos_o), fs = luminance(schlick(f0, glm::dvec3(f90), cos_o));
  std::array<double, 5> w = {fc, (1 - fc) * m, (1 - fc) * (1 - m) * (1 - t) * fs,
                             (1 - fc) * (1 - m) * (1 - t) * (1 - spec_albedo(cos_o)) * luminance(base),
                             (1 - fc) * (1 - m) * t};
  double sum = w[0] + w[1] + w[2] + w[3] + w[4];
  for (double& x : w) x = sum > 0.0 ? x / sum : 0.0;
  return w;
}

Reference GltfReference::operator()(glm::dvec3 wo, glm::dvec3 wi, bool reflection, bool front) const {
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
  glm::dvec3 diffuse = diffuse_roughness > 0.0 ? eon_reference(base, diffuse_roughness, wo, wi) : base / kPi;
  glm::dvec3 under = (1 - m) * (1 - t) * below_spec(wo.z, wi.z) * diffuse;
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

// ---- Material records ----

void PrintTo(const MaterialCase& m, std::ostream* os) { *os << m.name; }

dev::Material make_material(unsigned type, glm::dvec3 base_color) {
  dev::Material m{};
  m.type = type;
  for (int c = 0; c < 3; ++c) m.base_color[c] = float(base_color[c]);
  m.base_color[3] = 1.0f;
  if (type == MATERIAL_GLTF) {
    m.params.gltf.ior = 1.5f;
    for (float& s : m.params.gltf.specular_color) s = 1.0f;  // KHR_materials_specular defaults
    m.params.gltf.specular = 1.0f;
  }
  m.normal_scale = 1.0f;
  for (dev::TextureRef& t : m.textures) {
    t.index = NO_TEXTURE;
    t.m[0] = t.m[4] = 1.0f;
  }
  return m;
}

dev::Material gltf(glm::dvec3 base, double metallic, double roughness, double transmission, bool thin) {
  dev::Material m = make_material(MATERIAL_GLTF, base);
  m.params.gltf.metallic = float(metallic);
  m.params.gltf.roughness = float(roughness);
  m.params.gltf.transmission = float(transmission);
  if (thin) m.flags |= MATERIAL_THIN_WALLED;
  return m;
}

AlbedoTables::AlbedoTables(KernelRig& r, const cl::Program& program, const std::string& cache_file) {
  ggx = ggx_albedo_table(r.context, r.queue, program, cache_file).buffer;
  sheen = sheen_albedo_table(r.context, r.queue, program, cache_file).buffer;
}

dev::Material gold(double roughness, double anisotropy) {
  dev::Material m = make_material(MATERIAL_CONDUCTOR, glm::dvec3(1.0));
  for (int c = 0; c < 3; ++c) {
    m.params.conductor.eta[c] = float(gold_eta()[c]);
    m.params.conductor.k[c] = float(gold_k()[c]);
  }
  m.params.conductor.roughness = float(roughness);
  m.params.conductor.anisotropy_strength = float(anisotropy);
  return m;
}

float ior(const dev::Material& m) { return m.type == MATERIAL_GLTF ? m.params.gltf.ior : 1.5f; }

MaterialCase gltf_case(std::string name, dev::Material m, CellSpec cells) {
  return {name, m, false, {}, GltfReference(m), cells, {}};
}

MaterialCase delta_case(std::string name, dev::Material m, std::function<std::optional<glm::dvec3>(double)> albedo) {
  return {name, m, false, albedo, {}, {}, {}};
}

std::vector<LobeFamily> lobe_families() {
  return {diffuse_family(), conductor_family(), dielectric_family(), metallic_roughness_family()};
}

const std::vector<MaterialCase>& all_materials() {
  static const std::vector<MaterialCase> all = [] {
    std::vector<MaterialCase> v;
    for (const LobeFamily& f : lobe_families()) v.insert(v.end(), f.materials.begin(), f.materials.end());
    return v;
  }();
  return all;
}

const std::vector<EnergyLobe>& all_energy_lobes() {
  static const std::vector<EnergyLobe> all = [] {
    std::vector<EnergyLobe> v;
    for (const LobeFamily& f : lobe_families()) v.insert(v.end(), f.energy_lobes.begin(), f.energy_lobes.end());
    return v;
  }();
  return all;
}

const MaterialCase& material_case(const std::string& name) {
  for (const MaterialCase& m : all_materials())
    if (m.name == name) return m;
  throw std::invalid_argument("no material case " + name);
}

// ---- Shading geometry ----

Frame frame_around(glm::dvec3 n) {
  glm::dvec3 a = std::fabs(n.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
  glm::dvec3 t = glm::normalize(a - glm::dot(a, n) * n);
  return {t, glm::cross(n, t), n};
}

glm::dvec3 around(glm::dvec3 n, double theta_deg, double phi_deg) {
  double th = theta_deg * kPi / 180.0, ph = phi_deg * kPi / 180.0;
  return frame_around(glm::normalize(n))
      .world({std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
}

const std::vector<Geometry>& geometries() {
  static const glm::dvec3 kTilted = glm::normalize(glm::dvec3(1.0, 2.0, 3.0));
  static const glm::dvec3 kBumpedNs = around({0, 0, 1}, 20.0, 0.0);
  static const std::vector<Geometry> all = {
      {"normal", {0, 0, 1}, {0, 0, 1}, {1, 0, 0}, {0, 0, 1}},
      {"grazing", kTilted, kTilted, {1, 0, 0.5}, around(kTilted, 85.0, 30.0)},
      {"backfacing", {0, 0, 1}, {0, 0, 1}, {1, 0.2, 0.3}, around({0, 0, -1}, 40.0, 200.0)},
      {"bumped", {0, 0, 1}, kBumpedNs, {0, 1, 0}, around({0, 0, 1}, 40.0, 150.0)},
      // wo between ns and ng: dot(wo, ns) < 0 < dot(wo, ng); glossy lobes give nothing here
      {"belowshading", {0, 0, 1}, kBumpedNs, {0, 1, 0}, around({0, 0, 1}, 80.0, 180.0)},
      // From inside a refracting solid beyond the critical angle asin(1 / 1.5) = 41.8 degrees
      {"backgrazing", {0, 0, 1}, {0, 0, 1}, {1, 0, 0}, around({0, 0, -1}, 70.0, 60.0)},
  };
  return all;
}

const Geometry& geometry(const std::string& name) {
  for (const Geometry& g : geometries())
    if (g.name == name) return g;
  throw std::invalid_argument("no geometry " + name);
}

namespace {

// rusticl runs the material tests at these geometries only (front at grazing incidence,
// back face, bumped shading normal): it is about 5x slower a work-item than PoCL
const std::vector<std::string> kRusticlGeometries = {"grazing", "backfacing", "bumped"};

}  // namespace

bool runs_on(const std::string& device, const Geometry& g) {
  return device != "rusticl" ||
         std::find(kRusticlGeometries.begin(), kRusticlGeometries.end(), g.name) != kRusticlGeometries.end();
}

Geometry flat(double theta_deg, bool back) {
  glm::dvec3 n(0.0, 0.0, back ? -1.0 : 1.0);
  return {"flat", {0, 0, 1}, {0, 0, 1}, {1, 0, 0}, around(n, theta_deg, 30.0)};
}

Geometry seen_from(Geometry g, glm::dvec3 wo) {
  g.wo = wo;
  return g;
}

Oriented orient(const Geometry& g) {
  Oriented o;
  o.front = glm::dot(g.ng, g.wo) > 0.0;
  o.ng = o.front ? g.ng : -g.ng;
  o.ns = glm::dot(g.ns, o.ng) >= 0.0 ? g.ns : -g.ns;
  o.shading_is_geometric = glm::length(g.ns - g.ng) < 1e-12;
  return o;
}

namespace {

// Two-sided normal quantile of alpha
double normal_quantile(double alpha) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) (std::erfc((lo + hi) / 2.0 / std::sqrt(2.0)) > alpha ? lo : hi) = (lo + hi) / 2.0;
  return lo;
}

}  // namespace

// The harness's chi-square tests: one per device x material x geometry it runs at
double bsdf_alpha() {
  static const double alpha =
      sidak_alpha(0.01, int(all_materials().size() * (geometries().size() + kRusticlGeometries.size())));
  return alpha;
}

double bsdf_z() {
  static const double z = normal_quantile(bsdf_alpha());
  return z;
}

namespace {

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

}  // namespace

// ---- The kernels at a shading point ----

BsdfRun::BsdfRun(const KernelRig& r, const dev::Material& m, const Geometry& g)
    : rig(r), material(m), geo(g), materials(r.input(std::vector<dev::Material>{m})) {}

BsdfRun::BsdfRun(const KernelRig& r, const dev::Material& m, const Geometry& g, const cl::Buffer& table)
    : BsdfRun(r, m, g) {
  ggx_albedo = table;
}

namespace {

// The shading point's arguments of the test_bsdf kernels: material table, the GGX albedo
// table where bound (the _ggx kernels), ng, ns, tangent
struct ShadingPoint {
  const BsdfRun& run;
  cl_uint bind(cl::Kernel& k, cl_uint first) const {
    first = bind_args(k, first, run.materials);
    if (run.ggx_albedo()) first = bind_args(k, first, run.ggx_albedo);
    return bind_args(k, first, f4(run.geo.ng), f4(run.geo.ns), f4(run.geo.tangent));
  }
  // `kernel`, or its variant with the GGX albedo table
  const char* name(const char* kernel, const char* with_table) const { return run.ggx_albedo() ? with_table : kernel; }
};

}  // namespace

Samples BsdfRun::sample(cl_uint seed, size_t n) const {
  auto out = rig.output<cl_float4>(3 * n);
  auto info = rig.output<cl_uint4>(n);
  ShadingPoint at{*this};
  rig.run(at.name("test_bsdf_sample", "test_bsdf_sample_ggx"), n, at, f4(geo.wo), seed, out, info);
  return {out.read(), info.read()};
}

std::vector<cl_float4> BsdfRun::eval(const std::vector<std::pair<glm::dvec3, glm::dvec3>>& pairs) const {
  std::vector<cl_float4> in;
  in.reserve(2 * pairs.size());
  for (const auto& [wo, wi] : pairs) {
    in.push_back(f4(wo));
    in.push_back(f4(wi));
  }
  auto out = rig.output<cl_float4>(pairs.size());
  ShadingPoint at{*this};
  rig.run(at.name("test_bsdf_eval", "test_bsdf_eval_ggx"), pairs.size(), at, rig.input(in), out);
  return out.read();
}

std::vector<double> BsdfRun::pdf(const std::vector<glm::dvec3>& wis) const {
  std::vector<std::pair<glm::dvec3, glm::dvec3>> pairs;
  pairs.reserve(wis.size());
  for (const auto& wi : wis) pairs.emplace_back(geo.wo, wi);
  std::vector<double> p;
  p.reserve(wis.size());
  for (const auto& r : eval(pairs)) p.push_back(r.s[3]);
  return p;
}

SphereCells::SphereCells(glm::dvec3 ng_, glm::dvec3 ns_, Frame reflection, Frame transmission, CellSpec c)
    : ng(ng_), ns(ns_), frames{reflection, transmission}, spec(c) {
  for (int i = 0; i <= spec.rings; ++i) ring_theta.push_back(theta(double(i) / spec.rings));
}

double SphereCells::theta(double t) const {
  if (spec.warp == 0.0) return std::acos(std::clamp(1.0 - 2.0 * t, -1.0, 1.0));
  return kPi * (t - spec.warp * std::sin(2.0 * kPi * t) / (2.0 * kPi));
}

size_t SphereCells::index(glm::dvec3 w) const {
  int k = side(w);
  glm::dvec3 l = frames[k].local(w);
  double phi = std::atan2(l.y, l.x), th = std::acos(std::clamp(l.z / glm::length(l), -1.0, 1.0));
  if (phi < 0.0) phi += 2.0 * kPi;
  int i = int(std::upper_bound(ring_theta.begin(), ring_theta.end(), th) - ring_theta.begin()) - 1;
  i = std::clamp(i, 0, spec.rings - 1);
  int j = std::clamp(int(phi / (2.0 * kPi) * spec.sectors), 0, spec.sectors - 1);
  return k * per_side() + size_t(i) * spec.sectors + j;
}

std::vector<double> SphereCells::integrals(const PdfFunction& pdf) const {
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
        add(k * per_side() + size_t(a / sub_t) * spec.sectors + b / sub_phi, t0, t1, phi0, phi1, crossed ? kRefine : 1);
      }
    }
  }
  std::vector<double> p = pdf(dirs), cells(size(), 0.0);
  for (size_t i = 0; i < nodes.size(); ++i) cells[nodes[i].cell] += p[i] * nodes[i].weight;
  return cells;
}

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

std::vector<glm::dvec3> energy_weights(const Samples& s, glm::dvec3 ns) {
  std::vector<glm::dvec3> w(s.size(), glm::dvec3(0.0));
  for (size_t i = 0; i < s.size(); ++i)
    if (s.returned(i)) w[i] = s.f(i) * std::fabs(glm::dot(s.wi(i), ns)) / s.pdf(i) * s.eta(i) * s.eta(i);
  return w;
}

namespace {

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

}  // namespace

bool near_rel(double a, double b, double rel) { return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)); }

bool near_vec(glm::dvec3 a, glm::dvec3 b, double rel) {
  double scale =
      std::max({std::fabs(a.x), std::fabs(a.y), std::fabs(a.z), std::fabs(b.x), std::fabs(b.y), std::fabs(b.z)});
  return glm::all(glm::lessThanEqual(glm::abs(a - b), glm::dvec3(rel * scale)));
}

namespace {

bool has_transmission(const dev::Material& m) {
  return m.type == MATERIAL_GLTF && m.params.gltf.transmission > 0.0f && m.params.gltf.metallic < 1.0f;
}

// Tolerance of the kernels' f and pdf at (wo, wi) against each other or a reference
double tolerance(const MaterialCase& mat, const Geometry& g, const Oriented& o, glm::dvec3 wo, glm::dvec3 wi) {
  double tol = float_tolerance(std::min(std::fabs(glm::dot(wo, o.ns)), std::fabs(glm::dot(wi, o.ns))));
  const dev::Material& m = mat.material;
  if (!has_transmission(m)) return tol;
  Frame f = shading_frame(g, o, m);
  double eta = o.front ? ior(m) : 1.0 / ior(m);
  return tol + dielectric_tolerance(eta, m.flags & MATERIAL_THIN_WALLED, f.local(wo), f.local(wi));
}

}  // namespace

// ---- The checks ----

const std::string* KnownBugs::find(const MaterialCase& mat, const std::string& check, const Geometry& g) {
  auto it = mat.bugs.find(check + "/" + g.name);
  if (it == mat.bugs.end()) return nullptr;
  rows[it->second] += " " + mat.name + " " + it->first;
  return &it->second;
}

std::string KnownBugs::note() const {
  std::string note;
  for (const auto& [bug, where] : rows) note += "skipped" + where + ": " + bug + "\n";
  return note;
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
  EXPECT_NEAR(fraction, integral, bsdf_z() * sigma + kIntegrationTolerance)
      << "returned non-delta samples vs pdf integral";
  if (n > 0) {
    EXPECT_GT(chi2.p_value, bsdf_alpha()) << "chi2 " << chi2.statistic << " dof " << chi2.dof;
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
      EXPECT_NEAR(counts[k] / n, p, bsdf_z() * std::sqrt(p * (1.0 - p) / n) + 1e-6) << lobes[k].name << " frequency";
    }
    SampleMean e = estimate(contributions[k]);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(e.mean[c], lobes[k].contribution[c], bsdf_z() * e.se[c] + 1e-4 * lobes[k].contribution[c] + 1e-7)
          << lobes[k].name << " contribution, channel " << c;
  }
}

glm::dvec3 sphere_direction(double z, double phi) {
  double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

void check_sphere_sampling(const std::vector<cl_float4>& records, glm::dvec3 wo, const PairEval& eval, int sub,
                           double alpha) {
  const int nz = 32, nphi = 64;
  const size_t n = records.size() / 3;
  std::vector<double> observed(nz * nphi + 1, 0.0);
  size_t mismatched = 0;
  for (size_t i = 0; i < n; ++i) {
    const cl_float4 &a = records[3 * i], &f = records[3 * i + 1], &e = records[3 * i + 2];
    if (a.s[3] == 0.0f) {
      observed[nz * nphi] += 1.0;
      continue;
    }
    ASSERT_EQ(f.s[3], 0.0f) << "no delta lobe here";
    for (int ch = 0; ch < 3; ++ch)
      if (std::fabs(f.s[ch] - e.s[ch]) > 1e-3 * std::fabs(e.s[ch]) + 1e-6) ++mismatched;
    if (std::fabs(a.s[3] - e.s[3]) > 1e-3 * e.s[3]) ++mismatched;
    int iz = std::clamp(int((a.s[2] + 1.0) * 0.5 * nz), 0, nz - 1);
    double phi = std::atan2(a.s[1], a.s[0]);
    if (phi < 0.0) phi += 2.0 * kPi;
    int ip = std::clamp(int(phi / (2.0 * kPi) * nphi), 0, nphi - 1);
    observed[iz * nphi + ip] += 1.0;
  }
  EXPECT_EQ(mismatched, 0u);
  std::vector<cl_float4> pairs;
  for (int iz = 0; iz < nz; ++iz)
    for (int ip = 0; ip < nphi; ++ip)
      for (int a = 0; a < sub; ++a)
        for (int b = 0; b < sub; ++b) {
          pairs.push_back(f4(wo));
          pairs.push_back(f4(
              sphere_direction(-1.0 + 2.0 * (iz + (a + 0.5) / sub) / nz, 2.0 * kPi * (ip + (b + 0.5) / sub) / nphi)));
        }
  std::vector<cl_float4> ev = eval(pairs);
  std::vector<double> expected(nz * nphi + 1, 0.0);
  double d_omega = 4.0 * kPi / (double(nz) * nphi * sub * sub), total = 0.0;
  for (size_t i = 0; i < ev.size(); ++i) expected[i / (sub * sub)] += ev[i].s[3] * d_omega;
  for (int i = 0; i < nz * nphi; ++i) total += expected[i];
  EXPECT_LE(total, 1.0 + 2e-3);
  EXPECT_NEAR(total, 1.0 - observed[nz * nphi] / n, 5e-3);
  expected[nz * nphi] = std::max(0.0, 1.0 - total);
  double sum = 0.0;
  for (double& x : expected) sum += x;
  for (double& x : expected) x *= n / sum;
  ChiSquare cs = chi_square_test(observed, expected);
  EXPECT_GT(cs.p_value, alpha) << "chi-square " << cs.statistic << " on " << cs.dof << " dof";
}

std::string BsdfTestName::operator()(const ::testing::TestParamInfo<BsdfTest::ParamType>& info) const {
  return std::get<0>(info.param) + "_" + std::get<1>(info.param).name;
}

Samples BsdfDelta::sample(const dev::Material& m, const Geometry& g) {
  return BsdfRun(rig(), m, g).sample(seed_on(GetParam(), 99), 1 << 16);
}

}  // namespace candela::test
