#include "render/film.hpp"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "base/atomic_file.hpp"
#include "base/error.hpp"
#include "render/aov.hpp"

namespace candela {

glm::vec3 Film::variance_of_mean(size_t i) const {
  float n = samples(i);
  if (n < 2.0f) return glm::vec3(INFINITY);
  glm::vec3 m(m2[4 * i], m2[4 * i + 1], m2[4 * i + 2]);
  return m / (n - 1.0f) / n;
}

uint64_t Film::dropped_samples() const {
  double total = 0.0;
  for (size_t i = 0; i < pixels(); ++i) total += m2[4 * i + 3];
  return uint64_t(total);
}

Film merge_films(const Film& a, const Film& b) {
  if (a.width != b.width || a.height != b.height) throw Error("cannot merge films of different sizes");
  Film out(a.width, a.height);
  for (size_t i = 0; i < a.pixels(); ++i) {
    double na = a.mean[4 * i + 3], nb = b.mean[4 * i + 3], n = na + nb;
    for (int c = 0; c < 3; ++c) {
      double ma = a.mean[4 * i + c], mb = b.mean[4 * i + c];
      double delta = mb - ma;
      out.mean[4 * i + c] = n > 0 ? float(ma + delta * nb / n) : 0.0f;
      out.m2[4 * i + c] = n > 0 ? float(a.m2[4 * i + c] + b.m2[4 * i + c] + delta * delta * na * nb / n) : 0.0f;
    }
    out.mean[4 * i + 3] = float(n);
    out.m2[4 * i + 3] = a.m2[4 * i + 3] + b.m2[4 * i + 3];
  }
  if (a.aov.empty() || b.aov.empty()) return out;
  out.aov.resize(a.aov.size());
  for (size_t i = 0; i < a.pixels(); ++i) {
    double na = a.samples_taken(i), nb = b.samples_taken(i), n = na + nb;
    for (int c = 0; c < 8; ++c)
      out.aov[8 * i + c] = n > 0 ? float((na * a.aov[8 * i + c] + nb * b.aov[8 * i + c]) / n) : 0.0f;
  }
  return out;
}

float linear_to_srgb(float c) {
  c = std::clamp(c, 0.0f, 1.0f);
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

namespace {

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (auto& ch : ext) ch = char(std::tolower((unsigned char)ch));
  return ext;
}

}  // namespace

void check_output_path(const std::string& path) {
  check_writable_path(path);
  std::string ext = lower_extension(path);
  if (ext != ".exr" && ext != ".png" && ext != ".jpg" && ext != ".jpeg")
    throw Error("output must end in .exr, .png or .jpg: " + path);
}

void write_image(const std::string& path, const Film& film, const std::map<std::string, std::string>& metadata,
                 const DisplayTransform& display, const ImageLayers& layers) {
  check_output_path(path);
  bool exr = lower_extension(path) == ".exr";
  std::map<std::string, std::string> meta = metadata;
  if (!exr && layers.single) {
    meta["image"] = enum_name(kAovNames, Aov(layers.single));
    write_rgb_pixels(path, film.width, film.height, aov_display(film, Aov(layers.single)), false, meta);
    return;
  }
  // PNG with a transparent background: straight alpha (the colour divided by alpha)
  bool rgba = layers.transparent && lower_extension(path) == ".png";
  std::vector<float> rgb(film.pixels() * 3);
  float scale = std::exp2(display.exposure);
  const bool denoised = !film.denoised.empty();
  for (size_t i = 0; i < film.pixels(); ++i) {
    glm::vec3 v =
        denoised ? glm::vec3(film.denoised[3 * i], film.denoised[3 * i + 1], film.denoised[3 * i + 2]) : film.pixel(i);
    if (rgba && film_alpha(film, i) > 0.0f) v /= film_alpha(film, i);
    if (!exr) v = tonemap_apply(display.tonemap, v * scale);
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = exr ? v[c] : linear_to_srgb(v[c]);
  }
  if (!exr) meta["tonemap"] = tonemap_name(display.tonemap);
  std::vector<std::string> names;
  std::vector<float> extra;
  if (exr) aov_channels(film, layers.aovs, layers.transparent, &names, &extra);
  if (exr && denoised) {  // the unbiased estimate beside the denoised RGB
    std::vector<float> with(film.pixels() * (names.size() + 3));
    size_t k = names.size();
    for (size_t i = 0; i < film.pixels(); ++i) {
      for (int c = 0; c < 3; ++c) with[(k + 3) * i + c] = film.mean[4 * i + c];
      std::copy_n(extra.data() + k * i, k, with.data() + (k + 3) * i + 3);
    }
    names.insert(names.begin(), {"noisy.R", "noisy.G", "noisy.B"});
    extra.swap(with);
  }
  if (rgba) aov_channels(film, aov_bit(Aov::Alpha), false, &names, &extra);
  if (names.empty()) return write_rgb_pixels(path, film.width, film.height, rgb, exr, meta);
  std::vector<std::string> channels = {"R", "G", "B"};
  channels.insert(channels.end(), names.begin(), names.end());
  size_t n = channels.size(), k = names.size();
  std::vector<float> values(film.pixels() * n);
  for (size_t i = 0; i < film.pixels(); ++i) {
    std::copy_n(&rgb[3 * i], 3, &values[n * i]);
    for (size_t c = 0; c < k; ++c) values[n * i + 3 + c] = rgba ? film_alpha(film, i) : extra[k * i + c];
  }
  write_pixels(path, film.width, film.height, channels, values, exr, meta);
}

void write_rgb_pixels(const std::string& path, int width, int height, const std::vector<float>& rgb,
                      bool float_channels, const std::map<std::string, std::string>& metadata) {
  write_pixels(path, width, height, {"R", "G", "B"}, rgb, float_channels, metadata);
}

void write_pixels(const std::string& path, int width, int height, const std::vector<std::string>& channels,
                  const std::vector<float>& values, bool float_channels,
                  const std::map<std::string, std::string>& metadata) {
  OIIO::ImageSpec spec(width, height, int(channels.size()),
                       float_channels ? OIIO::TypeDesc::FLOAT : OIIO::TypeDesc::UINT8);
  spec.channelnames = channels;
  for (size_t c = 0; c < channels.size(); ++c)
    if (channels[c] == "A") spec.alpha_channel = int(c);
  // 8-bit values come with straight alpha already (OpenImageIO would divide them once more)
  if (spec.alpha_channel >= 0 && !float_channels) spec.attribute("oiio:UnassociatedAlpha", 1);
  for (const auto& [key, value] : metadata) spec.attribute("candela:" + key, value);
  spec.attribute("Software", "candela " CANDELA_VERSION);
  // Encoded in memory (no encoder meets a full disk half way), then written atomically
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput memory(bytes);
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw Error("cannot write " + path + ": " + first_line(OIIO::geterror()));
  out->set_ioproxy(&memory);
  bool ok = out->open(path, spec) && out->write_image(OIIO::TypeDesc::FLOAT, values.data());
  ok = out->close() && ok;
  if (!ok || bytes.empty()) throw Error("cannot encode " + path + ": " + first_line(out->geterror()));
  write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace candela
