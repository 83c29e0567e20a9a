// Denoising with Intel Open Image Denoise (OIDN), loaded at run time: candela has no
// link-time dependency on it. The library is looked for, in this order:
//   1. CANDELA_OIDN_LIBRARY, a path (then nothing else is tried),
//   2. oidn/lib/libOpenImageDenoise.so.2 beside the executable (where scripts/setup.sh puts it),
//   3. libOpenImageDenoise.so.2 through the system loader's search path.
#pragma once

#include <string>
#include <vector>

#include "base/enum_names.hpp"
#include "render/film.hpp"

namespace candela {

// OIDN's quality levels (its OIDN_QUALITY_* values)
enum class DenoiseQuality : int { Fast = 4, Balanced = 5, High = 6 };

inline constexpr EnumName<DenoiseQuality> kDenoiseQualityNames[] = {
    {DenoiseQuality::Fast, "fast", ""}, {DenoiseQuality::Balanced, "balanced", ""}, {DenoiseQuality::High, "high", ""}};

// Loads the library (once); throws Error("--denoise needs Open Image Denoise: WHY (run
// scripts/setup.sh)") when it cannot
void load_denoiser();

struct DenoiseResult {
  std::vector<float> rgb;  // 3 per pixel
  double seconds = 0.0;    // guides' prefiltering and the beauty's filter, with the copies
  std::string device;      // "CPU", "CUDA", ...
};

// The RT filter on the film's RGB (linear radiance, hdr) guided by its albedo and normal
// AOVs, each prefiltered first (OIDN's "clean aux" workflow). `prefer_gpu`: OIDN picks its
// device (a GPU it supports, else the CPU); otherwise the CPU. Throws Error when OIDN fails.
DenoiseResult denoise_film(const Film& film, DenoiseQuality quality, bool prefer_gpu);

}  // namespace candela
