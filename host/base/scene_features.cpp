#include "base/scene_features.hpp"

namespace candela {

std::string SceneFeatures::build_options() const {
  std::string options;
#define CD_FEATURE_OPTION(name, macro, fallback, needs) \
  options += std::string(options.empty() ? "" : " ") + "-D" #macro + (name ? "=1" : "=0");
  CD_SCENE_FEATURES(CD_FEATURE_OPTION)
#undef CD_FEATURE_OPTION
  return options;
}

bool SceneFeatures::covers(const SceneFeatures& needed) const {
  bool all = true;
#define CD_FEATURE_COVERS(name, macro, fallback, needs) all = all && (name || !needed.name);
  CD_SCENE_FEATURES(CD_FEATURE_COVERS)
#undef CD_FEATURE_COVERS
  return all;
}

std::vector<std::string> SceneFeatures::names() const {
  std::vector<std::string> on;
#define CD_FEATURE_NAME(name, macro, fallback, needs) \
  if (name) on.push_back(#name);
  CD_SCENE_FEATURES(CD_FEATURE_NAME)
#undef CD_FEATURE_NAME
  return on;
}

SceneFeatures SceneFeatures::all() {
  SceneFeatures f;
#define CD_FEATURE_ON(name, macro, fallback, needs) f.name = true;
  CD_SCENE_FEATURES(CD_FEATURE_ON)
#undef CD_FEATURE_ON
  return f;
}

bool SceneFeatures::*SceneFeatures::flag(const std::string& macro) {
#define CD_FEATURE_FLAG(name, macro_name, fallback, needs) \
  if (macro == #macro_name) return &SceneFeatures::name;
  CD_SCENE_FEATURES(CD_FEATURE_FLAG)
#undef CD_FEATURE_FLAG
  return nullptr;
}

}  // namespace candela
