// KHR_materials_iridescence (cl/bsdf/iridescence.cl, and its film mixed into the metal's and
// the specular layer's Fresnel terms in cl/bsdf/gltf/fresnel.cl) on PoCL, with a test program
// of its own (the shared one leaves CD_FEATURE_IRIDESCENCE out): the film's RGB reflectance against an
// explicit spectral reference (the Airy sum of the film's inter-reflections per wavelength,
// integrated against an analytic fit of the CIE 1931 colour matching functions, in double
// precision); its limit as the thickness goes to 0 (the Airy sum at zero phase, the base's
// F0 at normal incidence); its range; the BSDF's Fresnel terms being the film's mix at wo.h
// (rough lobes) and at wo (mirrors); bsdf_sample agreeing with bsdf_eval and bsdf_pdf and a
// chi-square of its directions with the film on; and a factor of 0 (or a thickness of 0)
// giving bit for bit the material of a kernel built without the feature.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstring>
#include <glm/glm.hpp>
#include <optional>

#include "bsdf/bsdf_checks.hpp"
#include "device/energy.hpp"
#include "device/kernel_sources.hpp"
#include "device/program_cache.hpp"
#include "device/sheen_albedo.hpp"

namespace candela::test {
namespace {

using Rgb = std::array<double, 3>;
constexpr size_t kIridescenceSamples = 1 << 18;

// ---- Host model of the film (double) ---------------------------------------------------------

double schlick(double f0, double c) { return f0 + (1.0 - f0) * std::pow(std::clamp(1.0 - c, 0.0, 1.0), 5.0); }

// The film's interfaces as the extension models them: Schlick reflectances R12 (air -> film,
// at the outside angle) and R23 (film -> base, inside the film; the base's index from its F0
// in air), the phase shifts of the amplitudes (pi where the far side has the lower index, in
// the convention r = (n_far - n_near) / (n_far + n_near): 0 or pi), and the film's cosine
struct Interfaces {
  double r12, r23, cos2;
  bool flip12, flip23;  // phase pi at air -> film, film -> base
};
Interfaces interfaces(double n, double f0, double cos1) {
  Interfaces i;
  i.cos2 = std::sqrt(1.0 - (1.0 - cos1 * cos1) / (n * n));
  i.r12 = schlick(std::pow((n - 1.0) / (n + 1.0), 2.0), cos1);
  double s = std::sqrt(std::clamp(f0, 0.0, 0.9999)), nb = (1.0 + s) / (1.0 - s);
  i.r23 = schlick(std::pow((nb - n) / (nb + n), 2.0), i.cos2);
  i.flip12 = n < 1.0;
  i.flip23 = nb < n;
  return i;
}

// The film's reflectance at one wavelength (nm): the Airy sum of amplitudes
// r = r12 + t12 t21 r23 e^(i delta) / (1 - r21 r23 e^(i delta)), r21 = -r12, t12 t21 = 1 - R12,
// delta = 2 pi (2 n d cos2) / lambda
double airy(const Interfaces& i, double n, double d, double lambda) {
  using C = std::complex<double>;
  double a = std::sqrt(i.r12) * (i.flip12 ? -1.0 : 1.0), b = std::sqrt(i.r23) * (i.flip23 ? -1.0 : 1.0);
  C e = std::polar(1.0, 2.0 * kPi * 2.0 * n * d * i.cos2 / lambda);
  C r = a + (1.0 - a * a) * b * e / (1.0 + a * b * e);
  return std::norm(r);
}

// CIE 1931 colour matching functions by Wyman, Sloan & Shirley's multi-lobe fit (JCGT 2(2), 2013)
double lobe(double l, double mu, double below, double above) {
  double s = l < mu ? below : above;
  return std::exp(-0.5 * (l - mu) * (l - mu) / (s * s));
}
Rgb cmf(double l) {
  return {1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) - 0.065 * lobe(l, 501.1, 20.4, 26.2),
          0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1),
          1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8)};
}
// XYZ -> linear sRGB (Rec. 709 primaries, D65)
constexpr double kXyzToRgb[3][3] = {
    {3.2404542, -1.5371385, -0.4985314}, {-0.9692660, 1.8760108, 0.0415560}, {0.0556434, -0.2040259, 1.0572252}};

