// glTF 2.0 (.gltf / .glb) scene loading through tinygltf.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "scene/scene.hpp"

namespace candela {

// Choices the user makes about reading a file (the command line's), over the file's own
struct LoadOptions {
  std::optional<LightUnits> light_units;  // else the scene extras' candela.light_units, else photometric
  std::string variant;                    // a KHR_materials_variants name; empty: the default materials
  bool allow_outside_paths = false;       // files outside the scene's folder (SceneFolder)
  // Animations: the pose at anim_time seconds (unset: the rest pose, animations ignored) of
  // the animation `animation` names (an index or a name; empty: all of them together)
  std::optional<double> anim_time;
  std::string animation;
};

// Whether the loader implements glTF extension `name` (others are named in a warning)
bool supported_gltf_extension(const std::string& name);

// Loads the default scene (or the first) with node transforms applied. Throws Error
// on a missing or malformed file; unsupported features land in Scene::warnings, and so
// do images that cannot be decoded (their textures fall back or are dropped).
Scene load_gltf(const std::string& path, const LoadOptions& options = {});

// The same from the bytes of a .gltf or .glb (told apart by the "glTF" magic). External
// URIs resolve against `base_dir`; with an empty `base_dir` no file is read (only data:
// URIs and the GLB's own BIN chunk load), as for untrusted input.
Scene load_gltf_from_memory(const std::string& data, const std::string& base_dir, const LoadOptions& options = {});

// A glTF file read, parsed and its images decoded once, then read into a Scene as often as
// asked, each time posed by its animations at another moment (a frame sequence)
class GltfDocument {
 public:
  GltfDocument(const std::string& path, const LoadOptions& options);
  ~GltfDocument();
  // The scene as load_gltf reads it with the document's options at anim_time
  Scene scene(std::optional<double> anim_time) const;

 private:
  struct Parsed;
  std::unique_ptr<Parsed> parsed_;
};

}  // namespace candela
