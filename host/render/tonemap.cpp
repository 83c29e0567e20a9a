#include "render/tonemap.hpp"

#include <algorithm>
#include <cmath>

#include "base/error.hpp"

namespace candela {

Tonemap parse_tonemap(const std::string& name) {
  if (auto t = enum_value(kTonemapNames, name)) return *t;
  throw Error("--tonemap must be " + enum_names(kTonemapNames) + ", not '" + name + "'");
}

glm::vec3 tonemap_pbr_neutral(glm::vec3 c) {
  // Published constants: compression starts at 0.8 - 0.04, desaturation 0.15
  const float start = 0.76f, desaturation = 0.15f;
  // Toe: a small offset removes the flare of near-black colours
  float low = std::min({c.r, c.g, c.b});
  float offset = low < 0.08f ? low - 6.25f * low * low : 0.04f;
  c -= offset;
  float peak = std::max({c.r, c.g, c.b});
  if (peak < start) return glm::max(c, glm::vec3(0.0f));
  // Highlights: the peak is compressed toward 1 and the colour desaturated as it goes
  const float d = 1.0f - start;
  float new_peak = 1.0f - d * d / (peak + d - start);
  c *= new_peak / peak;
  float g = 1.0f - 1.0f / (desaturation * (peak - new_peak) + 1.0f);
  return glm::mix(c, glm::vec3(new_peak), g);
}

namespace {

// m v, m given by rows
glm::vec3 mul(const float m[3][3], glm::vec3 v) {
  return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z, m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
          m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
}

// Linear sRGB <-> linear Rec. 2020 (ITU-R BT.2087)
constexpr float kSrgbToRec2020[3][3] = {
    {0.6274040f, 0.3292820f, 0.0433136f}, {0.0690970f, 0.9195400f, 0.0113612f}, {0.0163916f, 0.0880132f, 0.8955950f}};
constexpr float kRec2020ToSrgb[3][3] = {{1.6604903f, -0.5876391f, -0.0728516f},
                                        {-0.1245500f, 1.1328999f, -0.0083480f},
                                        {-0.0181511f, -0.1005787f, 1.1187299f}};
// AgX inset and outset matrices (rows), in Rec. 2020
constexpr float kAgxInset[3][3] = {{0.856627153315983f, 0.0951212405381588f, 0.0482516061458583f},
                                   {0.137318972929847f, 0.761241990602591f, 0.101439036467562f},
                                   {0.11189821299995f, 0.0767994186031903f, 0.811302368396859f}};
constexpr float kAgxOutset[3][3] = {{1.1271005818144368f, -0.11060664309660323f, -0.016493938717834573f},
                                    {-0.1413297634984383f, 1.157823702216272f, -0.016493938717834257f},
                                    {-0.14132976349843826f, -0.11060664309660294f, 1.2519364065950405f}};
constexpr float kAgxMinEv = -12.47393f, kAgxMaxEv = 4.026069f;

// Polynomial fit of AgX's default contrast sigmoid on the log-encoded value in [0, 1]
float agx_contrast(float x) {
  float x2 = x * x, x4 = x2 * x2;
  return 15.5f * x4 * x2 - 40.14f * x4 * x + 31.96f * x4 - 6.868f * x2 * x + 0.4298f * x2 + 0.1191f * x - 0.00232f;
}

}  // namespace

glm::vec3 tonemap_agx(glm::vec3 c) {
  glm::vec3 v = mul(kAgxInset, mul(kSrgbToRec2020, glm::max(c, glm::vec3(0.0f))));
  for (int k = 0; k < 3; ++k) {
    float ev = std::log2(std::max(v[k], 1e-10f));
    float x = std::clamp((ev - kAgxMinEv) / (kAgxMaxEv - kAgxMinEv), 0.0f, 1.0f);
    v[k] = agx_contrast(x);
  }
  v = mul(kAgxOutset, v);
  // The curve's output is display-encoded with gamma 2.2: back to linear, then to sRGB primaries
  for (int k = 0; k < 3; ++k) v[k] = std::pow(std::max(v[k], 0.0f), 2.2f);
  return glm::clamp(mul(kRec2020ToSrgb, v), 0.0f, 1.0f);
}

glm::vec3 tonemap_apply(Tonemap t, glm::vec3 c) {
  // A NaN or negative channel (none reach the film, but a merged or edited one might) is black
  for (int k = 0; k < 3; ++k)
    if (!(c[k] > 0.0f)) c[k] = 0.0f;
  switch (t) {
    case Tonemap::Neutral:
      return glm::clamp(tonemap_pbr_neutral(c), 0.0f, 1.0f);
    case Tonemap::Agx:
      return tonemap_agx(c);
    case Tonemap::Clamp:
      break;
  }
  return glm::clamp(c, 0.0f, 1.0f);
}

}  // namespace candela