// The film's RGB reflectance: each channel c the spectral reflectance with that channel's base
// F0, weighed by the channel's sensitivity (row c of XYZ -> sRGB applied to the colour matching
// functions) over 360-830 nm, normalized so that a flat spectrum of 1 gives 1; clamped to [0, 1]
// as the kernel's
Rgb spectral_film(double n, double d, Rgb f0, double cos1) {
  Rgb out{};
  for (int c = 0; c < 3; ++c) {
    Interfaces i = interfaces(n, f0[c], cos1);
    double num = 0.0, den = 0.0;
    for (double l = 360.0; l <= 830.0; l += 0.5) {
      Rgb x = cmf(l);
      double w = kXyzToRgb[c][0] * x[0] + kXyzToRgb[c][1] * x[1] + kXyzToRgb[c][2] * x[2];
      num += w * airy(i, n, d, l);
      den += w;
    }
    out[c] = std::clamp(num / den, 0.0, 1.0);
  }
  return out;
}

// The Airy sum at zero phase, the film's limit as its thickness goes to 0:
// ((a + b) / (1 + ab))^2 of the signed amplitudes
double zero_phase(double n, double f0, double cos1) {
  Interfaces i = interfaces(n, f0, cos1);
  double a = std::sqrt(i.r12) * (i.flip12 ? -1.0 : 1.0), b = std::sqrt(i.r23) * (i.flip23 ? -1.0 : 1.0);
  return std::pow((a + b) / (1.0 + a * b), 2.0);
}

// ---- The device ------------------------------------------------------------------------------

// The test program with every feature at its default (CD_FEATURE_IRIDESCENCE on) but the
// anisotropic table's (energy_test.cpp's), built once
const ProgramBuild& iridescence_program(KernelRig& r) {
  static std::optional<ProgramBuild> p;
  if (!p) p = build_program(r.context, r.device, test_program_source(), "-cl-std=CL1.2 -DCD_FEATURE_ANISOTROPY=0");
  return *p;
}

struct FilmQuery {
  double n, d;
  Rgb f0;
  double cos;
};

// iridescence_fresnel on the device for each query
std::vector<Rgb> device_film(KernelRig& r, const std::vector<FilmQuery>& qs) {
  std::vector<cl_float4> q, f0;
  for (const FilmQuery& x : qs) {
    q.push_back(f4(glm::dvec3(x.n, x.d, x.cos)));
    f0.push_back(f4(glm::dvec3(x.f0[0], x.f0[1], x.f0[2])));
  }
  auto out = r.output<cl_float4>(qs.size());
  cl::Kernel k(iridescence_program(r).program, "test_iridescence_fresnel");
  cl::Buffer qb = r.input(q), fb = r.input(f0);  // alive until the kernel is enqueued (which retains them)
  bind_args(k, 0, qb, fb, out);
  r.queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(qs.size()));
  std::vector<Rgb> v;
  for (const cl_float4& o : out.read()) v.push_back({o.s[0], o.s[1], o.s[2]});
  return v;
}

// A glTF material (specular 1, ior 1.5) with a film of factor `film`, index n, thickness d
// (the maximum; no thickness texture)
dev::Material material(double metallic, double roughness, glm::dvec3 base, double film, double n, double d,
                       double transmission = 0.0, double coat = 0.0, double specular = 1.0) {
  dev::Material m = gltf(base, metallic, roughness, transmission);
  dev::GltfMaterial& g = m.params.gltf;
  g.specular = float(specular);
  g.clearcoat = float(coat);
  g.clearcoat_roughness = 0.3f;
  g.iridescence = float(film);
  g.iridescence_ior = float(n);
  g.iridescence_thickness_min = float(0.25 * d);
  g.iridescence_thickness_max = float(d);
  return m;
}

// bsdf_sample and bsdf_eval of material m through test_sheen_sample / test_sheen_eval (tables:
// bit 0 binds the GGX albedo table, bit 1 the sheen table)
std::vector<cl_float4> sample(KernelRig& r, const cl::Program& p, const AlbedoTables& t, const dev::Material& m,
                              cl_uint tables, glm::dvec3 wo, size_t n, cl_uint seed) {
  return flat_sample(r, p, "test_sheen_sample", wo, n, seed, r.input(std::vector<dev::Material>{m}), t.ggx, t.sheen,
                     tables);
}
std::vector<cl_float4> eval(KernelRig& r, const cl::Program& p, const AlbedoTables& t, const dev::Material& m,
                            cl_uint tables, const std::vector<cl_float4>& pairs) {
  return flat_eval(r, p, "test_sheen_eval", pairs, r.input(std::vector<dev::Material>{m}), t.ggx, t.sheen, tables);
}

