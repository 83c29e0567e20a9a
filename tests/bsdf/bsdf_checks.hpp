// The BSDF harness (tests/bsdf/*_test.cpp): material records and shading geometries, the
// kernels' dispatch run at a made-up shading point (tests/bsdf/test_bsdf.cl), and the checks
// every material goes through. Each family of lobes has its test file
// (diffuse_test.cpp, conductor_test.cpp, dielectric_test.cpp, metallic_roughness_test.cpp)
// with its materials, reference lobes and delta-lobe tests, listed in lobe_families(); a new
// lobe is a new entry of its family, a new family a new file and an entry there, a new
// shading situation an entry of geometries().
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <functional>
#include <glm/glm.hpp>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "support/reference.hpp"
#include "support/stats.hpp"
#include "support/test_support.hpp"

namespace candela::test {

// Samples per chi-square test: 1M on PoCL; rusticl (llvmpipe) runs the same checks at a
// quarter of that, as it is about 5x slower per work-item
constexpr size_t kSamples = 1 << 20;
size_t samples_on(const std::string& device);
// n samples on PoCL, a quarter of them on rusticl
size_t samples_on(const std::string& device, size_t n);
// Each device its own random numbers, for independent evidence
cl_uint seed_on(const std::string& device, cl_uint seed);

// ---- Host reference lobes (double), in the local shading frame (z = ns on wo's side) -------

struct Reference {
  glm::dvec3 f;
  double pdf;
};
extern const Reference kNothing;

// (wo, wi) in the local frame; `reflection`: wi on wo's geometric side; `front`: wo on the
// front face (outside a refracting solid)
using ReferenceLobe = std::function<Reference(glm::dvec3 wo, glm::dvec3 wi, bool reflection, bool front)>;

// Reflectance of a dielectric interface, or of a thin sheet of it with its inter-reflections
// R' = R + T^2 R / (1 - R^2) = 2R / (1 + R)
double dielectric_reflectance(double cos_i, double eta, bool thin);

// Rough dielectric transmission from wo (z > 0) to wi (z < 0), eta = eta_wi / eta_wo, for
// radiance: Walter et al. 2007 eq. 21 and 17 with the generalized half vector
// h ~ -(eta_wo wo + eta_wi wi); a thin sheet passes the reflection lobe mirrored through it
Reference dielectric_transmission(const GgxReference& g, double eta, bool thin, glm::dvec3 wo, glm::dvec3 wi);

// The energy-preserving Oren-Nayar lobe (EON) of albedo rho and roughness r in (0, 1] for wo
// and wi above the surface, and its directional albedo (exact: E_FON integrated in closed form)
glm::dvec3 eon_reference(glm::dvec3 rho, double r, glm::dvec3 wo, glm::dvec3 wi);
glm::dvec3 eon_albedo(glm::dvec3 rho, double r, double cos_o);

// glTF metallic-roughness (glTF 2.0 Appendix B with KHR_materials_specular, _ior,
// _transmission, _clearcoat, _anisotropy, _diffuse_roughness) as a weighted sum of lobes:
// coat over metal + plastic (specular + Lambert or EON) + glass. Its pdf is the kernel's mixture, with
// component probabilities estimated at wo (cl/bsdf/bsdf_gltf.cl, gltf_at_wo).
struct GltfReference {
  glm::dvec3 base, f0;
  double metallic, transmission, ior, f90, coat, diffuse_roughness;
  bool thin;
  GgxReference ggx, coat_ggx;

