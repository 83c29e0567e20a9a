// BSDF tests through the kernels' own dispatch (bsdf_at, bsdf_sample, bsdf_eval, bsdf_pdf;
// tests/cl/test_bsdf.cl) for every device x material x shading geometry: sampled
// directions follow bsdf_pdf (chi-square, 1M samples, cells with expected count < 5
// pooled, alpha = 0.01 with the Sidak correction over this file's chi-square tests), the
// pdf integrates to at most 1, sample weights agree with eval and pdf, no energy is
// created, eval is reciprocal and matches a host-side reference lobe. A new lobe is a new
// entry of kMaterials; a new shading situation a new entry of kGeometries.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <glm/glm.hpp>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <tuple>

#include "stats.hpp"
#include "test_support.hpp"

namespace candela::test {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr size_t kSamples = 1 << 20;

// The pdf is integrated over histogram cells by the midpoint rule on this grid over the
// sphere in (cos theta, phi); its error over the sphere comes from the pdf's jump at the
// geometric horizon (about 3e-5 with ns 20 degrees off ng)
constexpr int kIntegrationCos = 640, kIntegrationPhi = 1280;
constexpr double kIntegrationTolerance = 2e-4;

// The lobe's f and pdf written independently of the kernels, in the local shading frame
// (z = ns on wo's side, x along the tangent); `reflection`: wi is on wo's geometric side
struct Reference {
  glm::dvec3 f;
  double pdf;
};
using ReferenceLobe = std::function<Reference(glm::dvec3 wo, glm::dvec3 wi, bool reflection)>;

struct MaterialCase {
  std::string name;
  dev::Material material;
  bool pdf_normalized;  // the pdf integrates to 1 when ns == ng (no delta, nothing lost)
  std::optional<glm::dvec3> albedo;  // the exact albedo when ns == ng, where known
  ReferenceLobe reference;  // where one exists (not for delta lobes)
  // Chi-square cells over the sphere in (cos theta, phi): fewer cells test smooth lobes
  // harder, narrow lobes need more (divisors of kIntegrationCos, kIntegrationPhi)
  int cos_cells = 20, phi_cells = 40;
};

void PrintTo(const MaterialCase& m, std::ostream* os) { *os << m.name; }

dev::Material make_material(unsigned type, glm::dvec3 base_color) {
  dev::Material m{};
  m.type = type;
  for (int c = 0; c < 3; ++c) m.base_color[c] = float(base_color[c]);
  m.base_color[3] = 1.0f;
  m.ior = 1.5f;
  for (dev::TextureRef& t : m.textures) {
    t.index = NO_TEXTURE;
    t.m[0] = t.m[4] = 1.0f;
  }
  return m;
}

// Lambert: f = albedo / pi, pdf = cos theta / pi
MaterialCase diffuse(glm::dvec3 albedo) {
  auto lambert = [albedo](glm::dvec3, glm::dvec3 wi, bool reflection) {
    return reflection && wi.z > 0.0 ? Reference{albedo / kPi, wi.z / kPi} : Reference{glm::dvec3(0.0), 0.0};
  };
  return {"diffuse", make_material(MATERIAL_DIFFUSE, albedo), true, albedo, lambert};
}

const std::vector<MaterialCase> kMaterials = {diffuse({0.8, 0.5, 0.2})};

// A shading point as a mesh gives it: normals unoriented, tangent not orthogonal to ns
struct Geometry {
  std::string name;
  glm::dvec3 ng, ns, tangent, wo;
};

void PrintTo(const Geometry& g, std::ostream* os) { *os << g.name; }

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

// The kernels' shading frame: t from the tangent by Gram-Schmidt against n (frame_from_z_x,
// whose fallback for a tangent along n this does not copy: geometries give real tangents)
Frame tangent_frame(glm::dvec3 n, glm::dvec3 tangent) {
  glm::dvec3 t = glm::normalize(tangent - glm::dot(tangent, n) * n);
  return {t, glm::cross(n, t), n};
}

// Unit direction at polar angle theta from n, azimuth phi (degrees) in frame_around(n)
glm::dvec3 around(glm::dvec3 n, double theta_deg, double phi_deg) {
  double th = theta_deg * kPi / 180.0, ph = phi_deg * kPi / 180.0;
  return frame_around(glm::normalize(n)).world({std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)});
}

