// Pixel filters, importance-sampled: a film sample lands at an offset from the pixel
// centre drawn with the filter's density, so that a pixel's unweighted mean of samples
// is the image convolved with the filter (no weights, no negative lobes, no splatting).

// Inverse CDF of the tent 1 - |x| on [-1, 1]
float filter_tent_offset(float u) { return u < 0.5f ? sqrt(2.0f * u) - 1.0f : 1.0f - sqrt(2.0f - 2.0f * u); }

// Where in pixel (0, 0) .. (1, 1) a sample lands (the offset from the centre is this
// minus 1/2; tent and Gaussian reach into neighbouring pixels), from two uniforms in [0, 1)
float2 filter_sample(uint filter, float u, float v) {
  if (filter == FILTER_TENT) return (float2)(0.5f + filter_tent_offset(u), 0.5f + filter_tent_offset(v));
  if (filter == FILTER_GAUSSIAN) {
    // Box-Muller with sigma = 1/2: a radius with density r exp(-r^2 / (2 sigma^2)) / sigma^2
    // and a uniform angle give two independent normal offsets. 1 - u > 0 keeps the log
    // finite; 24-bit uniforms reach at most 5.8 sigma (2.9 pixels), so no truncation.
    float r = 0.5f * sqrt(-2.0f * log(1.0f - u));
    float cos_phi, sin_phi = sincos_turn(v, &cos_phi);
    return (float2)(0.5f + r * cos_phi, 0.5f + r * sin_phi);
  }
  return (float2)(u, v);  // FILTER_BOX: today's uniform jitter, bit for bit
}