// m thin-walled, with the base's index of refraction 1 (glass that matches the air; one with
// a volume would refract nothing: its rough transmission is a delta lobe)
dev::Material thin_index_matched(dev::Material m) {
  m.params.gltf.ior = 1.0f;
  m.flags |= MATERIAL_THIN_WALLED;
  return m;
}

const Rgb kGold{0.944, 0.776, 0.373}, kGrey{0.04, 0.04, 0.04}, kBlack{0.0, 0.0, 0.0}, kMixed{0.5, 0.2, 0.8};

// ---- The film ----------------------------------------------------------------------------------

// The closed form (Gaussian fits of the colour matching functions in Fourier space) against the
// spectral Airy sum: within 0.04 (the fits' error; the largest seen, 0.036, is a saturated gold
// film at grazing incidence), and the film coloured (its channels apart) where it should be
TEST(Iridescence, FilmMatchesASpectralAiryReference) {
  KernelRig& r = kernel_rig("pocl");
  std::vector<FilmQuery> qs;
  for (double n : {1.3, 1.5, 2.0})
    for (double d : {100.0, 200.0, 300.0, 450.0, 700.0})
      for (double c : {1.0, 0.7, 0.3, 0.05})
        for (const Rgb& f0 : {kGrey, kGold, kBlack, kMixed}) qs.push_back({n, d, f0, c});
  std::vector<Rgb> got = device_film(r, qs);
  double worst = 0.0;
  for (size_t i = 0; i < qs.size(); ++i) {
    const FilmQuery& q = qs[i];
    Rgb want = spectral_film(q.n, q.d, q.f0, q.cos);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(got[i][c], want[c], 0.04) << "n " << q.n << ", d " << q.d << " nm, cos " << q.cos << ", f0 "
                                            << q.f0[0] << " " << q.f0[1] << " " << q.f0[2] << ", channel " << c;
      worst = std::max(worst, std::fabs(got[i][c] - want[c]));
    }
  }
  std::printf("largest difference from the spectral reference: %.4f\n", worst);
  // A 300 nm film of index 1.3 over a dielectric at normal incidence is visibly coloured
  // (in the reference and on the device alike)
  Rgb want = spectral_film(1.3, 300.0, kGrey, 1.0);
  Rgb got300 = device_film(r, {{1.3, 300.0, kGrey, 1.0}})[0];
  double spread = *std::max_element(want.begin(), want.end()) - *std::min_element(want.begin(), want.end());
  EXPECT_GT(spread, 0.01);
  EXPECT_GT(*std::max_element(got300.begin(), got300.end()) - *std::min_element(got300.begin(), got300.end()),
            0.5 * spread);
}

// As the thickness goes to 0 (the film's index held), the film tends to the Airy sum at zero
// phase ((a + b) / (1 + ab))^2, which at normal incidence is the base's F0 exactly
TEST(Iridescence, VanishingFilmTendsToTheBase) {
  KernelRig& r = kernel_rig("pocl");
  std::vector<FilmQuery> qs;
  for (double n : {1.2, 1.3, 1.8, 2.5})
    for (double c : {1.0, 0.8, 0.5, 0.2, 0.05})
      for (const Rgb& f0 : {kGrey, kGold, kBlack, kMixed}) qs.push_back({n, 1e-3, f0, c});
  std::vector<Rgb> got = device_film(r, qs);
  for (size_t i = 0; i < qs.size(); ++i) {
    const FilmQuery& q = qs[i];
    for (int c = 0; c < 3; ++c) {
      SCOPED_TRACE("n " + std::to_string(q.n) + ", cos " + std::to_string(q.cos) + ", channel " + std::to_string(c));
      Interfaces f = interfaces(q.n, q.f0[c], q.cos);
      // The series (orders m of amplitude |Rs - T121| r^m, r = sqrt(R12 R23)) stops where the
      // amplitude falls under 1e-4, or after the 8th order: the tail left out is at most
      // 2 max(1e-4, |Rs - T121| r^9) / (1 - r); and float rounding
      double r = std::sqrt(f.r12 * f.r23), t121 = 1.0 - f.r12, rs = t121 * t121 * f.r23 / (1.0 - f.r12 * f.r23);
      double tol = 2.0 * std::max(1e-4, std::fabs(rs - t121) * std::pow(r, 9.0)) / (1.0 - r) + 2e-5;
      EXPECT_NEAR(got[i][c], zero_phase(q.n, q.f0[c], q.cos), tol);
      if (q.cos == 1.0) {
        EXPECT_NEAR(got[i][c], q.f0[c], tol);
      }
    }
  }
}

