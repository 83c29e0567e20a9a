#include "render/aov.hpp"

#include <algorithm>
#include <filesystem>

#include "base/error.hpp"

namespace candela {

uint32_t parse_aov_list(const std::string& list) {
  uint32_t set = 0;
  size_t pos = 0;
  while (pos <= list.size()) {
    size_t comma = list.find(',', pos);
    std::string name = list.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    auto a = enum_value(kAovNames, name);
    if (!a) throw Error("--aov: unknown AOV '" + name + "' (the AOVs: " + enum_names(kAovNames) + ")");
    set |= aov_bit(*a);
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  return set;
}

std::string aov_list_text(uint32_t set) {
  std::string s;
  for (const auto& row : kAovNames)
    if (set & aov_bit(row.value)) s += (s.empty() ? "" : ",") + std::string(row.name);
  return s.empty() ? "none" : s;
}

namespace {
std::string lower_extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (auto& ch : ext) ch = char(std::tolower((unsigned char)ch));
  return ext;
}
}  // namespace

OutputSpec parse_output(const std::string& out) {
  size_t colon = out.rfind(':');
  if (colon == std::string::npos || out.find('/', colon) != std::string::npos) return {out, 0};
  std::string path = out.substr(0, colon), name = out.substr(colon + 1), ext = lower_extension_of(path);
  bool image = ext == ".png" || ext == ".jpg" || ext == ".jpeg";
  auto a = enum_value(kAovNames, name);
  if (ext == ".exr" && a)
    throw Error("-o " + out + ": an .exr holds every AOV of --aov as channels; FILE:NAME is for .png and .jpg");
  if (!image) return {out, 0};
  if (!a) throw Error("-o " + out + ": unknown AOV '" + name + "' (the AOVs: " + enum_names(kAovNames) + ")");
  return {path, aov_bit(*a)};
}

float film_alpha(const Film& film, size_t i) {
  return film.aov.empty() ? 1.0f : std::clamp(film.aov[8 * i + 3], 0.0f, 1.0f);
}

void aov_channels(const Film& film, uint32_t set, bool transparent, std::vector<std::string>* names,
                  std::vector<float>* values) {
  names->clear();
  std::vector<int> from;  // per channel: index into the pixel's 8 AOV floats, or -1: spp
  if (transparent || (set & aov_bit(Aov::Alpha))) names->push_back("A"), from.push_back(3);
  if (set & aov_bit(Aov::Albedo))
    for (int c = 0; c < 3; ++c) names->push_back(std::string("albedo.") + "RGB"[c]), from.push_back(c);
  if (set & aov_bit(Aov::Normal))
    for (int c = 0; c < 3; ++c) names->push_back(std::string("normal.") + "XYZ"[c]), from.push_back(4 + c);
  if (set & aov_bit(Aov::Depth)) names->push_back("depth.Z"), from.push_back(7);
  if (set & aov_bit(Aov::Spp)) names->push_back("spp.Y"), from.push_back(-1);
  values->assign(film.pixels() * from.size(), 0.0f);
  for (size_t i = 0; i < film.pixels(); ++i)
    for (size_t k = 0; k < from.size(); ++k) {
      float v = 0.0f;
      if (from[k] < 0)
        v = film.samples_taken(i);
      else if (!film.aov.empty())
        v = film.aov[8 * i + size_t(from[k])];
      (*values)[i * from.size() + k] = v;
    }
}

std::vector<float> aov_display(const Film& film, Aov a) {
  std::vector<float> rgb(film.pixels() * 3, 0.0f);
  float largest = 0.0f;
  for (size_t i = 0; i < film.pixels(); ++i) {
    if (a == Aov::Depth && !film.aov.empty()) largest = std::max(largest, film.aov[8 * i + 7]);
    if (a == Aov::Spp) largest = std::max(largest, film.samples_taken(i));
  }
  for (size_t i = 0; i < film.pixels(); ++i) {
    const float* v = film.aov.empty() ? nullptr : &film.aov[8 * i];
    for (int c = 0; c < 3; ++c) {
      float x = 0.0f;
      switch (a) {
        case Aov::Albedo: x = v ? linear_to_srgb(v[c]) : 0.0f; break;
        case Aov::Normal: x = v ? 0.5f + 0.5f * v[4 + c] : 0.5f; break;
        case Aov::Depth: x = v && largest > 0.0f ? v[7] / largest : 0.0f; break;
        case Aov::Alpha: x = film_alpha(film, i); break;
        case Aov::Spp: x = largest > 0.0f ? film.samples_taken(i) / largest : 0.0f; break;
      }
      rgb[3 * i + c] = std::clamp(x, 0.0f, 1.0f);
    }
  }
  return rgb;
}

}  // namespace candela
