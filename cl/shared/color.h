// Colour helpers shared by host and device (the host includes this file inside
// namespace candela::dev): one luminance and one sRGB decode for both sides.

#ifndef CANDELA_COLOR_H
#define CANDELA_COLOR_H

#ifdef __OPENCL_C_VERSION__
#define CD_POWF pow
#else
#define CD_POWF std::pow
#endif

// Relative luminance of linear Rec. 709 / sRGB primaries
static inline float luminance_rgb(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

// sRGB transfer function to linear (IEC 61966-2-1)
static inline float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : CD_POWF((c + 0.055f) / 1.055f, 2.4f);
}

#endif  // CANDELA_COLOR_H
