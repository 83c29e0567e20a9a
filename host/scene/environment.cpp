// Environment maps on the host (environment.hpp): loading, the built-in studio, the mean radiance.
#include "scene/environment.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <glm/glm.hpp>

#include "base/error.hpp"
#include "base/file_access.hpp"

namespace candela {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr uint64_t kMaxMapBytes = uint64_t(1) << 30;  // as float RGBA: 8192 x 8192

double texel_luminance(const TextureDesc& map, size_t i) {
  const float* t = &map.rgbaf[4 * i];
  return dev::luminance_rgb(t[0], t[1], t[2]);
}

}  // namespace

TextureDesc load_environment_image(const std::string& path) {
  check_regular_file(path, "environment map");  // a FIFO or /dev/zero would never end
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    std::string why = OIIO::geterror();
    throw Error("cannot read environment map " + path + (why.empty() ? "" : ": " + why));
  }
  const OIIO::ImageSpec spec = in->spec();
  int w = spec.width, h = spec.height, nc = spec.nchannels;
  if (w <= 0 || h <= 0 || nc <= 0) throw Error("environment map " + path + " has no pixels");
  if (uint64_t(w) * uint64_t(h) * 16 > kMaxMapBytes)
    throw Error("environment map " + path + " is too large (" + std::to_string(w) + " x " + std::to_string(h) +
                ", over 1 GiB as float RGBA)");
  std::vector<float> pixels(size_t(w) * size_t(h) * size_t(nc));
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw Error("cannot read environment map " + path + ": " + in->geterror());
  in->close();
  // Integer images hold sRGB-encoded colour unless they say otherwise
  bool integer = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  std::string space = spec.get_string_attribute("oiio:ColorSpace");
  bool srgb = integer && space != "Linear" && space != "linear";
  TextureDesc t;
  t.width = w;
  t.height = h;
  t.wrap_s = WRAP_REPEAT;
  t.wrap_t = WRAP_CLAMP;
  t.nearest = true;
  t.rgbaf.resize(size_t(w) * size_t(h) * 4);
  for (size_t i = 0; i < t.texels(); ++i) {
    for (int c = 0; c < 3; ++c) {
      float v = pixels[i * size_t(nc) + size_t(std::min(c, nc - 1))];
      if (srgb) v = dev::srgb_to_linear(std::clamp(v, 0.0f, 1.0f));
      t.rgbaf[4 * i + size_t(c)] = std::isfinite(v) && v > 0.0f ? v : 0.0f;
    }
    t.rgbaf[4 * i + 3] = 1.0f;
  }
  return t;
}

EnvironmentDesc load_environment(const std::string& path, float strength, float rotation) {
  if (!(strength >= 0.0f) || !std::isfinite(strength))
    throw Error("environment strength must be finite and non-negative");
  if (!std::isfinite(rotation)) throw Error("environment rotation must be finite");
  EnvironmentDesc e;
  e.image = load_environment_image(path);
  e.strength = strength;
  e.rotation = rotation;
  e.source = path;
  return e;
}

namespace {

// A soft lobe around unit direction `axis`: exp((cos - 1) / width), 1 on the axis
double soft_lobe(const glm::dvec3& d, glm::dvec3 axis, double width) {
  return std::exp((glm::dot(d, glm::normalize(axis)) - 1.0) / width);
}

// The studio's radiance toward direction d (neutral grey): a bright ceiling over a darker
// floor, blended across a soft horizon, with a key softbox in front to the left and above
// (glTF assets face +Z), a weaker fill to the right and a rim light behind
double studio_radiance(const glm::dvec3& d) {
  double sky = 0.55 + 0.30 * std::max(d.y, 0.0), floor = 0.18;
  double t = std::clamp((d.y + 0.2) / 0.28, 0.0, 1.0);
  double base = floor + (sky - floor) * t * t * (3.0 - 2.0 * t);
  double key = 4.0 * soft_lobe(d, {-0.45, 0.75, 0.5}, 0.02);
  double fill = 1.5 * soft_lobe(d, {0.85, 0.35, 0.4}, 0.04);
  double rim = 2.5 * soft_lobe(d, {0.2, 0.55, -0.8}, 0.02);
  return base + key + fill + rim;
}

}  // namespace

EnvironmentDesc builtin_environment() {
  const int w = 512, h = 256;
  EnvironmentDesc e;
  e.source = "built-in studio";
  TextureDesc& t = e.image;
  t.width = w;
  t.height = h;
  t.wrap_s = WRAP_REPEAT;
  t.wrap_t = WRAP_CLAMP;
  t.nearest = false;  // bilinear: no steps between texels; every texel is > 0, so the
                      // piecewise-constant sampling pdf covers the whole sphere
  t.rgbaf.resize(size_t(w) * h * 4);
  for (int r = 0; r < h; ++r) {
    double theta = kPi * (r + 0.5) / h;
    for (int c = 0; c < w; ++c) {
      // The direction of the texel centre, as cl/lights/environment.cl maps it (rotation 0)
      double phi = 2.0 * kPi * (c + 0.5) / w;
      glm::dvec3 d(-std::sin(theta) * std::sin(phi), std::cos(theta), std::sin(theta) * std::cos(phi));
      float v = float(studio_radiance(d));
      float* texel = &t.rgbaf[4 * (size_t(r) * w + c)];
      texel[0] = texel[1] = texel[2] = v;
      texel[3] = 1.0f;
    }
  }
  return e;
}

double environment_mean_luminance(const TextureDesc& map) {
  int w = map.width, h = map.height;
  double sum = 0.0;
  for (int r = 0; r < h; ++r) {
    double solid_angle = 2.0 * kPi / w * (std::cos(kPi * r / h) - std::cos(kPi * (r + 1) / h));
    for (int c = 0; c < w; ++c) sum += texel_luminance(map, size_t(r) * w + c) * solid_angle;
  }
  return sum / (4.0 * kPi);
}

}  // namespace candela