  explicit GltfReference(const dev::Material& m);
  double coat_fresnel(double c) const;
  // Without the albedo table a layer's albedo is its Schlick term at mu; what lies below
  // gets (1 - A(mu_o)) (1 - A(mu_i)) of reflected light, 1 - A(mu outside) of transmitted
  double spec_albedo(double mu) const;
  double below_spec(double mu_o, double mu_i) const;
  double below_coat(double mu_o, double mu_i) const;
  // Component probabilities: coat, metal, specular, diffuse, glass
  std::array<double, 5> lobes(double cos_o) const;
  Reference operator()(glm::dvec3 wo, glm::dvec3 wi, bool reflection, bool front) const;
};

// ---- Material records -----------------------------------------------------------------------

// Histogram cells: which axis they are centred on (per geometry) and their resolution
enum class Focus { Normal, Mirror, Refraction, Straight };
struct CellSpec {
  // `rings` around an axis x `sectors` in phi (dividing the integration grid, 160 x 320).
  // warp 0: rings of equal solid angle, uniform in cos theta, for broad lobes. warp c in
  // (0, 1): polar angle theta(t) = pi (t - c sin(2 pi t) / (2 pi)), t uniform, so rings are
  // (1 - c) times a uniform angular step at both poles and (1 + c) times it at the equator:
  // a narrow lobe on the axis spans many rings (and the integration's sub-rings resolve its
  // peak), and so does one straight opposite (the reflection when the cells follow the
  // refraction at normal incidence)
  int rings = 20, sectors = 40;
  double warp = 0.0;
  Focus reflection = Focus::Normal, transmission = Focus::Normal;  // axes of the two sides
};
// Lobes a few degrees wide (alpha <= 0.1): rings of 0.2 degrees at the axis
constexpr CellSpec kNarrow{80, 32, 0.9, Focus::Mirror, Focus::Refraction};
constexpr CellSpec kGlossy{32, 32, 0.6, Focus::Mirror, Focus::Refraction};

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

void PrintTo(const MaterialCase& m, std::ostream* os);

// A material record of `type` and base colour, everything else at its default
dev::Material make_material(unsigned type, glm::dvec3 base_color);
// glTF metallic-roughness with the given factors; the rest default
dev::Material gltf(glm::dvec3 base, double metallic, double roughness, double transmission = 0.0, bool thin = false);
// The loader's gold preset
dev::Material gold(double roughness, double anisotropy = 0.0);
// A glTF material's index of refraction; 1.5 for the other types (make_material's default)
float ior(const dev::Material& m);

// Microfacet lobes lose the samples reflected below the horizon: their pdf integrates to less than 1
MaterialCase gltf_case(std::string name, dev::Material m, CellSpec cells);
// Delta lobes: eval and pdf are 0 everywhere; `albedo` where it is known
MaterialCase delta_case(std::string name, dev::Material m,
                        std::function<std::optional<glm::dvec3>(double)> albedo = {});

// A lobe family for the energy grid, by roughness; `back`: wo inside the solid
struct EnergyLobe {
  std::string name;
  std::function<dev::Material(double roughness)> material;
  bool back;
  std::string bug;  // a known kernel bug that creates energy: those rows are noted, not failed
};

// A family of lobes, one test file each: its material records for the harness's checks and
// its lobes for the energy grid
struct LobeFamily {
  std::vector<MaterialCase> materials;
  std::vector<EnergyLobe> energy_lobes;
};
LobeFamily diffuse_family();             // diffuse_test.cpp
LobeFamily conductor_family();           // conductor_test.cpp
LobeFamily dielectric_family();          // dielectric_test.cpp
LobeFamily metallic_roughness_family();  // metallic_roughness_test.cpp
std::vector<LobeFamily> lobe_families();
// Every family's
const std::vector<MaterialCase>& all_materials();
const std::vector<EnergyLobe>& all_energy_lobes();
const MaterialCase& material_case(const std::string& name);

// A program's GGX and sheen albedo tables (energy.hpp, sheen_albedo.hpp), cached beside it
struct AlbedoTables {
  cl::Buffer ggx, sheen;
  AlbedoTables(KernelRig& r, const cl::Program& program, const std::string& cache_file);
};

// ---- Shading geometry -----------------------------------------------------------------------

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
Frame frame_around(glm::dvec3 n);
// Unit direction at polar angle theta from n, azimuth phi (degrees) in frame_around(n)
glm::dvec3 around(glm::dvec3 n, double theta_deg, double phi_deg);

// The shading geometries every material is checked at (normal, grazing, back-facing, bumped,
// wo below the shading normal, grazing from inside)
const std::vector<Geometry>& geometries();
const Geometry& geometry(const std::string& name);
// rusticl runs the material tests at some of them only (it is about 5x slower a work-item)
bool runs_on(const std::string& device, const Geometry& g);
// A shading point with ng = ns = z, wo at theta from +z (front) or -z (back)
Geometry flat(double theta_deg, bool back);
Geometry seen_from(Geometry g, glm::dvec3 wo);

// Normals turned as surface_at turns them (ng to wo's side, ns to ng's)
struct Oriented {
  glm::dvec3 ng, ns;
  bool front;  // wo on the side ng points to (outside)
  bool shading_is_geometric;
};
Oriented orient(const Geometry& g);

// The significance of each of the harness's chi-square tests (one per device x material x
// geometry it runs at, Sidak-corrected to 0.01), and its two-sided normal quantile, for the
// binomial checks that go with each chi-square
double bsdf_alpha();
double bsdf_z();

// ---- The kernels at a shading point ---------------------------------------------------------

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
  const KernelRig& rig;
  const dev::Material material;
  const Geometry geo;
  cl::Buffer materials;
  cl::Buffer ggx_albedo;  // the GGX albedo table where bound (energy compensation on), else null