const glm::dvec3 kTilted = glm::normalize(glm::dvec3(1.0, 2.0, 3.0));
const std::vector<Geometry> kGeometries = {
    {"normal", {0, 0, 1}, {0, 0, 1}, {1, 0, 0}, {0, 0, 1}},
    {"grazing", kTilted, kTilted, {1, 0, 0.5}, around(kTilted, 85.0, 30.0)},
    {"backfacing", {0, 0, 1}, {0, 0, 1}, {1, 0.2, 0.3}, around({0, 0, -1}, 40.0, 200.0)},
    {"bumped", {0, 0, 1}, around({0, 0, 1}, 20.0, 0.0), {0, 1, 0}, around({0, 0, 1}, 40.0, 150.0)},
};

// The file's chi-square tests, one per device x material x geometry
const double kAlpha = sidak_alpha(0.01, int(2 * kMaterials.size() * kGeometries.size()));

// Normals turned as surface_at turns them (ng to wo's side, ns to ng's) and the
// histogram frame around ns
struct Oriented {
  glm::dvec3 ng, ns;
  Frame frame;
  bool shading_is_geometric;
};
Oriented orient(const Geometry& g) {
  Oriented o;
  o.ng = glm::dot(g.ng, g.wo) > 0.0 ? g.ng : -g.ng;
  o.ns = glm::dot(g.ns, o.ng) >= 0.0 ? g.ns : -g.ns;
  o.frame = frame_around(o.ns);
  o.shading_is_geometric = glm::length(g.ns - g.ng) < 1e-12;
  return o;
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

// A material on a shading point of one device, and what its kernels return
struct BsdfRun {
  KernelRig& rig;
  const MaterialCase& mat;
  const Geometry& geo;
  cl::Buffer materials;

  BsdfRun(KernelRig& r, const MaterialCase& m, const Geometry& g)
      : rig(r), mat(m), geo(g),
        materials(r.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof(dev::Material),
                  const_cast<dev::Material*>(&m.material)) {}

  void set_shading_point(cl::Kernel& k) const {
    k.setArg(0, materials);
    k.setArg(1, f4(geo.ng));
    k.setArg(2, f4(geo.ns));
    k.setArg(3, f4(geo.tangent));
  }

  // kSamples calls of bsdf_sample from wo
  struct Samples {
    std::vector<cl_float4> out;  // per sample: (wi, pdf), (f, eta), (eval f, eval pdf)
    std::vector<cl_uint4> info;  // (returned, delta, reflection, flags valid)
  };
  Samples sample(cl_uint seed) const {
    cl::Buffer out(rig.context, CL_MEM_WRITE_ONLY, 3 * kSamples * sizeof(cl_float4));
    cl::Buffer info(rig.context, CL_MEM_WRITE_ONLY, kSamples * sizeof(cl_uint4));
    cl::Kernel k(rig.program, "test_bsdf_sample");
    set_shading_point(k);
    k.setArg(4, f4(geo.wo));
    k.setArg(5, seed);
    k.setArg(6, out);
    k.setArg(7, info);
    rig.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(kSamples));
    Samples s{std::vector<cl_float4>(3 * kSamples), std::vector<cl_uint4>(kSamples)};
    rig.queue.enqueueReadBuffer(out, CL_TRUE, 0, s.out.size() * sizeof(cl_float4), s.out.data());
    rig.queue.enqueueReadBuffer(info, CL_TRUE, 0, s.info.size() * sizeof(cl_uint4), s.info.data());
    return s;
  }

  // (f, pdf) for each pair (wo, wi)
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

// Histogram cells over the whole sphere, n_cos x n_phi in (cos theta, phi) around frame.n
struct SphereCells {
  Frame frame;
  int n_cos, n_phi;

  size_t size() const { return size_t(n_cos) * n_phi; }

  size_t index(glm::dvec3 w) const {
    glm::dvec3 l = frame.local(w);
    double phi = std::atan2(l.y, l.x);
    if (phi < 0.0) phi += 2.0 * kPi;
    int i = std::clamp(int((std::clamp(l.z, -1.0, 1.0) + 1.0) * 0.5 * n_cos), 0, n_cos - 1);
    int j = std::clamp(int(phi / (2.0 * kPi) * n_phi), 0, n_phi - 1);
    return size_t(i) * n_phi + j;
  }

  // Integral of the pdf over each cell: midpoint rule in (cos theta, phi), dw = dcos dphi
  std::vector<double> integrals(const PdfFunction& pdf) const {
    const int n = kIntegrationCos, m = kIntegrationPhi, sub_cos = n / n_cos, sub_phi = m / n_phi;
    EXPECT_TRUE(n % n_cos == 0 && m % n_phi == 0) << "cells must divide the integration grid";
    const double dz = 2.0 / n, dphi = 2.0 * kPi / m;
    std::vector<glm::dvec3> dirs;
    dirs.reserve(size_t(n) * m);
    for (int a = 0; a < n; ++a) {
      double z = -1.0 + (a + 0.5) * dz, r = std::sqrt(std::max(0.0, 1.0 - z * z));
      for (int b = 0; b < m; ++b) {
        double phi = (b + 0.5) * dphi;
        dirs.push_back(frame.world({r * std::cos(phi), r * std::sin(phi), z}));
      }
    }
    std::vector<double> p = pdf(dirs), cells(size(), 0.0);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < m; ++b)
        cells[size_t(a / sub_cos) * n_phi + b / sub_phi] += p[size_t(a) * m + b] * dz * dphi;
    return cells;
  }
};

