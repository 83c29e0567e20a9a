#include "render/image_stats.hpp"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "base/error.hpp"

namespace candela {

void write_variance_image(const std::string& path, const Film& film,
                          const std::map<std::string, std::string>& metadata) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".exr") throw Error("--variance must name an .exr file (the variance is linear float data): " + path);
  std::vector<float> rgb(film.pixels() * 3);
  for (size_t i = 0; i < film.pixels(); ++i) {
    glm::vec3 v = film.variance_of_mean(i);
    for (int c = 0; c < 3; ++c) rgb[3 * i + c] = v[c];
  }
  std::map<std::string, std::string> meta = metadata;
  meta["image"] = "variance_of_mean";
  write_rgb_pixels(path, film.width, film.height, rgb, true, meta);
}

RgbImage read_rgb_image(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(what + " not found: " + path);
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw Error("cannot read " + what + " " + path + ": " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  RgbImage img;
  img.width = spec.width;
  img.height = spec.height;
  int channels = spec.nchannels;
  if (channels < 1 || img.width <= 0 || img.height <= 0)
    throw Error("cannot read " + what + " " + path + ": no pixels");
  std::vector<float> all(img.pixels() * size_t(channels));
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, all.data()))
    throw Error("cannot read " + what + " " + path + ": " + in->geterror());
  for (const auto& p : spec.extra_attribs) {
    std::string name = p.name().string();
    if (name.rfind("candela:", 0) == 0) img.metadata[name.substr(8)] = p.get_string();
  }
  in->close();
  // A denoised render's unbiased estimate is noisy.R/G/B: read that, leave the denoised RGB out
  auto index = [&](const std::string& name) {
    auto named = std::find(spec.channelnames.begin(), spec.channelnames.end(), name);
    return named != spec.channelnames.end() ? int(named - spec.channelnames.begin()) : -1;
  };
  const bool noisy = index("noisy.R") >= 0 && index("noisy.G") >= 0 && index("noisy.B") >= 0;
  int rgb[3], denoised[3] = {-1, -1, -1};
  for (int c = 0; c < 3; ++c) {
    int plain = index(std::string(1, "RGB"[c]));
    rgb[c] = noisy ? index(std::string("noisy.") + "RGB"[c]) : plain >= 0 ? plain : std::min(c, channels - 1);
    if (noisy) denoised[c] = plain;
  }
  std::vector<int> others;
  for (int k = 0; k < channels; ++k)
    if (k != rgb[0] && k != rgb[1] && k != rgb[2] && k != denoised[0] && k != denoised[1] && k != denoised[2] &&
        k < int(spec.channelnames.size())) {
      others.push_back(k);
      img.extra_names.push_back(spec.channelnames[size_t(k)]);
    }
  img.rgb.resize(img.pixels() * 3);
  img.extra.resize(img.pixels() * others.size());
  for (size_t i = 0; i < img.pixels(); ++i) {
    for (int c = 0; c < 3; ++c) img.rgb[3 * i + c] = all[i * channels + rgb[c]];
    for (size_t k = 0; k < others.size(); ++k) img.extra[i * others.size() + k] = all[i * channels + others[k]];
  }
  return img;
}

namespace {

void check_same_size(const RgbImage& a, const RgbImage& b, const std::string& what) {
  if (a.width != b.width || a.height != b.height)
    throw Error(what + ": the images differ in size (" + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " against " + std::to_string(b.width) + "x" + std::to_string(b.height) + ")");
}

}  // namespace

ErrorMetrics image_error(const RgbImage& image, const RgbImage& reference, double epsilon) {
  check_same_size(image, reference, "error against the reference");
  ErrorMetrics m;
  double rel = 0.0, sq = 0.0, abs_sum = 0.0;
  for (size_t k = 0; k < image.rgb.size(); ++k) {
    double x = image.rgb[k], r = reference.rgb[k], d = x - r;
    rel += d * d / (r * r + epsilon);
    sq += d * d;
    abs_sum += std::abs(d);
  }
  m.values = image.rgb.size();
  if (m.values) {
    m.rel_mse = rel / m.values;
    m.mse = sq / m.values;
    m.mae = abs_sum / m.values;
  }
  return m;
}