  BsdfRun(const KernelRig& r, const dev::Material& m, const Geometry& g);
  // The same with the GGX albedo table bound (the kernels test_bsdf_sample_ggx, test_bsdf_eval_ggx):
  // the lobes' energy compensation on (cl/bsdf/energy.cl, energy_dielectric.cl)
  BsdfRun(const KernelRig& r, const dev::Material& m, const Geometry& g, const cl::Buffer& table);
  // n calls of bsdf_sample from wo
  Samples sample(cl_uint seed, size_t n = kSamples) const;
  // (f, pdf) for each pair (wo, wi), the hit oriented by that wo
  std::vector<cl_float4> eval(const std::vector<std::pair<glm::dvec3, glm::dvec3>>& pairs) const;
  // bsdf_pdf(wo, wi) for each wi
  std::vector<double> pdf(const std::vector<glm::dvec3>& wis) const;
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

  SphereCells(glm::dvec3 ng_, glm::dvec3 ns_, Frame reflection, Frame transmission, CellSpec c);
  size_t per_side() const { return size_t(spec.rings) * spec.sectors; }
  size_t size() const { return 2 * per_side(); }
  int side(glm::dvec3 w) const { return glm::dot(w, ng) > 0.0 ? 0 : 1; }
  double theta(double t) const;  // polar angle at ring coordinate t in [0, 1]
  size_t index(glm::dvec3 w) const;
  // Integral of the pdf over each cell, dw = dcos dphi, on sub-cells of the integration
  // grid: two Gauss-Legendre nodes in cos theta, the midpoint in phi; the sub-cells a
  // horizon crosses are split kRefine x kRefine times more
  std::vector<double> integrals(const PdfFunction& pdf) const;

 private:
  static constexpr int kRefine = 4;
  std::vector<double> ring_theta;  // ring edges, increasing
};

SphereCells cells_for(const CellSpec& spec, const Geometry& g, const Oriented& o, const dev::Material& m);

// Non-delta samples, histogrammed, against the pdf's cell integrals scaled to their count;
// *returned gets that count
ChiSquare direction_chi_square(const Samples& s, const SphereCells& grid, const std::vector<double>& cells,
                               size_t* returned);

// Mean and standard error of per-sample values
struct SampleMean {
  glm::dvec3 mean, se;
};
SampleMean estimate(const std::vector<glm::dvec3>& v);

// The weight f |cos| / pdf of each sample times eta^2 (0 where none returned): eta =
// eta_wi / eta_wo undoes refraction's 1 / eta^2 radiance scaling (pbrt's etaScale), so that
// the mean is the fraction of energy scattered, at most 1
std::vector<glm::dvec3> energy_weights(const Samples& s, glm::dvec3 ns);

bool near_rel(double a, double b, double rel);
// Colours equal channel by channel, relative to their largest channel
bool near_vec(glm::dvec3 a, glm::dvec3 b, double rel);

// ---- The checks -------------------------------------------------------------------------------

// Known kernel bugs met by a test: bug -> the rows it kept out. A row is
// "<material> <check>/<geometry>", listed in MaterialCase::bugs.
struct KnownBugs {
  std::map<std::string, std::string> rows;
  const std::string* find(const MaterialCase& mat, const std::string& check, const Geometry& g);
  std::string note() const;
};

// Marks the test skipped when known kernel bugs kept rows out (the others ran)
#define BSDF_SKIP_KNOWN_BUGS(bugs) \
  if (!bugs.rows.empty()) GTEST_SKIP() << bugs.note()

// Sampling: sampled directions follow bsdf_pdf (chi-square), the pdf integrates to at most
// 1 (1 where it is normalized), non-delta samples are returned as often as it integrates
// to, every sample is valid and agrees with bsdf_eval and bsdf_pdf (delta samples:
// validity only); the eta^2-weighted albedo is at most 1 + 4 SE (the known albedo where
// there is one)
void check_sampling(const std::string& device, const BsdfRun& r, const MaterialCase& mat, KnownBugs& bugs);