SphereCells cells_for(const MaterialCase& mat, const Oriented& o) { return {o.frame, mat.cos_cells, mat.phi_cells}; }

bool is_returned(const cl_uint4& info) { return info.s[0] != 0u; }
bool is_delta(const cl_uint4& info) { return info.s[1] != 0u; }

// Non-delta samples, histogrammed, against the pdf's cell integrals scaled to their count;
// *returned gets that count
ChiSquare direction_chi_square(const BsdfRun::Samples& s, const SphereCells& grid,
                               const std::vector<double>& cells, size_t* returned) {
  std::vector<double> observed(cells.size(), 0.0), expected(cells.size());
  size_t n = 0;
  for (size_t i = 0; i < kSamples; ++i) {
    if (!is_returned(s.info[i]) || is_delta(s.info[i])) continue;
    observed[grid.index(d3(s.out[3 * i]))] += 1.0;
    ++n;
  }
  double total = 0.0;
  for (double c : cells) total += c;
  for (size_t c = 0; c < cells.size(); ++c) expected[c] = total > 0.0 ? n * cells[c] / total : 0.0;
  *returned = n;
  return chi_square_test(observed, expected);
}

// Relative tolerance between float computations of a lobe: rounding through the local
// frame grows as 1 / cos theta toward the horizon
double float_tolerance(double cos_theta) { return 1e-4 + 1e-6 / std::fabs(cos_theta); }

bool near_rel(double a, double b, double rel) { return std::fabs(a - b) <= rel * std::max(std::fabs(a), std::fabs(b)); }

