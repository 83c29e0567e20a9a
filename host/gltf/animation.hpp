// glTF animation samplers (specification 3.11): a channel's keys and their value at a time.
// animation.cpp poses a document with them (reader.hpp: pose_animations).
#pragma once

#include <cstddef>
#include <vector>

namespace candela::gltf {

enum class Interpolation { Step, Linear, CubicSpline };

// One sampler's keys: non-decreasing times (seconds) and, per key, `width` floats; a
// CUBICSPLINE key holds three such groups: in-tangent, value, out-tangent
struct AnimationCurve {
  std::vector<float> times;
  std::vector<float> values;
  size_t width = 0;
  Interpolation interpolation = Interpolation::Linear;
};

// The curve's value at time t (`width` floats): the first key's before it, the last key's
// after it; STEP holds a key's value until the next key; LINEAR interpolates linearly, or,
// with `rotation` (unit quaternions x, y, z, w), spherically along the shorter arc;
// CUBICSPLINE is the Hermite spline with the tangents scaled by the key interval (a rotation
// then normalized)
std::vector<float> sample_curve(const AnimationCurve& curve, double t, bool rotation);

}  // namespace candela::gltf
