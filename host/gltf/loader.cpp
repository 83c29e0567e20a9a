// The glTF loader's entry points: the file or bytes through tinygltf, compressed geometry
// decoded (EXT_meshopt_compression, KHR_draco_mesh_compression), posed by its animations at
// the time asked (animation.cpp), then each reader in turn
// (materials, then the node trees with their meshes, cameras and lights, then the
// environment map the extras name).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "base/error.hpp"
#include "base/file_access.hpp"
#include "gltf/gltf_loader.hpp"
#include "gltf/limits.hpp"
#include "gltf/reader.hpp"

namespace candela {
namespace gltf {

bool supported_extension(const std::string& name) {
  static const std::set<std::string> kSupported = {"KHR_materials_emissive_strength",
                                                   "KHR_texture_transform",
                                                   "KHR_mesh_quantization",
                                                   "KHR_materials_volume",
                                                   "KHR_materials_unlit",
                                                   "KHR_lights_punctual",
                                                   "KHR_draco_mesh_compression",
                                                   "EXT_meshopt_compression",
                                                   "EXT_mesh_gpu_instancing",
                                                   "EXT_texture_webp",
                                                   "KHR_materials_pbrSpecularGlossiness",
                                                   "KHR_materials_variants",
                                                   "KHR_animation_pointer"};
  // and the material extensions whose factors GLTF_PARAMS lists
#define CD_PARAM_EXTENSION(_, param, n, value, lo, hi, ext, ...) \
  if (name == #ext && name != "CORE") return true;
  GLTF_PARAMS(CD_PARAM_EXTENSION)
#undef CD_PARAM_EXTENSION
  return kSupported.count(name) > 0;
}

namespace {

void warn_model_wide(const tinygltf::Model& model, Warnings* warn) {
  for (const auto& ext : model.extensionsUsed)
    if (!supported_extension(ext)) warn->add("glTF extension " + ext + " is not supported yet and is ignored");
  for (const auto& ext : model.extensionsRequired)
    if (!supported_extension(ext))
      warn->add("the scene requires glTF extension " + ext +
                ", which candela does not support: the image may be wrong");
}

// The scene's animations listed and, at LoadOptions::anim_time, the document posed by the
// chosen ones; without a time, the rest pose
void apply_animations(tinygltf::Model* model, const LoadOptions& options, Scene* scene, Warnings* warn) {
  scene->animations = describe_animations(*model, warn);
  if (!options.anim_time) {
    if (!options.animation.empty()) throw Error("--animation needs --anim-time (the moment to render)");
    if (!model->animations.empty())
      warn->add(
          "animations are ignored (render --anim-time or --frames poses them): the scene renders as posed by its node "
          "transforms and default morph weights");
    return;
  }
  if (!(std::isfinite(*options.anim_time) && *options.anim_time >= 0.0))
    throw Error("--anim-time must be a finite, non-negative number of seconds");
  std::vector<int> chosen = chosen_animations(*model, options.animation);
  if (chosen.empty()) warn->add("the scene has no animations: --anim-time changes nothing");
  pose_animations(model, chosen, *options.anim_time, warn);
}

// tinygltf file access that finds no file: glTF from memory without a base folder
bool no_file_exists(const std::string&, void*) { return false; }
std::string no_expand_path(const std::string& path, void*) { return path; }
bool no_read(std::vector<unsigned char>*, std::string* err, const std::string& path, void*) {
  if (err) *err += "external files are not read: " + path + "\n";
  return false;
}
bool no_write(std::string*, const std::string&, const std::vector<unsigned char>&, void*) { return false; }

// tinygltf file access for a scene with a folder: tinygltf joins the folder and the
// decoded URI (then tries the working directory, which is never allowed here); the
// folder's policy (SceneFolder::resolve) and the regular-file check decide, and their
// reason becomes tinygltf's read error
struct SceneFiles {
  const SceneFolder* folder;
  std::string prefix;  // folder + "/", as tinygltf joins it
};
bool scene_file_exists(const std::string& path, void* user) {
  const auto* files = static_cast<const SceneFiles*>(user);
  return path.compare(0, files->prefix.size(), files->prefix) == 0;
}
bool read_scene_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const auto* files = static_cast<const SceneFiles*>(user);
  try {
    std::string file = files->folder->resolve(path.substr(files->prefix.size()), "the file");
    read_regular_file(file, "the file", kMaxFileBytes, out);
    return true;
  } catch (const Error& e) {
    if (err) *err += e.what();
    return false;
  }
}

void trim_end(std::string* text, const char* chars) {
  while (!text->empty() && std::string(chars).find(text->back()) != std::string::npos) text->pop_back();
}

// The document parsed by tinygltf; images that fail their checks are left empty, with
// the reason in *image_errors. *warn gets tinygltf's warnings.
tinygltf::Model parse_model(const std::string& data, const SceneFolder& folder, const std::string& name,
                            std::map<int, std::string>* image_errors, std::string* warn) {
  const std::string& base_dir = folder.root;
  tinygltf::TinyGLTF gltf;
  SceneFiles files{&folder, base_dir.empty() || base_dir.back() == '/' ? base_dir : base_dir + "/"};
  tinygltf::FsCallbacks fs = {};
  fs.FileExists = base_dir.empty() ? no_file_exists : scene_file_exists;
  fs.ExpandFilePath = no_expand_path;  // never the shell expansion tinygltf does by default
  fs.ReadWholeFile = base_dir.empty() ? no_read : read_scene_file;
  fs.WriteWholeFile = no_write;
  fs.user_data = &files;
  gltf.SetFsCallbacks(fs);
  gltf.SetImageLoader(load_checked_image, image_errors);
  tinygltf::Model model;
  std::string err;
  // Binary glTF starts with the magic "glTF", whatever the file is called
  bool binary = data.compare(0, 4, "glTF") == 0;
  std::string patched;  // the file with defaults tinygltf needs written in, if any
  std::set<int> bad_images;
  const std::string& bytes = prepare_document(data, binary, name, &patched, &bad_images);
  bool ok = binary ? gltf.LoadBinaryFromMemory(&model, &err, warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                               unsigned(bytes.size()), base_dir)
                   : gltf.LoadASCIIFromString(&model, &err, warn, bytes.data(), unsigned(bytes.size()), base_dir);
  if (!ok) {
    trim_end(&err, "\n ");
    throw Error("cannot load glTF scene " + name + ": " + (err.empty() ? "malformed file" : err));
  }
  for (int i : bad_images) (*image_errors)[i] = "has a data: URI that is not base64";
  return model;
}

// The document tinygltf parsed, with what parsing found: the images left empty and why,
// tinygltf's warnings
struct ParsedDocument {
  SceneFolder folder;
  tinygltf::Model model;
  std::map<int, std::string> image_errors;  // filled by load_checked_image
  std::string warn;
};

// Parses glTF JSON or GLB bytes; `name` labels error messages. External URIs resolve
// against `base_dir`; with an empty one, only data: URIs load.
ParsedDocument parse_document(const std::string& data, const std::string& base_dir, const std::string& name,
                              const LoadOptions& options) {
  ParsedDocument doc{SceneFolder{base_dir, options.allow_outside_paths}, {}, {}, {}};
  if (data.empty()) throw Error("cannot load glTF scene " + name + ": the file is empty");
  if (data.size() > kMaxFileBytes) throw Error("cannot load glTF scene " + name + ": larger than 4 GiB");
  doc.model = parse_model(data, doc.folder, name, &doc.image_errors, &doc.warn);
  trim_end(&doc.warn, "\n");
  return doc;
}

// The scene of a parsed document (its model consumed: compressed geometry decoded into it,
// posed by its animations)
Scene build_scene(tinygltf::Model model, const ParsedDocument& doc, const LoadOptions& options) {
  Scene scene;
  if (!doc.warn.empty()) scene.warnings.push_back("glTF loader: " + doc.warn);
  Warnings warnings(&scene.warnings);
  scene.extensions_used = model.extensionsUsed;
  warn_model_wide(model, &warnings);
  decode_meshopt_views(&model);
  decode_draco_primitives(&model, &warnings);
  apply_animations(&model, options, &scene, &warnings);
  scene.variants = variant_names(model);
  ReadContext ctx{model, scene, warnings, doc.folder, doc.image_errors, options};
  ctx.variant = chosen_variant(model, options.variant);
  if (options.light_units) scene.light_units = *options.light_units;
  read_materials(ctx);
  read_nodes(ctx);
  if (scene.meshes.empty()) throw Error("the scene has no triangles to render");
  load_environment_file(ctx);
  return scene;
}

Scene load_gltf_bytes(const std::string& data, const std::string& base_dir, const std::string& name,
                      const LoadOptions& options) {
  ParsedDocument doc = parse_document(data, base_dir, name, options);
  tinygltf::Model model = std::move(doc.model);
  return build_scene(std::move(model), doc, options);
}

std::string folder_of(const std::string& path) {
  std::string dir = std::filesystem::path(path).parent_path().string();
  return dir.empty() ? "." : dir;
}

}  // namespace
}  // namespace gltf

bool supported_gltf_extension(const std::string& name) { return gltf::supported_extension(name); }

Scene load_gltf(const std::string& path, const LoadOptions& options) {
  std::string data = read_regular_file(path, "scene file", gltf::kMaxFileBytes);
  return gltf::load_gltf_bytes(data, gltf::folder_of(path), path, options);
}

Scene load_gltf_from_memory(const std::string& data, const std::string& base_dir, const LoadOptions& options) {
  return gltf::load_gltf_bytes(data, base_dir, "(from memory)", options);
}

struct GltfDocument::Parsed {
  gltf::ParsedDocument doc;
  LoadOptions options;
};

GltfDocument::GltfDocument(const std::string& path, const LoadOptions& options) {
  std::string data = read_regular_file(path, "scene file", gltf::kMaxFileBytes);
  parsed_ = std::make_unique<Parsed>(Parsed{gltf::parse_document(data, gltf::folder_of(path), path, options), options});
}

GltfDocument::~GltfDocument() = default;

Scene GltfDocument::scene(std::optional<double> anim_time) const {
  LoadOptions options = parsed_->options;
  options.anim_time = anim_time;
  return gltf::build_scene(parsed_->doc.model, parsed_->doc, options);  // a copy of the model
}

}  // namespace candela
