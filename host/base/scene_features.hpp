// The kernel features a scene needs (CD_SCENE_FEATURES, cl/shared/device_types.h): build
// options of the specialized kernel, and part of the program cache's key. Computed from the
// scene description (Scene::features) and carried by the compiled scene to the renderer.
#pragma once

#include <string>
#include <vector>

#include "base/device_types.hpp"

namespace candela {

// Coarse scene features that select kernel code at build time (part of the cache key): one
// flag per entry of CD_SCENE_FEATURES (cl/shared/device_types.h), on when the scene has what
// the entry's `needs` says (Scene::features)
struct SceneFeatures {
#define CD_FEATURE_FIELD(name, macro, fallback, needs) bool name = false;
  CD_SCENE_FEATURES(CD_FEATURE_FIELD)
#undef CD_FEATURE_FIELD
  // -DMACRO=0|1 for every feature, in list order
  std::string build_options() const;
  // Does this kernel have every feature `needed` names?
  bool covers(const SceneFeatures& needed) const;
  // The names of the features on, in list order
  std::vector<std::string> names() const;
  // Every flag on: the generic kernel, correct for any scene (--generic)
  static SceneFeatures all();
  // The flag of the feature whose kernel macro is `macro` (a feature column of CD_MATERIALS
  // or CD_LIGHTS); nullptr for any other text, such as "1" (always compiled in)
  static bool SceneFeatures::*flag(const std::string& macro);
};

}  // namespace candela
