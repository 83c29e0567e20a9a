// Inside the glTF loader: the state its readers share while one document becomes a Scene,
// and each reader's entry point (one file per glTF concept; loader.cpp runs them).
#pragma once

#include <tiny_gltf.h>

#include <cstdint>
#include <glm/glm.hpp>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "base/file_access.hpp"
#include "gltf/gltf_loader.hpp"
#include "scene/scene.hpp"

namespace candela::gltf {

// Scene::warnings, each one once
class Warnings {
 public:
  explicit Warnings(std::vector<std::string>* out) : out_(out) {}
  void add(const std::string& w) {
    if (seen_.insert(w).second) out_->push_back(w);
  }

 private:
  std::vector<std::string>* out_;
  std::set<std::string> seen_;
};

struct ReadContext {
  const tinygltf::Model& model;
  Scene& scene;
  Warnings& warn;
  const SceneFolder& folder;                          // where files the scene names are found
  const std::map<int, std::string>& image_errors;     // why load_checked_image left each image empty
  const LoadOptions& options;                         // the user's choices over the file's
  std::map<std::pair<int, bool>, int> textures = {};  // (glTF texture, sRGB) -> Scene::textures or NO_TEXTURE
  size_t degenerate = 0;                              // zero-area triangles skipped
  std::vector<bool> visited = {};                     // nodes of the default scene
  std::vector<glm::mat4> world = {};                  // each visited node's world transform
  std::vector<int> parent = {};                       // each node's parent or -1, once a skin needs it
  int variant = -1;                                   // KHR_materials_variants: the variant rendered; -1 the default
  std::map<int, std::vector<glm::mat4>> skin_joints = {};  // joint_matrices of each skin met
  size_t instanced_triangles = 0;                          // triangles EXT_mesh_gpu_instancing added
};

// obj[key] (index < 0) or obj[key][index] when it is a number, else `fallback`
inline double number_or(const tinygltf::Value& obj, const char* key, int index, double fallback) {
  if (!obj.Has(key)) return fallback;
  const tinygltf::Value& v = obj.Get(key);
  if (index >= 0) {
    if (!v.IsArray() || int(v.ArrayLen()) <= index || !v.Get(index).IsNumber()) return fallback;
    return v.Get(index).GetNumberAsDouble();
  }
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

// An extension this loader implements fully (others are named in a warning)
bool supported_extension(const std::string& name);

// draco.cpp: each KHR_draco_mesh_compression primitive decoded into new buffers, its accessors
// pointed at them (the extension then removed); one that does not decode keeps it and is skipped
void decode_draco_primitives(tinygltf::Model* model, Warnings* warn);

// meshopt.cpp: each EXT_meshopt_compression bufferView decoded into a new buffer it then points
// at; Error for one that does not decode
void decode_meshopt_views(tinygltf::Model* model);

// document.cpp: the bytes tinygltf parses (`data` itself or *patched); Error for JSON nested
// deeper than kMaxJsonDepth. *bad_images gets the images whose data: URI does not decode
// (replaced by a stand-in that load_checked_image drops).
const std::string& prepare_document(const std::string& data, bool binary, const std::string& name, std::string* patched,
                                    std::set<int>* bad_images);

// images.cpp: tinygltf's image decoding behind the size checks (a tinygltf::LoadImageDataFunction)
bool load_checked_image(tinygltf::Image* image, int index, std::string* err, std::string* warn, int req_width,
                        int req_height, const unsigned char* bytes, int size, void* errors);

// accessors.cpp: accessor elements (count x components values), sparse substitution applied
std::vector<float> read_accessor(const tinygltf::Model& model, int index, int want_components);
std::vector<uint32_t> read_indices(const tinygltf::Model& model, int index);

// textures.cpp: a material's texture slot from a core textureInfo (with its extensions) or
// from a textureInfo `key` inside an extension object; each texture's image decoded once
void set_texture_slot(ReadContext& ctx, MaterialDesc* m, int slot, int gltf_texture, int texcoord,
                      const tinygltf::ExtensionMap& extensions, bool srgb);
void set_texture_slot(ReadContext& ctx, MaterialDesc* m, int slot, const tinygltf::Value& ext, const char* key,
                      bool srgb);
// The glTF texture's image (with its sampler) decoded into *t, not added to the scene; false,
// with one warning, when no image of it decodes
bool decode_texture(ReadContext& ctx, int gltf_texture, bool srgb, TextureDesc* t);
// The textureInfo `key` of an extension object, not decoded: its index is the glTF texture's
// (-1 when absent), with its texCoord and KHR_texture_transform
TextureSlot texture_info(const tinygltf::Value& ext, const char* key);

// materials.cpp: every material, then the default one (index = the model's material count)
void read_materials(ReadContext& ctx);

// media.cpp: a medium from candela's extras (`where` names it in errors)
MediumDesc read_medium(const tinygltf::Value& v, const std::string& where, const SceneFolder& folder);

// nodes.cpp: the default scene's node trees (meshes, the first camera, lights), its extras
void read_nodes(ReadContext& ctx);

// meshes.cpp: the node's mesh, each primitive with its default morph weights, placed in the
// world by the node's transform, its skin's joints or each EXT_mesh_gpu_instancing instance
void read_node_mesh(ReadContext& ctx, int node_index);

// skins.cpp: the skin's joint matrices (joint world transform x inverse bind matrix), and the
// world transform of any node, in the default scene or not
const std::vector<glm::mat4>& joint_matrices(ReadContext& ctx, int skin);
glm::mat4 node_world(ReadContext& ctx, int node);
glm::mat4 local_transform(const tinygltf::Node& node);

// nodes.cpp: the EXT_mesh_gpu_instancing transforms of the node (empty without the extension)
std::vector<glm::mat4> instance_transforms(ReadContext& ctx, int node_index);

// variants.cpp: KHR_materials_variants: the variants' names, the one LoadOptions::variant names
// (Error for an unknown one), and a primitive's material for ReadContext::variant
std::vector<std::string> variant_names(const tinygltf::Model& model);
int chosen_variant(const tinygltf::Model& model, const std::string& name);
int primitive_material(const ReadContext& ctx, const tinygltf::Primitive& prim);

// spec_gloss.cpp: KHR_materials_pbrSpecularGlossiness converted to metallic-roughness, in place
// of pbrMetallicRoughness; false when the material has no such extension
bool read_specular_glossiness(ReadContext& ctx, const tinygltf::Material& gm, MaterialDesc* m);

// lights.cpp: the node's KHR_lights_punctual light, placed in the world
void read_node_light(ReadContext& ctx, int node_index, const tinygltf::Value& ext, const glm::mat4& world);

// animation.cpp: the animations LoadOptions::animation names (an index or a name; empty: all),
// Error naming the file's for an unknown one; the document posed at time t (seconds) by them,
// in order (a later channel wins), one warning for each property it leaves out; and the
// animations as Scene::animations lists them (a malformed one warned about)
std::vector<int> chosen_animations(const tinygltf::Model& model, const std::string& selection);
void pose_animations(tinygltf::Model* model, const std::vector<int>& animations, double t, Warnings* warn);
std::vector<AnimationDesc> describe_animations(const tinygltf::Model& model, Warnings* warn);

// extras.cpp: the scene's extras.candela (environment, strategy, medium, background), and
// the environment map file it names, read once the document is
void read_scene_extras(ReadContext& ctx, const tinygltf::Value& extras);
void load_environment_file(ReadContext& ctx);

}  // namespace candela::gltf
