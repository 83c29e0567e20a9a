// Emission profiles of lights shared by host and device (the host includes this file inside
// namespace candela::dev): the kernel samples with them, and the host's estimates of what a
// light sends (host/scene/default_light.cpp) use the same functions.

#ifndef CANDELA_LIGHT_PROFILES_H
#define CANDELA_LIGHT_PROFILES_H

#ifdef __OPENCL_C_VERSION__
#define CD_CLAMP clamp
#else
#define CD_CLAMP std::clamp
#endif

// KHR_lights_punctual's spot cone profile at cosine `cos_axis` from the axis: t^2, t
// interpolating the cosine linearly from cos(outer) (t = 0) to cos(inner) (t = 1), with
// the extension's scale 1 / max(0.001, cos(inner) - cos(outer)) and offset -cos(outer) x
// scale (SpotLight.cone_scale, cone_offset)
static inline float spot_profile(float cos_axis, float scale, float offset) {
  float t = CD_CLAMP(cos_axis * scale + offset, 0.0f, 1.0f);
  return t * t;
}

#endif  // CANDELA_LIGHT_PROFILES_H
