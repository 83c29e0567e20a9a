// KHR_materials_variants: the file's named variants, and the material each primitive takes
// for the variant chosen (its own `material` by default and when no mapping names it).
#include <cmath>

#include "base/error.hpp"
#include "gltf/reader.hpp"

namespace candela::gltf {
namespace {

constexpr const char* kExtension = "KHR_materials_variants";

// The non-negative integer a JSON value holds, else -1
int index_of(const tinygltf::Value& v) {
  if (!v.IsNumber()) return -1;
  double d = v.GetNumberAsDouble();
  return d >= 0.0 && d < 2147483647.0 && d == std::floor(d) ? int(d) : -1;
}

}  // namespace

std::vector<std::string> variant_names(const tinygltf::Model& model) {
  std::vector<std::string> names;
  auto ext = model.extensions.find(kExtension);
  if (ext == model.extensions.end() || !ext->second.Has("variants")) return names;
  const tinygltf::Value& variants = ext->second.Get("variants");
  for (size_t i = 0; variants.IsArray() && i < variants.ArrayLen(); ++i) {
    const tinygltf::Value& v = variants.Get(int(i));
    names.push_back(v.Has("name") && v.Get("name").IsString() ? v.Get("name").Get<std::string>()
                                                              : "variant " + std::to_string(i));
  }
  return names;
}

int chosen_variant(const tinygltf::Model& model, const std::string& name) {
  if (name.empty()) return -1;
  std::vector<std::string> names = variant_names(model);
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return int(i);
  std::string known;
  for (const std::string& n : names) known += (known.empty() ? "'" : ", '") + n + "'";
  throw Error("material variant '" + name + "' is not in the scene (" +
              (names.empty() ? std::string("it has no KHR_materials_variants") : "its variants: " + known) + ")");
}

int primitive_material(const ReadContext& ctx, const tinygltf::Primitive& prim) {
  const int count = int(ctx.model.materials.size());  // the default material's index
  int material = prim.material;
  auto ext = prim.extensions.find(kExtension);
  if (ctx.variant >= 0 && ext != prim.extensions.end() && ext->second.Has("mappings")) {
    const tinygltf::Value& mappings = ext->second.Get("mappings");
    for (size_t i = 0; mappings.IsArray() && i < mappings.ArrayLen(); ++i) {
      const tinygltf::Value& m = mappings.Get(int(i));
      if (!m.Has("variants") || !m.Get("variants").IsArray()) continue;
      const tinygltf::Value& variants = m.Get("variants");
      for (size_t k = 0; k < variants.ArrayLen(); ++k)
        if (index_of(variants.Get(int(k))) == ctx.variant) {
          material = m.Has("material") ? index_of(m.Get("material")) : -1;
          if (material < 0 || material >= count)
            throw Error("KHR_materials_variants mapping refers to a missing material");
          return material;
        }
    }
  }
  if (material >= count)  // -1: no material, the glTF default
    ctx.warn.add("a primitive names material " + std::to_string(material) + ", which the file does not have (" +
                 std::to_string(count) + " materials): it gets the default material");
  return material >= 0 && material < count ? material : count;
}

}  // namespace candela::gltf