// Colours equal channel by channel, relative to their largest channel
bool near_vec(glm::dvec3 a, glm::dvec3 b, double rel) {
  double scale = std::max({std::fabs(a.x), std::fabs(a.y), std::fabs(a.z), std::fabs(b.x), std::fabs(b.y), std::fabs(b.z)});
  return glm::all(glm::lessThanEqual(glm::abs(a - b), glm::dvec3(rel * scale)));
}

using Param = std::tuple<std::string, MaterialCase, Geometry>;

class BsdfTest : public ::testing::TestWithParam<Param> {
 protected:
  static void TearDownTestSuite() { rigs().clear(); }

  // Skips when the device is absent; else the material at the geometry on that device
  std::unique_ptr<BsdfRun> run() {
    const std::string& name = std::get<0>(GetParam());
    auto d = device_by_name(name);
    if (!d) return nullptr;
    return std::make_unique<BsdfRun>(rig_for(name, *d), std::get<1>(GetParam()), std::get<2>(GetParam()));
  }
};

#define BSDF_RUN_OR_SKIP(r)                                                                    \
  auto r = run();                                                                              \
  if (!r) GTEST_SKIP() << std::get<0>(GetParam()) << " OpenCL device is not available"

}  // namespace

// Sampled directions are distributed as bsdf_pdf, and samples are returned (non-delta)
// as often as the pdf's integral over the sphere says
TEST_P(BsdfTest, SampledDirectionsFollowPdf) {
  BSDF_RUN_OR_SKIP(r);
  Oriented o = orient(r->geo);
  BsdfRun::Samples s = r->sample(4321);
  SphereCells grid = cells_for(r->mat, o);
  std::vector<double> cells = grid.integrals([&](const auto& w) { return r->pdf(w); });
  double integral = 0.0;
  for (double c : cells) integral += c;
  size_t n = 0;
  ChiSquare chi2 = direction_chi_square(s, grid, cells, &n);
  double fraction = double(n) / kSamples;
  double sigma = std::sqrt(std::max(integral * (1.0 - integral), 0.0) / kSamples);
  EXPECT_NEAR(fraction, integral, 4.0 * sigma + kIntegrationTolerance) << "returned non-delta samples vs pdf integral";
  if (n > 0) {
    EXPECT_GT(chi2.p_value, kAlpha) << "chi2 " << chi2.statistic << " dof " << chi2.dof;
  }
}

// Integral of bsdf_pdf over the sphere: at most 1, exactly 1 for a normalized lobe at ns == ng
TEST_P(BsdfTest, PdfIntegratesToAtMostOne) {
  BSDF_RUN_OR_SKIP(r);
  Oriented o = orient(r->geo);
  double integral = 0.0;
  for (double c : cells_for(r->mat, o).integrals([&](const auto& w) { return r->pdf(w); })) integral += c;
  EXPECT_LE(integral, 1.0 + kIntegrationTolerance);
  if (r->mat.pdf_normalized && o.shading_is_geometric) {
    EXPECT_NEAR(integral, 1.0, 1e-3);
  }
}

