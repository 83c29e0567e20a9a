// Whether a scene is lit by its own lights, or needs the built-in environment a viewer would
// give it: glTF assets carry no environment, and their emissive textures (screens, labels,
// visors) are not meant to light them.
#pragma once

#include <optional>
#include <string>
#include <vector>

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

// Whether PNG/JPEG outputs get an automatic exposure (render without --exposure): a scene lit
// by its own lights far brighter than the studio (a sun given in lux, read photometrically),
// over kAutoExposureShare times the studio's light (two stops over); nullopt (exposure 0)
// otherwise, and whenever the studio or the scene's own environment lights it. The value,
// -log2(own_share) stops to 0.1 stop, is the estimate before the render; render applies the
// exposure metered from the image (image_exposure).
constexpr double kAutoExposureShare = 4.0;
std::optional<float> automatic_exposure(const DefaultLightChoice& c);

// The exposure actually applied to a scene automatic_exposure flags, metered from the rendered
// image as a camera meters it: the log-average luminance of its lit zones mapped to middle
// grey (kMiddleGrey), highlights left to clip. The share above ignores occlusion, and a scene
// lit by small bright emitters (lamps, sparks, screens of strength 20) gets far less of their
// light than it says: a sun of 6.8 klx outside a room lit by 3,840 emitters of strength 20 was
// judged 5 times the studio, exposed -2.4 stops and came out at 3 % of full scale; metered,
// +1.9 stops and 18 % (48 x 48 pixels, 8 samples each). Zones: the image in blocks of side
// ceil(min(width, height) / kMeterZones) pixels, each its mean luminance, which keeps the
// meter steady at a few samples per pixel (the log of single noisy pixels would not be). Lit
// zones: those brighter than 1/1000 of the 99th percentile of the zones (a black sky or
// background is left out: it would drag a scene lit by its own lights towards white). In
// [-kImageExposureRange, +kImageExposureRange] stops, to 0.1 stop; nullopt when no zone is
// lit. EXR outputs stay linear, and --exposure overrides it. `luminance`: width x height
// pixels, row by row.
constexpr double kMiddleGrey = 0.18;
constexpr int kMeterZones = 16;
constexpr double kImageExposureRange = 20.0;
std::optional<float> image_exposure(const std::vector<float>& luminance, int width, int height);

// The rule of --default-light (docs/lights.md): a scene that sets its own environment or
// background (scene extras, --env, --background) keeps it; otherwise Off keeps it as it is,
// On adds the built-in environment, and Auto adds it when the scene has no light or its own
// lights' share is below kOwnLightShareThreshold.
DefaultLightChoice choose_default_light(const Scene& scene, DefaultLight mode, bool environment_given,
                                        double environment_radiance);

}  // namespace candela
