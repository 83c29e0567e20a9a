// Whether a scene is lit by its own lights, or needs the built-in environment a viewer would
// give it: glTF assets carry no environment, and their emissive textures (screens, labels,
// visors) are not meant to light them.
#pragma once

#include <optional>
#include <string>

#include "base/enum_names.hpp"
#include "scene/scene.hpp"

namespace candela {

enum class DefaultLight { Auto, On, Off };
inline constexpr EnumName<DefaultLight> kDefaultLightNames[] = {
    {DefaultLight::Auto, "auto",
     "default: when the scene sets no environment or background and its own lights give under 10 % of the light "
     "on its surfaces"},
    {DefaultLight::On, "on", ""},
    {DefaultLight::Off, "off", ""}};

struct DefaultLightChoice {
  bool use_environment = false;
  double own_share = 0.0;  // own_light_share of the scene (Auto with own lights only)
  std::string reason;      // one line for the user
};

// The share of the light on the scene's surfaces that its own lights give, against the
// built-in environment: the median, over points spread over its non-emissive surfaces by
// area (a fixed pseudo-random set), of E_own(p) / E_env, with E_own the irradiance its
// lights give p on its brighter side and E_env = pi x the environment's mean radiance.
// Its lights are the punctual lights and the emitters brighter than white (radiance > 1,
// which glTF reaches only through KHR_materials_emissive_strength): emission up to white
// is a glowing material (a screen, a label, a visor) that no glTF viewer lets light
// anything. The share is 0 when emissive surfaces cover at least half of the scene (the
// asset is its glowing parts). Occlusion is left out (both lights would be shadowed alike), which keeps
// it cheap: O(points x lights), emitters subsampled by power beyond a few thousand.
struct OwnLight {
  bool lights = false;           // the scene has lights by the rule above
  bool mostly_emissive = false;  // emissive surfaces cover at least half of it
  double share = 0.0;
};
OwnLight own_light_share(const Scene& scene, double environment_radiance);

// Below this share the scene's own lights are decorative and the environment lights it
// (docs/lights.md, Default lighting, has the measurements behind it)
constexpr double kOwnLightShareThreshold = 0.10;

// The automatic exposure of PNG/JPEG outputs (render without --exposure): a scene lit by
// its own lights far brighter than the studio (a sun given in lux, read photometrically) is
// exposed as if its surfaces had the studio's light: -log2(own_share) stops, to 0.1 stop,
// when its own lights give over kAutoExposureShare times the studio's light (two stops
// over); nullopt (exposure 0) otherwise, and whenever the studio or the scene's own
// environment lights it.
constexpr double kAutoExposureShare = 4.0;
std::optional<float> automatic_exposure(const DefaultLightChoice& c);

// The rule of --default-light (docs/lights.md): a scene that sets its own environment or
// background (scene extras, --env, --background) keeps it; otherwise Off keeps it as it is,
// On adds the built-in environment, and Auto adds it when the scene has no light or its own
// lights' share is below kOwnLightShareThreshold.
DefaultLightChoice choose_default_light(const Scene& scene, DefaultLight mode, bool environment_given,
                                        double environment_radiance);

}  // namespace candela