// Each returned sample is a valid direction whose f, pdf and weight f |cos| / pdf are what
// bsdf_eval and bsdf_pdf give at it (delta samples: only the validity checks)
TEST_P(BsdfTest, SamplesAgreeWithEvalAndPdf) {
  BSDF_RUN_OR_SKIP(r);
  Oriented o = orient(r->geo);
  BsdfRun::Samples s = r->sample(977);
  size_t bad = 0;
  auto fail = [&](size_t i, const std::string& what) {
    if (++bad <= 5)
      ADD_FAILURE() << "sample " << i << ": " << what << "; wi " << s.out[3 * i].s[0] << " " << s.out[3 * i].s[1]
                    << " " << s.out[3 * i].s[2] << " pdf " << s.out[3 * i].s[3] << " eval pdf " << s.out[3 * i + 2].s[3];
  };
  for (size_t i = 0; i < kSamples; ++i) {
    const cl_uint4& info = s.info[i];
    if (!is_returned(info)) continue;
    if (!info.s[3]) fail(i, "flags outside bsdf_flags or not one of reflection, transmission");
    glm::dvec3 wi = d3(s.out[3 * i]), f = d3(s.out[3 * i + 1]), fe = d3(s.out[3 * i + 2]);
    double pdf = s.out[3 * i].s[3], pdf_e = s.out[3 * i + 2].s[3], eta = s.out[3 * i + 1].s[3];
    bool reflect = info.s[2] != 0u;
    if (std::fabs(glm::length(wi) - 1.0) > 1e-5) fail(i, "wi not unit");
    if (!(pdf > 0.0) || !std::isfinite(pdf)) fail(i, "pdf not positive and finite");
    if (!(std::isfinite(f.x) && std::isfinite(f.y) && std::isfinite(f.z)) || glm::min(f.x, glm::min(f.y, f.z)) < 0.0)
      fail(i, "f negative or not finite");
    if (reflect != (glm::dot(wi, o.ng) > 0.0)) fail(i, "reflection flag disagrees with the geometric side");
    if (reflect && eta != 1.0) fail(i, "eta != 1 on reflection");
    if (is_delta(info)) continue;
    double cos_i = std::fabs(glm::dot(wi, o.ns)), tol = float_tolerance(cos_i);
    if (!near_rel(pdf, pdf_e, tol)) fail(i, "pdf != bsdf_pdf");
    if (!near_vec(f, fe, tol)) fail(i, "f != bsdf_eval");
    if (!(pdf_e > 0.0) || !near_vec(f * cos_i / pdf, fe * cos_i / pdf_e, tol))
      fail(i, "weight != bsdf_eval |cos| / bsdf_pdf");
  }
  EXPECT_EQ(bad, 0u) << "inconsistent samples";
}

// Mean sample weight (0 for a failed sample) is at most 1; the known albedo where there is one
TEST_P(BsdfTest, AlbedoAtMostOne) {
  BSDF_RUN_OR_SKIP(r);
  Oriented o = orient(r->geo);
  BsdfRun::Samples s = r->sample(2024);
  glm::dvec3 sum(0.0), sum2(0.0);
  for (size_t i = 0; i < kSamples; ++i) {
    if (!is_returned(s.info[i])) continue;
    glm::dvec3 w = d3(s.out[3 * i + 1]) * std::fabs(glm::dot(d3(s.out[3 * i]), o.ns)) / double(s.out[3 * i].s[3]);
    sum += w;
    sum2 += w * w;
  }
  glm::dvec3 mean = sum / double(kSamples);
  glm::dvec3 se = glm::sqrt(glm::max(sum2 / double(kSamples) - mean * mean, 0.0) / double(kSamples));
  for (int c = 0; c < 3; ++c) {
    EXPECT_LE(mean[c], 1.0 + 4.0 * se[c] + 1e-6) << "channel " << c << " SE " << se[c];
    if (r->mat.albedo && o.shading_is_geometric) {
      EXPECT_NEAR(mean[c], (*r->mat.albedo)[c], 4.0 * se[c] + 1e-5) << "channel " << c << " SE " << se[c];
    }
  }
}

// f(wo, wi) = f(wi, wo) for pairs above both normals
TEST_P(BsdfTest, EvalIsReciprocal) {
  BSDF_RUN_OR_SKIP(r);
  Oriented o = orient(r->geo);
  std::mt19937_64 gen(7);
  std::normal_distribution<double> normal;
  auto above = [&] {
    for (;;) {
      glm::dvec3 w = glm::normalize(glm::dvec3(normal(gen), normal(gen), normal(gen)));
      if (glm::dot(w, o.ng) > 0.01 && glm::dot(w, o.ns) > 0.01) return w;
    }
  };
  const size_t n = 4096;
  std::vector<std::pair<glm::dvec3, glm::dvec3>> pairs(2 * n);
  for (size_t i = 0; i < n; ++i) {
    pairs[i] = {above(), above()};
    pairs[n + i] = {pairs[i].second, pairs[i].first};
  }
  std::vector<cl_float4> v = r->eval(pairs);
  size_t bad = 0;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c)
      if (!near_rel(v[i].s[c], v[n + i].s[c], 1e-5) && ++bad <= 5)
        ADD_FAILURE() << "pair " << i << " channel " << c << ": " << v[i].s[c] << " vs " << v[n + i].s[c];
  EXPECT_EQ(bad, 0u);
}