// Finite and within [0, 1] for every angle, thickness, film index and base
TEST(Iridescence, FilmStaysInTheUnitRange) {
  KernelRig& r = kernel_rig("pocl");
  std::vector<FilmQuery> qs;
  for (double n : {1.0, 1.01, 1.3, 2.0, 3.0})
    for (double d : {0.0, 1.0, 50.0, 250.0, 1000.0, 5000.0})
      for (int k = 0; k <= 20; ++k)
        for (const Rgb& f0 : {kGrey, kGold, kBlack, kMixed, Rgb{1.0, 0.999, 0.9999}})
          qs.push_back({n, d, f0, k / 20.0});
  std::vector<Rgb> got = device_film(r, qs);
  for (size_t i = 0; i < qs.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(std::isfinite(got[i][c]) && got[i][c] >= 0.0 && got[i][c] <= 1.0)
          << got[i][c] << " at n " << qs[i].n << ", d " << qs[i].d << ", cos " << qs[i].cos;
    }
}

// A film of index 2 and 300 nm over a base of index 1 (F0 = 0: the base matches the air and
// reflects nothing) and over one of index 1.5 (F0 = 0.04), at normal and oblique incidence:
// the device's RGB reflectance against the spectral Airy sum. The reference itself first: at
// normal incidence over the base of index 1, the film reflects 0.30 at 450 nm, 0.14 at 550 nm
// and nothing at 600 nm (|r12 + r23 e^(i delta)|^2 / |1 + r12 r23 e^(i delta)|^2, r12 = -r23
// = -1/3, delta = 4 pi n d / lambda), a blue mirror
TEST(Iridescence, FilmReflectsOverAnIndexMatchedBase) {
  Interfaces matched = interfaces(2.0, 0.0, 1.0);
  EXPECT_NEAR(matched.r12, 1.0 / 9.0, 1e-12);
  EXPECT_NEAR(matched.r23, 1.0 / 9.0, 1e-12);
  EXPECT_NEAR(airy(matched, 2.0, 300.0, 450.0), 0.2967, 1e-4);
  EXPECT_NEAR(airy(matched, 2.0, 300.0, 550.0), 0.1412, 1e-4);
  EXPECT_NEAR(airy(matched, 2.0, 300.0, 600.0), 0.0, 1e-12);
  KernelRig& r = kernel_rig("pocl");
  std::vector<FilmQuery> qs;
  for (double f0 : {0.0, 0.04})
    for (double c : {1.0, 0.8, 0.5, 0.25}) qs.push_back({2.0, 300.0, Rgb{f0, f0, f0}, c});
  std::vector<Rgb> got = device_film(r, qs);
  for (size_t i = 0; i < qs.size(); ++i) {
    Rgb want = spectral_film(qs[i].n, qs[i].d, qs[i].f0, qs[i].cos);
    std::printf("base F0 %.2f, cos %.2f: device %.4f %.4f %.4f, reference %.4f %.4f %.4f\n", qs[i].f0[0], qs[i].cos,
                got[i][0], got[i][1], got[i][2], want[0], want[1], want[2]);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(got[i][c], want[c], 0.04) << "F0 " << qs[i].f0[0] << ", cos " << qs[i].cos << ", channel " << c;
  }
  // Normal incidence over the matched base: a blue mirror, as the reference
  EXPECT_GT(got[0][2], 0.2);
  EXPECT_GT(got[0][2], 1.5 * got[0][0]);
  EXPECT_GT(got[0][2], got[0][1]);
}

// ---- The BSDF ----------------------------------------------------------------------------------

