// Frame sequences (`render --frames A:B[:STEP]`): the frames asked for and the output path of
// each, from a pattern whose run of '#' takes the frame number.
#pragma once

#include <string>
#include <vector>

namespace candela {

// "A:B" or "A:B:STEP": the frames A, A + STEP, ... up to B (integers, 0 <= A <= B, STEP >= 1,
// at most 10^6 frames); Error naming --frames otherwise
std::vector<long> parse_frames(const std::string& text);

// Whether `path` holds a run of '#' (in its file name)
bool has_frame_pattern(const std::string& path);

// `path` with the last run of '#' in its file name replaced by the frame number, zero-padded
// to the run's length (a number with more digits kept whole): fox_####.png, 7 -> fox_0007.png
std::string frame_path(const std::string& path, long frame);

// Whether a frame's output `path` was written whole: it exists and, where its metadata tell
// (EXR, PNG), the render was not stopped inside a pass nor before `spp` samples (0: unknown)
bool frame_written(const std::string& path, unsigned spp);

}  // namespace candela