// Reciprocity: f(wo, wi) = f(wi, wo) for pairs above both normals, and across refraction
// f(wo, wi) / eta_o^2 = f(wi, wo) / eta_i^2 (Veach 1997, sec. 5.2)
void check_reciprocity(const BsdfRun& run, const MaterialCase& mat, KnownBugs& bugs);

// f and pdf equal the reference lobe's over the sphere, away from the horizons
void check_reference(const BsdfRun& run, const MaterialCase& mat, KnownBugs& bugs);

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

// Every delta sample belongs to one of `lobes` with its flags, eta and weight; the lobes'
// frequencies and contributions match within bsdf_z() standard errors; `pure`: no
// non-delta sample either
void check_delta(const Samples& s, const std::vector<DeltaLobe>& lobes, bool pure);

// ---- Sampling over the sphere at the flat point (kernels of their own) -------------------------

// Unit direction of cosine z to +z at azimuth phi (radians) from +x
glm::dvec3 sphere_direction(double z, double phi);

// The flat-point sampling kernel `kernel` of `program` (its arguments: `scene...`, then wo,
// seed and the output): n samples' records, three float4 each (test_bsdf_sample_record)
template <typename... Scene>
std::vector<cl_float4> flat_sample(const KernelRig& r, const cl::Program& program, const char* kernel, glm::dvec3 wo,
                                   size_t n, cl_uint seed, const Scene&... scene) {
  auto out = r.output<cl_float4>(3 * n);
  cl::Kernel k(program, kernel);
  bind_args(k, 0, scene..., f4(wo), seed, out);
  r.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(n));
  return out.read();
}

// The flat-point evaluation kernel `kernel` of `program` (its arguments: `scene...`, then the
// pairs and the output): (f, pdf) for each (wo, wi) = (pairs[2i], pairs[2i + 1])
template <typename... Scene>
std::vector<cl_float4> flat_eval(const KernelRig& r, const cl::Program& program, const char* kernel,
                                 const std::vector<cl_float4>& pairs, const Scene&... scene) {
  cl::Buffer in = r.input(pairs);  // alive until the kernel is enqueued (which retains it)
  auto out = r.output<cl_float4>(pairs.size() / 2);
  cl::Kernel k(program, kernel);
  bind_args(k, 0, scene..., in, out);
  r.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(pairs.size() / 2));
  return out.read();
}

// (f, pdf) of a material's kernel for (wo, wi) pairs, given as float4 pairs
using PairEval = std::function<std::vector<cl_float4>(const std::vector<cl_float4>& pairs)>;

// For a sampling kernel whose records are three float4 a sample (test_bsdf_sample_record in
// tests/bsdf/test_bsdf.cl: (wi, pdf), (f, 1 for a delta sample), (bsdf_eval, bsdf_pdf) at
// wi; all zero where sampling failed), of a material without delta lobes seen from wo:
// every sample's f and pdf are eval's (1e-3 relative); the pdf integrates to at most
// 1 + 2e-3 and to the fraction of samples returned within 5e-3; a chi-square of the
// sampled directions against the pdf (p > alpha) in 32 x 64 cells of equal solid angle
// (z uniform in [-1, 1] x phi), each integrated on sub x sub midpoints, and one more for
// the failed samples with what the pdf lacks of 1
void check_sphere_sampling(const std::vector<cl_float4>& records, glm::dvec3 wo, const PairEval& eval, int sub,
                           double alpha);

// ---- Fixtures -----------------------------------------------------------------------------------

// Sampling (check_sampling): one test per device x material, every geometry inside; each
// family's file instantiates it (prefix Lobes) for its materials, named by BsdfTestName
class BsdfTest : public ::testing::TestWithParam<std::tuple<std::string, MaterialCase>> {};
struct BsdfTestName {
  std::string operator()(const ::testing::TestParamInfo<BsdfTest::ParamType>& info) const;
};

// Delta lobes (check_delta) and other checks on flat geometry, per device
class BsdfDelta : public DeviceTest {
 protected:
  // 64K samples of bsdf_sample of m at g
  Samples sample(const dev::Material& m, const Geometry& g);
};

}  // namespace candela::test