// Without the albedo table (no multiple scattering) a rough metal's f is its Fresnel term times
// the microfacet lobe, and a black plastic's its specular term: f with the film over f without
// is mix(F, film, factor) / F at wo.h, the film the device's at that cosine (the dielectric's
// over F0(ior) = 0.04, scaled by the specular factor). A mirror's sample weight is the mix at wo.z.
TEST(Iridescence, FresnelIsTheFilmsMix) {
  KernelRig& r = kernel_rig("pocl");
  const ProgramBuild& p = iridescence_program(r);
  AlbedoTables t(r, p.program, p.cache_file);
  const double n = 1.4, d = 350.0;
  struct Case {
    const char* name;
    double metallic, factor, specular;
    Rgb base;
  } cases[] = {{"gold metal, factor 0.6", 1.0, 0.6, 1.0, kGold},
               {"black plastic, factor 1, specular 0.8", 0.0, 1.0, 0.8, kBlack}};
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    glm::dvec3 base(k.base[0], k.base[1], k.base[2]);
    dev::Material film = material(k.metallic, 0.4, base, k.factor, n, d, 0.0, 0.0, k.specular);
    dev::Material plain = material(k.metallic, 0.4, base, 0.0, n, d, 0.0, 0.0, k.specular);
    std::vector<cl_float4> pairs;
    std::vector<FilmQuery> qs;
    for (double zo : {0.9, 0.5, 0.15})
      for (double zi : {0.95, 0.6, 0.2})
        for (double phi : {0.5, 2.0, 3.0}) {
          glm::dvec3 wo = sphere_direction(zo, 0.0), wi = sphere_direction(zi, phi);
          pairs.push_back(f4(wo));
          pairs.push_back(f4(wi));
          double cos_h = glm::dot(wo, glm::normalize(wo + wi));
          qs.push_back({n, d, k.metallic > 0.0 ? k.base : kGrey, cos_h});
        }
    std::vector<cl_float4> fa = eval(r, p.program, t, film, 0u, pairs), fb = eval(r, p.program, t, plain, 0u, pairs);
    std::vector<Rgb> films = device_film(r, qs);
    for (size_t i = 0; i < qs.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        double f0 = k.metallic > 0.0 ? k.base[c] * 1.0 : 0.04 * k.specular, f90 = k.metallic > 0.0 ? 1.0 : k.specular;
        double schlick_f = f0 + (f90 - f0) * std::pow(1.0 - qs[i].cos, 5.0);
        double mixed = (1.0 - k.factor) * schlick_f + k.factor * f90 * films[i][c];
        ASSERT_GT(fb[i].s[c], 0.0f);
        EXPECT_NEAR(fa[i].s[c] / fb[i].s[c], mixed / schlick_f, 2e-4 * mixed / schlick_f) << "pair " << i;
        EXPECT_FLOAT_EQ(fa[i].s[3], fb[i].s[3]);  // the pdf: the film changes no weight of these single-lobe mixtures
      }
    // The mirror: every sample is the delta reflection, of weight f wo.z / pdf = the mix at wo.z
    for (double zo : {0.9, 0.4, 0.1}) {
      glm::dvec3 wo = sphere_direction(zo, 0.3);
      dev::Material mirror = material(k.metallic, 0.0, base, k.factor, n, d, 0.0, 0.0, k.specular);
      std::vector<cl_float4> s = sample(r, p.program, t, mirror, 0u, wo, 64, 3u);
      Rgb f = device_film(r, {{n, d, k.metallic > 0.0 ? k.base : kGrey, zo}})[0];
      for (size_t i = 0; i < 64; ++i) {
        ASSERT_EQ(s[3 * i + 1].s[3], 1.0f) << "a delta sample";
        for (int c = 0; c < 3; ++c) {
          double f0 = k.metallic > 0.0 ? k.base[c] : 0.04 * k.specular, f90 = k.metallic > 0.0 ? 1.0 : k.specular;
          double want = (1.0 - k.factor) * (f0 + (f90 - f0) * std::pow(1.0 - zo, 5.0)) + k.factor * f90 * f[c];
          EXPECT_NEAR(s[3 * i + 1].s[c] * zo / s[3 * i].s[3], want, 1e-5 + 1e-5 * want);
        }
      }
    }
  }
}

