// Arbitrary output variables: their names, the --aov list, the `-o FILE.png:NAME` outputs,
// and how each becomes image channels (cl/integrator/aov.cl computes them; Film::aov holds
// their means).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "base/enum_names.hpp"
#include "render/film.hpp"

namespace candela {

// Bits of a set of AOVs
enum class Aov : uint32_t { Albedo = 1, Normal = 2, Depth = 4, Alpha = 8, Spp = 16 };

inline constexpr EnumName<Aov> kAovNames[] = {{Aov::Albedo, "albedo", "albedo.R/G/B"},
                                              {Aov::Normal, "normal", "normal.X/Y/Z"},
                                              {Aov::Depth, "depth", "depth.Z"},
                                              {Aov::Alpha, "alpha", "A"},
                                              {Aov::Spp, "spp", "spp.Y"}};

inline uint32_t aov_bit(Aov a) { return uint32_t(a); }
// Whether the set needs the kernel's AOVs (CD_AOV): all but spp, which is the film's count
inline bool aovs_need_kernel(uint32_t set) { return (set & ~aov_bit(Aov::Spp)) != 0; }

// "albedo,normal" -> the set; Error naming the choices for an unknown name
uint32_t parse_aov_list(const std::string& list);
// The set as a list in the table's order ("none" when empty)
std::string aov_list_text(uint32_t set);

// An output argument: FILE, or FILE.png:NAME (FILE.jpg:NAME), one AOV as an 8-bit image
struct OutputSpec {
  std::string path;
  uint32_t aov = 0;  // one bit, or 0: the image
};
// Error for an unknown NAME, or a NAME after an .exr (whose channels hold every AOV)
OutputSpec parse_output(const std::string& out);

// The EXR channels of the set (`transparent`: A too): names, and the values per pixel
void aov_channels(const Film& film, uint32_t set, bool transparent, std::vector<std::string>* names,
                  std::vector<float>* values);

// One AOV as 8-bit-ready RGB in [0, 1] per pixel (docs/cli.md, Outputs): albedo
// sRGB-encoded, normal 0.5 + 0.5 n, depth / the largest depth, alpha, spp / the largest count
std::vector<float> aov_display(const Film& film, Aov a);

// The pixel's alpha from the film's AOVs, in [0, 1]
float film_alpha(const Film& film, size_t i);

}  // namespace candela
