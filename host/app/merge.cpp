// `candela merge` (merge.hpp): shards of one render checked against each other and merged.
#include "app/merge.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

#include "app/report.hpp"
#include "base/atomic_file.hpp"
#include "base/error.hpp"
#include "render/aov.hpp"
#include "render/film.hpp"
#include "render/image_stats.hpp"

namespace candela {

namespace {

bool partial(const RgbImage& img) {
  auto it = img.metadata.find("partial_pass");
  return it != img.metadata.end() && it->second == "1";
}

bool ends_with_exr(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".exr";
}

uint64_t parse_count(const std::string& path, const std::string& key, const std::string& text) {
  size_t used = 0;
  unsigned long long v = 0;
  try {
    v = std::stoull(text, &used);
  } catch (...) {
    used = 0;
  }
  if (used == 0 || used != text.size() || text[0] == '-')
    throw Error("cannot merge: " + path + " has a malformed candela:" + key + " '" + text + "'");
  return v;
}

SampleRanges ranges_of(const RgbImage& img, const std::string& path, uint64_t spp) {
  SampleRanges out;
  auto it = img.metadata.find("sample_ranges");
  if (it != img.metadata.end()) {
    std::string text = it->second;
    size_t pos = 0;
    uint64_t total = 0;
    while (pos <= text.size()) {
      size_t comma = text.find(',', pos);
      std::string item = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
      size_t colon = item.find(':');
      if (colon == std::string::npos)
        throw Error("cannot merge: " + path + " has a malformed candela:sample_ranges '" + text + "'");
      uint64_t b = parse_count(path, "sample_ranges", item.substr(0, colon));
      uint64_t e = parse_count(path, "sample_ranges", item.substr(colon + 1));
      if (e <= b) throw Error("cannot merge: " + path + " has a malformed candela:sample_ranges '" + text + "'");
      out.emplace_back(b, e);
      total += e - b;
      if (comma == std::string::npos) break;
      pos = comma + 1;
    }
    // A render stopped inside a range holds whole passes (spp) and part of one more
    if (total != spp && !(partial(img) && total > spp))
      throw Error("cannot merge: " + path + ": candela:sample_ranges holds " + std::to_string(total) +
                  " samples, candela:spp says " + std::to_string(spp));
    return out;
  }
  uint64_t offset = 0;
  if (auto o = img.metadata.find("sample_offset"); o != img.metadata.end())
    offset = parse_count(path, "sample_offset", o->second);
  out.emplace_back(offset, offset + spp);
  return out;
}

std::string format_range(const std::pair<uint64_t, uint64_t>& r) {
  return "[" + std::to_string(r.first) + ", " + std::to_string(r.second) + ")";
}

struct Input {
  std::string path;
  RgbImage img;
  uint64_t spp;
  SampleRanges ranges;
};

Input read_input(const std::string& path) {
  if (!ends_with_exr(path)) throw Error("cannot merge " + path + ": merge reads .exr images written by candela render");
  Input x{path, read_rgb_image(path, "image"), 0, {}};
  if (!x.img.metadata.count("spp"))
    throw Error("cannot merge " + path +
                ": no candela metadata (candela:spp); merge reads .exr images written by candela render");
  if (auto it = x.img.metadata.find("image"); it != x.img.metadata.end())
    throw Error("cannot merge " + path + ": it is a " + it->second + " image, not a render");
  if (auto it = x.img.metadata.find("noise_threshold"); it != x.img.metadata.end() && it->second != "off")
    throw Error("cannot merge " + path + ": an adaptive render (candela:noise_threshold " + it->second +
                "), whose pixels hold different sample counts");
  x.spp = parse_count(path, "spp", x.img.metadata.at("spp"));
  if (x.spp == 0) throw Error("cannot merge " + path + ": it holds no complete pass of samples (candela:spp 0)");
  x.ranges = ranges_of(x.img, path, x.spp);
  return x;
}

// Same size as the first input, and the same metadata where a render's must match
// (report.hpp: must_match_keys; camera and lighting are fingerprints of the device camera
// and of the background and environment: the inputs are then samples of the same estimator)
void check_same_render(const Input& first, const Input& x) {
  if (x.img.width != first.img.width || x.img.height != first.img.height)
    throw Error("cannot merge: " + x.path + " is " + std::to_string(x.img.width) + "x" + std::to_string(x.img.height) +
                ", " + first.path + " is " + std::to_string(first.img.width) + "x" + std::to_string(first.img.height));
  for (const std::string& key : must_match_keys()) {
    auto a = first.img.metadata.find(key), b = x.img.metadata.find(key);
    std::string va = a == first.img.metadata.end() ? "(none)" : a->second;
    std::string vb = b == x.img.metadata.end() ? "(none)" : b->second;
    if (va != vb)
      throw Error("cannot merge: different " + key + ": " + first.path + " has '" + va + "', " + x.path + " has '" +
                  vb + "'");
  }
}

// Every input's sample ranges (with the input's index), sorted; Error unless disjoint
std::vector<std::pair<std::pair<uint64_t, uint64_t>, size_t>> disjoint_ranges(const std::vector<Input>& in) {
  std::vector<std::pair<std::pair<uint64_t, uint64_t>, size_t>> all;
  for (size_t i = 0; i < in.size(); ++i)
    for (const auto& r : in[i].ranges) all.push_back({r, i});
  std::sort(all.begin(), all.end());
  for (size_t k = 1; k < all.size(); ++k)
    if (all[k].first.first < all[k - 1].first.second)
      throw Error("cannot merge: overlapping sample ranges: " + in[all[k - 1].second].path + " holds " +
                  format_range(all[k - 1].first) + ", " + in[all[k].second].path + " holds " +
                  format_range(all[k].first) + " (give each shard its own --sample-offset)");
  return all;
}

// Where an AOV channel goes in Film::aov (render/aov.hpp), -1 for spp.Y (summed), -2: none
int aov_slot(const std::string& name) {
  const char* names[] = {"albedo.R", "albedo.G", "albedo.B", "A", "normal.X", "normal.Y", "normal.Z", "depth.Z"};
  for (int k = 0; k < 8; ++k)
    if (name == names[k]) return k;
  return name == "spp.Y" ? -1 : -2;
}

// Weighted mean per pixel, in double; the AOV channels (the same in every input: --aov must
// match) alike, and spp.Y summed
Film merged_film(const std::vector<Input>& in, uint64_t total) {
  Film film(in.front().img.width, in.front().img.height);
  const std::vector<std::string>& names = in.front().img.extra_names;
  bool any_aov = false;
  for (const auto& name : names) any_aov = any_aov || aov_slot(name) >= 0;
  if (any_aov) film.aov.assign(film.pixels() * 8, 0.0f);
  for (size_t p = 0; p < film.pixels(); ++p) {
    for (int c = 0; c < 3; ++c) {
      double sum = 0.0;
      for (const auto& x : in) sum += double(x.spp) * x.img.rgb[3 * p + c];
      film.mean[4 * p + c] = float(sum / double(total));
    }
    film.mean[4 * p + 3] = float(total);
    for (size_t k = 0; k < names.size(); ++k) {
      int slot = aov_slot(names[k]);
      if (slot == -2) continue;
      double sum = 0.0;
      for (const auto& x : in) {
        size_t at = std::find(x.img.extra_names.begin(), x.img.extra_names.end(), names[k]) - x.img.extra_names.begin();
        float v = at < x.img.extra_names.size() ? x.img.extra[p * x.img.extra_names.size() + at] : 0.0f;
        sum += slot < 0 ? double(v) : double(x.spp) * v;
      }
      if (slot < 0)
        film.mean[4 * p + 3] = float(sum);
      else
        film.aov[8 * p + size_t(slot)] = float(sum / double(total));
    }
  }
  return film;
}

// The inputs' AOVs and transparency, from their metadata (the first's: they must match)
ImageLayers merged_layers(const std::map<std::string, std::string>& meta) {
  ImageLayers layers;
  auto aov = meta.find("aov");
  if (aov != meta.end() && aov->second != "none") layers.aovs = parse_aov_list(aov->second);
  auto transparent = meta.find("transparent");
  layers.transparent = transparent != meta.end() && transparent->second == "on";
  return layers;
}

// "B:E,B:E": the sorted ranges, adjacent ones coalesced; *first gets the first index
std::string ranges_text(const std::vector<std::pair<std::pair<uint64_t, uint64_t>, size_t>>& all, uint64_t* first) {
  SampleRanges merged;
  for (const auto& [r, i] : all) {
    if (!merged.empty() && merged.back().second == r.first)
      merged.back().second = r.second;
    else
      merged.push_back(r);
  }
  std::string text;
  for (const auto& r : merged)
    text += (text.empty() ? "" : ",") + std::to_string(r.first) + ":" + std::to_string(r.second);
  *first = merged.front().first;
  return text;
}

// The first input's metadata with the merged counts: seconds and dropped samples summed,
// each device once
std::map<std::string, std::string> merged_metadata(const std::vector<Input>& in, uint64_t total) {
  std::map<std::string, std::string> meta = in.front().img.metadata;
  double seconds = 0.0;
  uint64_t dropped = 0;
  std::vector<std::string> devices;
  for (const auto& x : in) {
    if (auto it = x.img.metadata.find("seconds"); it != x.img.metadata.end()) seconds += std::atof(it->second.c_str());
    if (auto it = x.img.metadata.find("dropped_samples"); it != x.img.metadata.end())
      dropped += std::strtoull(it->second.c_str(), nullptr, 10);
    if (auto it = x.img.metadata.find("device");
        it != x.img.metadata.end() && std::find(devices.begin(), devices.end(), it->second) == devices.end())
      devices.push_back(it->second);
  }
  std::string device_text;
  for (const auto& d : devices) device_text += (device_text.empty() ? "" : " + ") + d;
  meta["spp"] = std::to_string(total);
  meta["seconds"] = std::to_string(seconds);
  meta["dropped_samples"] = std::to_string(dropped);
  meta["device"] = device_text;
  meta["merged_from"] = std::to_string(in.size());
  meta.erase("partial_pass");
  meta["denoise"] = "off";  // merged from the inputs' unbiased estimates, not denoised
  for (const auto& x : in)
    if (partial(x.img)) meta["partial_pass"] = "1";
  return meta;
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  return std::filesystem::equivalent(a, b, ec);
}

}  // namespace

int run_merge(const MergeArgs& args) {
  if (args.inputs.size() < 2) throw Error("merge needs at least two input images");
  if (!ends_with_exr(args.output)) throw Error("merge writes an .exr (linear float with metadata): " + args.output);
  check_writable_path(args.output);
  for (const auto& path : args.inputs)
    if (same_file(path, args.output)) throw Error("cannot merge: the output " + args.output + " is one of the inputs");
  std::vector<Input> in;
  for (const auto& path : args.inputs) in.push_back(read_input(path));
  for (size_t i = 1; i < in.size(); ++i) check_same_render(in.front(), in[i]);
  auto all = disjoint_ranges(in);
  uint64_t total = 0;
  for (const auto& x : in) total += x.spp;
  if (total > (uint64_t(1) << 32)) throw Error("cannot merge: more than 2^32 samples per pixel");
  Film film = merged_film(in, total);
  std::map<std::string, std::string> meta = merged_metadata(in, total);
  uint64_t first_index = 0;
  std::string ranges = ranges_text(all, &first_index);
  meta["sample_offset"] = std::to_string(first_index);
  meta["sample_ranges"] = ranges;
  write_image(args.output, film, meta, {}, merged_layers(meta));
  std::printf("wrote %s\n", args.output.c_str());
  if (!args.quiet)
    std::printf("merged %zu images: %llu spp, sample indices %s\n", in.size(), (unsigned long long)total,
                ranges.c_str());
  return 0;
}

}  // namespace candela