// The exact Fresnel term of a dielectric interface (eta = n_t / n_i), in double
double fresnel_exact(double c, double eta) {
  double s2 = (1.0 - c * c) / (eta * eta);
  if (s2 >= 1.0) return 1.0;
  double t = std::sqrt(1.0 - s2), rp = (eta * c - t) / (eta * c + t), rs = (c - eta * t) / (c + eta * t);
  return 0.5 * (rp * rp + rs * rs);
}

// Smooth glass (transmission 1) under a film of index 2 and 300 nm: the film's reflectance
// replaces the exact Fresnel term in the split, F = mix(exact, film over F0(ior), factor), for
// a base of index 1 (the exact term 0) and of index 1.5, thin-walled too (2F / (1 + F) per
// channel). Every sample is a delta one; a reflection weighs F, a transmission (1 - F) x tint,
// and reflections are chosen with probability mean(F): energy is conserved channel by channel
TEST(Iridescence, GlassSplitsByTheFilm) {
  KernelRig& r = kernel_rig("pocl");
  const ProgramBuild& p = iridescence_program(r);
  AlbedoTables t(r, p.program, p.cache_file);
  struct Case {
    const char* name;
    double ior, factor, tint;
    bool thin;
  } cases[] = {{"sunglasses: ior 1, factor 1, tint 0.009", 1.0, 1.0, 0.009, false},
               {"ior 1.5, factor 0.5, tint 0.8", 1.5, 0.5, 0.8, false},
               {"thin-walled, ior 1, factor 1, tint 0.3", 1.0, 1.0, 0.3, true}};
  const size_t n = 1 << 14;
  for (const Case& k : cases)
    for (double zo : {1.0, 0.7, 0.3}) {
      SCOPED_TRACE(std::string(k.name) + ", wo.z " + std::to_string(zo));
      dev::Material m = material(0.0, 0.0, glm::dvec3(k.tint), k.factor, 2.0, 300.0, 1.0);
      m.params.gltf.ior = float(k.ior);
      if (k.thin) m.flags |= MATERIAL_THIN_WALLED;
      glm::dvec3 wo = sphere_direction(zo, 0.3);
      double f0 = std::pow((k.ior - 1.0) / (k.ior + 1.0), 2.0);
      Rgb film = device_film(r, {{2.0, 300.0, Rgb{f0, f0, f0}, zo}})[0];
      Rgb want{};
      double share = 0.0;
      for (int c = 0; c < 3; ++c) {
        double f = (1.0 - k.factor) * fresnel_exact(zo, k.ior) + k.factor * film[c];
        want[c] = k.thin ? 2.0 * f / (1.0 + f) : f;
        share += want[c] / 3.0;
      }
      if (k.ior == 1.0) {
        EXPECT_GT(want[2], 0.05) << "the film reflects where the bare base would not";
      }
      std::vector<cl_float4> s = sample(r, p.program, t, m, 0u, wo, n, 11u);
      size_t reflected = 0;
      for (size_t i = 0; i < n; ++i) {
        const cl_float4 &dir = s[3 * i], &f = s[3 * i + 1];
        ASSERT_EQ(f.s[3], 1.0f) << "a delta sample";
        bool reflects = dir.s[2] > 0.0f;
        reflected += reflects;
        ASSERT_NEAR(dir.s[3], reflects ? share : 1.0 - share, 1e-5);
        double cos_t = std::fabs(dir.s[2]), eta2 = k.thin ? 1.0 : k.ior * k.ior;
        for (int c = 0; c < 3; ++c) {
          double weight = reflects ? f.s[c] * zo : f.s[c] * cos_t * eta2;
          double expect = reflects ? want[c] : k.tint * (1.0 - want[c]);
          ASSERT_NEAR(weight, expect, 2e-5 + 2e-4 * expect) << "sample " << i << ", channel " << c;
        }
      }
      double frac = double(reflected) / double(n), se = std::sqrt(share * (1.0 - share) / double(n));
      EXPECT_NEAR(frac, share, 5.0 * se + 1e-6);
    }
}