// f and pdf equal the reference lobe's over the sphere, away from the horizons
TEST_P(BsdfTest, EvalAndPdfMatchReference) {
  BSDF_RUN_OR_SKIP(r);
  if (!r->mat.reference) GTEST_SKIP() << "no reference lobe for " << r->mat.name;
  Oriented o = orient(r->geo);
  Frame shading = tangent_frame(o.ns, r->geo.tangent);
  std::mt19937_64 gen(11);
  std::normal_distribution<double> normal;
  std::vector<std::pair<glm::dvec3, glm::dvec3>> pairs;
  while (pairs.size() < 4096) {
    glm::dvec3 wi = glm::normalize(glm::dvec3(normal(gen), normal(gen), normal(gen)));
    if (std::fabs(glm::dot(wi, o.ng)) > 1e-3 && std::fabs(glm::dot(wi, o.ns)) > 1e-3) pairs.emplace_back(r->geo.wo, wi);
  }
  std::vector<cl_float4> v = r->eval(pairs);
  size_t bad = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    glm::dvec3 wi = pairs[i].second;
    Reference ref = r->mat.reference(shading.local(r->geo.wo), shading.local(wi), glm::dot(wi, o.ng) > 0.0);
    double tol = float_tolerance(glm::dot(wi, o.ns));
    if ((!near_rel(v[i].s[3], ref.pdf, tol) || !near_vec(d3(v[i]), ref.f, tol)) && ++bad <= 5)
      ADD_FAILURE() << "wi " << wi.x << " " << wi.y << " " << wi.z << ": f " << v[i].s[0] << " " << v[i].s[1] << " "
                    << v[i].s[2] << " pdf " << v[i].s[3] << ", reference f " << ref.f.x << " " << ref.f.y << " "
                    << ref.f.z << " pdf " << ref.pdf;
  }
  EXPECT_EQ(bad, 0u);
}

INSTANTIATE_TEST_SUITE_P(Lobes, BsdfTest,
                         ::testing::Combine(::testing::Values("pocl", "rusticl"), ::testing::ValuesIn(kMaterials),
                                            ::testing::ValuesIn(kGeometries)),
                         [](const ::testing::TestParamInfo<Param>& info) {
                           return std::get<0>(info.param) + "_" + std::get<1>(info.param).name + "_" +
                                  std::get<2>(info.param).name;
                         });

// The harness must be able to fail: cosine-weighted samples against a uniform pdf
TEST(BsdfHarness, ChiSquareRejectsAWrongPdf) {
  KernelRig rig(pocl_device());
  BsdfRun r(rig, kMaterials[0], kGeometries[0]);
  Oriented o = orient(r.geo);
  BsdfRun::Samples s = r.sample(4321);
  auto uniform_hemisphere = [&](const std::vector<glm::dvec3>& w) {
    std::vector<double> p;
    for (const auto& d : w) p.push_back(glm::dot(d, o.ns) > 0.0 ? 0.5 / kPi : 0.0);
    return p;
  };
  size_t n = 0;
  SphereCells grid = cells_for(r.mat, o);
  ChiSquare chi2 = direction_chi_square(s, grid, grid.integrals(uniform_hemisphere), &n);
  EXPECT_GT(n, 0u);
  EXPECT_LT(chi2.p_value, 1e-6);
}

}  // namespace candela::test