ZTest z_test(const RgbImage& a, const RgbImage& var_a, const RgbImage& b, const RgbImage& var_b,
             const ZTestRule& rule) {
  check_same_size(a, b, "z-test");
  check_same_size(a, var_a, "z-test (variance image of the first render)");
  check_same_size(b, var_b, "z-test (variance image of the second render)");
  ZTest t;
  double sum_z = 0.0, sum_z2 = 0.0;
  size_t over3 = 0, over4 = 0;
  for (size_t k = 0; k < a.rgb.size(); ++k) {
    double va = var_a.rgb[k], vb = var_b.rgb[k], d = double(a.rgb[k]) - b.rgb[k];
    double v = va + vb;
    if (!std::isfinite(v)) {
      ++t.undefined;
      continue;
    }
    double scale = std::max(std::abs(double(a.rgb[k])), std::abs(double(b.rgb[k])));
    if (!(v > 1e-12 * scale * scale)) {
      // A pixel without noise (an emitter seen directly, the background, a white furnace):
      // the two renders should agree to float rounding. A variance at rounding level (a
      // standard deviation below 1e-6 of the value: samples equal but for their last bits)
      // counts as none; dividing a 1-ulp difference by it would give a huge z.
      ++t.zero_variance;
      if (std::abs(d) > 1e-5 * scale + 1e-7) ++t.zero_variance_mismatch;
      continue;
    }
    double z = d / std::sqrt(v);
    ++t.values;
    sum_z += z;
    sum_z2 += z * z;
    if (std::abs(z) > 3) ++over3;
    if (std::abs(z) > 4) ++over4;
    t.max_abs_z = std::max(t.max_abs_z, std::abs(z));
  }
  if (t.values) {
    double n = double(t.values);
    t.mean_z = sum_z / n;
    t.mean_z2 = sum_z2 / n;
    t.frac_over_3 = over3 / n;
    t.frac_over_4 = over4 / n;
    t.count_over_4 = over4;

    char buf[200];
    double z2_limit = 1.0 + rule.z2_slack + 4.0 * std::sqrt(2.0 / n);
    if (t.mean_z2 > z2_limit) {
      std::snprintf(buf, sizeof buf, "mean z^2 = %.3f exceeds %.3f", t.mean_z2, z2_limit);
      t.reasons.push_back(buf);
    }
    double bias_limit = 4.0 / std::sqrt(n / 3.0);
    if (std::abs(t.mean_z) > bias_limit) {
      std::snprintf(buf, sizeof buf, "mean z = %.4f: |mean z| exceeds %.4f (a bias)", t.mean_z, bias_limit);
      t.reasons.push_back(buf);
    }
    double expected4 = rule.tail_allowance * n * std::erfc(4.0 / std::sqrt(2.0));
    double tail_limit = expected4 + 4.0 * std::sqrt(expected4) + 3.0;
    if (double(over4) > tail_limit) {
      std::snprintf(buf, sizeof buf, "%zu values with |z| > 4, more than %.1f", over4, tail_limit);
      t.reasons.push_back(buf);
    }
  } else {
    t.reasons.push_back("no pixel-channel with a finite, positive variance (render at least 2 spp)");
  }
  if (t.zero_variance_mismatch) {
    t.reasons.push_back(std::to_string(t.zero_variance_mismatch) +
                        " noise-free pixel-channels differ beyond float rounding");
  }
  t.consistent = t.reasons.empty();
  return t;
}

SameSeedDiff same_seed_diff(const RgbImage& a, const RgbImage& b) {
  check_same_size(a, b, "same-seed comparison");
  SameSeedDiff s;
  size_t identical = 0;
  for (size_t k = 0; k < a.rgb.size(); ++k) {
    double x = a.rgb[k], y = b.rgb[k], d = std::abs(x - y);
    if (x == y) ++identical;
    s.max_abs = std::max(s.max_abs, d);
    double scale = std::max(std::abs(x), std::abs(y));
    if (scale > 0) s.max_rel = std::max(s.max_rel, d / scale);
  }
  s.identical_fraction = a.rgb.empty() ? 1.0 : double(identical) / a.rgb.size();
  return s;
}

}  // namespace candela