// bsdf_sample agrees with bsdf_eval and bsdf_pdf, the pdf integrates to 1 less what the GGX
// lobes send below the horizon, and a chi-square of the sampled directions against the pdf
TEST(Iridescence, SamplingMatchesThePdf) {
  KernelRig& r = kernel_rig("pocl");
  const ProgramBuild& p = iridescence_program(r);
  AlbedoTables t(r, p.program, p.cache_file);
  struct Case {
    const char* name;
    dev::Material m;
  } cases[] = {
      {"film 1.3/380 nm over white plastic r0.3", material(0.0, 0.3, glm::dvec3(1.0), 1.0, 1.3, 380.0)},
      {"film 1.8/250 nm over gold r0.3", material(1.0, 0.3, glm::dvec3(kGold[0], kGold[1], kGold[2]), 1.0, 1.8, 250.0)},
      {"half film over half metal r0.5", material(0.5, 0.5, glm::dvec3(0.2, 0.5, 0.8), 0.5, 1.5, 500.0)},
      {"film under a coat r0.4", material(0.0, 0.4, glm::dvec3(0.7), 1.0, 1.3, 300.0, 0.0, 1.0)},
      {"film over rough glass r0.3", material(0.2, 0.3, glm::dvec3(1.0), 1.0, 1.4, 420.0, 1.0)},
      {"film 2/300 nm over rough thin glass of ior 1 r0.3",
       thin_index_matched(material(0.0, 0.3, glm::dvec3(0.5), 1.0, 2.0, 300.0, 1.0))},
  };
  std::vector<double> wo_z = {0.8, 0.3, 0.05};
  double alpha = sidak_alpha(1e-3, int(std::size(cases) * wo_z.size()));
  for (const Case& c : cases)
    for (double z : wo_z) {
      SCOPED_TRACE(std::string(c.name) + ", wo.z " + std::to_string(z));
      glm::dvec3 wo = sphere_direction(z, 0.4);
      check_sphere_sampling(
          sample(r, p.program, t, c.m, 3u, wo, kIridescenceSamples, 7u), wo,
          [&](const std::vector<cl_float4>& pairs) { return eval(r, p.program, t, c.m, 3u, pairs); }, 16, alpha);
    }
}

// Factor 0, or a film of thickness 0: bsdf_sample and bsdf_eval give bit for bit what the
// shared test program (built with CD_FEATURE_IRIDESCENCE=0, the kernel of a scene without
// a film) gives for the material
TEST(Iridescence, NoFilmIsTheMaterialWithoutTheFeature) {
  KernelRig& r = kernel_rig("pocl");
  const ProgramBuild& p = iridescence_program(r);
  AlbedoTables t(r, p.program, p.cache_file), tp(r, r.program, r.program_cache_file);
  dev::Material cases[] = {
      material(0.0, 0.4, glm::dvec3(0.8), 0.0, 1.6, 300.0),
      material(1.0, 0.2, glm::dvec3(0.9, 0.6, 0.3), 0.0, 1.6, 300.0),
      material(0.0, 0.0, glm::dvec3(0.8), 0.0, 1.6, 300.0),
      material(0.3, 0.1, glm::dvec3(1.0), 0.0, 1.6, 300.0, 1.0),
      material(0.0, 0.5, glm::dvec3(0.5), 0.0, 1.6, 300.0, 0.0, 1.0),
      material(0.5, 0.3, glm::dvec3(0.5), 1.0, 1.6, 0.0),  // thickness 0: no film
  };
  size_t n = kIridescenceSamples / 8;
  for (size_t ci = 0; ci < std::size(cases); ++ci) {
    const dev::Material& m = cases[ci];
    for (double z : {0.9, 0.3, 0.01}) {
      SCOPED_TRACE("case " + std::to_string(ci) + ", wo.z " + std::to_string(z));
      glm::dvec3 wo = sphere_direction(z, 0.6);
      std::vector<cl_float4> a = sample(r, p.program, t, m, 3u, wo, n, 5u),
                             b = sample(r, r.program, tp, m, 3u, wo, n, 5u);
      EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(cl_float4)), 0);
      std::vector<cl_float4> pairs;
      for (size_t i = 0; i < n; ++i) {
        pairs.push_back(f4(wo));
        pairs.push_back(a[3 * i].s[3] > 0.0f ? a[3 * i] : f4(sphere_direction(-0.5, 0.1 * double(i))));
      }
      std::vector<cl_float4> ea = eval(r, p.program, t, m, 3u, pairs), eb = eval(r, r.program, tp, m, 3u, pairs);
      EXPECT_EQ(std::memcmp(ea.data(), eb.data(), ea.size() * sizeof(cl_float4)), 0);
    }
  }
}

}  // namespace
}  // namespace candela::test
