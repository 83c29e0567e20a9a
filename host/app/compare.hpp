// `candela compare`: renders one scene on several devices and tests, against the first
// device, whether the images agree within their measured noise (README, "Speed against
// accuracy"). Each render is a `candela render` child process, so every render option
// applies unchanged and each device starts from its own empty kernel caches.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace candela {

struct CompareArgs {
  std::string scene;
  std::vector<std::string> devices;  // selectors, as --device takes them
  uint32_t spp = 64;
  int width = 64, height = 0;  // height 0: from the camera's aspect ratio
  uint32_t seed = 0;
  bool same_seed = false;                   // every device renders seed `seed` (breaks the z-test's independence)
  bool determinism_check = true;            // also render the first device's seed on the others
  std::vector<std::string> device_args;     // "I:OPTIONS": extra render options for device I
  std::vector<std::string> render_options;  // passed to every render
  std::string json;                         // write the results here
  std::string keep;                         // keep the images in this directory
  bool quiet = false;
};

// The path of this candela executable (for child renders)
std::string self_executable();

// Returns the exit status: 0 when every device is consistent with the first, 2 when one
// is not; throws Error for bad input or a failed render
int run_compare(const CompareArgs& args);

}  // namespace candela
