// The render's progress bar on stderr: redrawn in place on a terminal, elsewhere (logs, CI)
// a line every 10 seconds.
#pragma once

#include "render/renderer.hpp"

namespace candela {

class ProgressBar {
 public:
  ProgressBar(bool enabled, double pixels);
  // With several devices, each one's share of the samples follows the line
  void show_device_shares(bool on) { shares_ = on; }
  void update(const RenderProgress& p);
  void finish();  // ends the line a terminal bar was drawn on

 private:
  bool enabled_, terminal_;
  bool shares_ = false;
  double pixels_;
  double next_line_ = 10.0;
  bool drawn_ = false;
};

}  // namespace candela
