// Host-side scene description: what the glTF loader produces and the scene compiler
// (scene_compiler.hpp) turns into device records.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <string>
#include <vector>

#include "base/device_types.hpp"
#include "base/enum_names.hpp"
#include "base/scene_features.hpp"

namespace candela {

// One texture slot of a material: texture, TEXCOORD_n, KHR_texture_transform
struct TextureSlot {
  int index = NO_TEXTURE;     // into Scene::textures
  int texcoord = 0;           // 0 or 1
  glm::mat3 transform{1.0f};  // uv' = transform * (u, v, 1)
  bool operator==(const TextureSlot& o) const {
    return index == o.index && texcoord == o.texcoord && transform == o.transform;
  }
};

enum class AlphaMode { Opaque, Mask, Blend };

// A participating medium (cl/media/media.cl): coefficients per unit length in linear RGB.
// With a density grid the coefficients and the emission are scaled by the density at the
// point: trilinear between the nodes of a dense grid, which span [grid_min, grid_max] in world
// space, or between the voxels of a NanoVDB grid (host/vdb_grid.hpp).
struct MediumDesc {
  glm::vec3 sigma_a{0.0f}, sigma_s{0.0f};
  glm::vec3 emission{0.0f};                  // radiance emitted per unit length (L_e(z), radiative transfer)
  float g = 0.0f;                            // Henyey-Greenstein asymmetry, in (-1, 1)
  glm::ivec3 grid_size{0};                   // nodes along x, y, z (each >= 2) when there is a grid
  std::vector<float> density;                // grid values, x fastest, then y, then z; empty: homogeneous
  glm::vec3 grid_min{0.0f}, grid_max{0.0f};  // a NanoVDB grid: its box in index space
  float density_scale = 1.0f;
  // A NanoVDB float grid (MEDIUM_NANOVDB) instead of `density`: its buffer as 32-bit words,
  // what it came from (for --stats), and majorant cells splitting [grid_min, grid_max]
  // evenly, each the largest value (>= 0, unscaled) that a trilinear lookup inside it reads
  std::vector<uint32_t> nanovdb;
  std::string grid_source;
  glm::ivec3 majorant_size{0};
  std::vector<float> majorant_density;  // x fastest
  // An optional emission grid (inline dense, with a dense density grid): emission at p is
  // emission x emission_scale x the trilinear value of these nodes, which span
  // [emission_grid_min, emission_grid_max] (inside the density grid's box), instead of
  // emission x density
  glm::ivec3 emission_grid_size{0};
  glm::vec3 emission_grid_min{0.0f}, emission_grid_max{0.0f};
  std::vector<float> emission_grid;  // x fastest; empty: emission scales with the density
  float emission_scale = 1.0f;
  bool is_nanovdb() const { return !nanovdb.empty(); }
  bool has_emission_grid() const { return !emission_grid.empty(); }
  bool is_grid() const { return !density.empty() || is_nanovdb(); }
};

// A glTF material factor of n floats: float or glm::vec3 (GLTF_PARAMS)
template <int n>
struct GltfFactor {
  using type = glm::vec<n, float>;
};
template <>
struct GltfFactor<1> {
  using type = float;
};

// A material as glTF describes it (defaults: the glTF specification's), or a measured
// conductor; factors multiply the textures of the same name
struct MaterialDesc {
  std::string name;  // the glTF material's, if it has one
  uint32_t type = MATERIAL_GLTF;
  glm::vec4 base_color{1.0f};  // linear rgba
  glm::vec3 emission{0.0f};    // radiance: emissiveFactor x emissive strength
  // The parameters of cl/shared/gltf_params.h (metallic, roughness, ior, specular, ... with
  // their glTF defaults); factors multiply the textures of their slots
#define CD_MATERIAL_PARAM(_, name, n, value, ...) GltfFactor<n>::type name{value};
  GLTF_PARAMS(CD_MATERIAL_PARAM)
#undef CD_MATERIAL_PARAM
  bool thin_walled = true;  // no KHR_materials_volume (or thickness 0): a sheet, not a solid
  bool unlit = false;       // KHR_materials_unlit: shows base colour x vertex colour, no lighting
  float normal_scale = 1.0f;
  glm::vec3 conductor_eta{0.0f}, conductor_k{0.0f};  // MATERIAL_CONDUCTOR
  bool double_sided = false;
  AlphaMode alpha_mode = AlphaMode::Opaque;
  float alpha_cutoff = 0.5f;
  int medium = -1;                  // into Scene::media: what fills the closed surface (KHR_materials_volume
                                    // attenuation, extras.candela.medium); -1: vacuum
  bool null_boundary = false;       // extras.candela.medium without transmission: the surface is
                                    // invisible and only bounds its medium
  TextureSlot textures[TEX_SLOTS];  // TEX_* slots
  const TextureSlot& texture(int slot) const { return textures[slot]; }
  // MASK or BLEND with an alpha that can make rays pass: traversal must test its hits
  bool alpha_tested() const;
  // The BSDF the kernel shades it with: MATERIAL_DIFFUSE for a glTF material that is exactly
  // Lambertian whatever its textures (its LOBE factors of GLTF_PARAMS all 0, each of which
  // multiplies its texture), else `type`; an unlit material has no BSDF (MATERIAL_DIFFUSE,
  // never evaluated)
  uint32_t kernel_type() const;
  // Whether the kernel needs the feature whose CD_FEATURE_* macro is named `macro` for this
  // material: a glTF-shaded one with a nonzero LOBE or MODIFIER factor of that feature
  // (GLTF_PARAMS), or an anisotropic conductor
  bool needs(const char* macro) const;
};

struct TextureDesc {
  int width = 0, height = 0;
  uint32_t wrap_s = WRAP_REPEAT, wrap_t = WRAP_REPEAT;
  bool srgb = false;           // rgba8 holds sRGB-encoded colour (alpha linear)
  bool nearest = false;        // nearest-texel lookup (sampler magFilter NEAREST), else bilinear
  std::vector<uint8_t> rgba8;  // 4 per texel, or
  std::vector<float> rgbaf;    // 4 per texel (float images)
  size_t texels() const { return size_t(width) * height; }
  // Mean luminance of the decoded texels
  double mean_luminance() const;
};

// An equirectangular environment map (cl/lights/environment.cl documents the mapping): a
// LIGHT_ENVIRONMENT with a texture, replacing the constant background
struct EnvironmentDesc {
  TextureDesc image;      // float RGBA texels (alpha 1), linear, row 0 looks up (+Y)
  float strength = 1.0f;  // radiance = strength x texel
  float rotation = 0.0f;  // degrees about +Y, counter-clockwise seen from above
  std::string source;     // the file it came from, or "built-in sky"
};

// One glTF primitive placed in the world: vertex arrays (world space) and triangles
struct MeshDesc {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;   // per vertex, unit or zero (flat); empty: all flat
  std::vector<glm::vec2> uv0, uv1;  // TEXCOORD_0/1 as stored; empty when absent
  std::vector<glm::vec4> tangents;  // xyz world-space tangent, w handedness; empty when absent
  std::vector<glm::vec3> colors;    // COLOR_0 rgb, linear; empty when absent
  std::vector<uint32_t> indices;    // three per triangle, counter-clockwise = front
  uint32_t material = 0;
  // Motion blur (Scene::motion_steps K > 0): positions and normals at each of the K + 1 poses
  // across the shutter, vertex-major (vertex i's pose s at i (K + 1) + s); the arrays above
  // hold the shutter's middle
  std::vector<glm::vec3> motion_positions, motion_normals;
  size_t triangles() const { return indices.size() / 3; }
};

// How KHR_lights_punctual intensities are read: photometric, the extension's units (candela
// for point and spot lights, lux for directional ones), turned into radiant intensity (W/sr)
// and irradiance (W/m^2) by 683 lm/W as Blender's importer does; or radiometric, taken one
// to one, for files written that way (scene extras candela.light_units, --light-units)
enum class LightUnits { Photometric, Radiometric };
inline constexpr EnumName<LightUnits> kLightUnitNames[] = {
    {LightUnits::Photometric, "photometric", "candela and lux, divided by 683 lm/W"},
    {LightUnits::Radiometric, "radiometric", "W/sr and W/m^2, one to one"}};
constexpr double kLumensPerWatt = 683.0;

// A KHR_lights_punctual light placed in the world, in radiometric units; colour (linear
// RGB) multiplies the intensity.
enum class PunctualType { Point, Spot, Directional };
struct PunctualLightDesc {
  PunctualType type = PunctualType::Point;
  glm::vec3 position{0.0f};                // point, spot: the node's world origin
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // spot, directional: the node's world -Z, unit
  glm::vec3 color{1.0f};
  float intensity = 1.0f;  // point, spot: radiant intensity (W/sr); directional: irradiance (W/m^2)
  float range = 0.0f;      // point, spot: 0 = infinite
  float inner_cone = 0.0f, outer_cone = 0.7853982f;  // spot, radians
};

enum class Projection { Perspective, Orthographic };

struct CameraDesc {
  std::string name;  // the glTF camera's (or "camera N"); empty for cameras made otherwise
  Projection projection = Projection::Perspective;
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float yfov = 0.7853982f;  // perspective: vertical field of view, radians
  float ymag = 1.0f;        // orthographic: half-height of the view in scene units
  float aspect = 0.0f;      // width / height (glTF aspectRatio, or xmag / ymag); 0 = not given
  // Thin lens (perspective only), in scene units: aperture radius (0 = pinhole) and the
  // distance of the sharp plane along the view axis; unset = resolve_camera's default
  float aperture_radius = 0.0f;
  std::optional<float> focus_distance;
};

struct Bounds {
  glm::vec3 lo{1e30f}, hi{-1e30f};
  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Bounds& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x; }
  glm::vec3 center() const { return 0.5f * (lo + hi); }
  float radius() const { return 0.5f * glm::length(hi - lo); }
};

// A glTF animation as `candela info` lists it (the loader poses them: LoadOptions::anim_time)
struct AnimationDesc {
  std::string name;
  size_t channels = 0;
  std::string targets;            // what its channels animate: "rotation of 22 nodes, translation of 1 node"
  double start = 0.0, end = 0.0;  // the range of its key times, seconds
};

struct Scene {
  std::vector<MeshDesc> meshes;
  std::vector<MaterialDesc> materials;
  std::vector<TextureDesc> textures;
  std::optional<CameraDesc> camera;                // the one to render with: the first of `cameras`, or none
  std::vector<CameraDesc> cameras;                 // every camera node of the scene, in node order
  std::string strategy;                            // scene extras candela.strategy (nee, bsdf, auto); empty: not given
  glm::vec3 background{0.0f};                      // constant environment radiance
  std::vector<PunctualLightDesc> punctual_lights;  // KHR_lights_punctual
  std::optional<EnvironmentDesc> environment;      // a map; when present, background is not used
  std::vector<MediumDesc> media;                   // the global medium and the materials' interiors
  int global_medium = -1;                          // into media: what fills the scene (scene extras); -1: vacuum
  LightUnits light_units = LightUnits::Photometric;  // how the file's punctual lights were read
  bool lighting_given = false;               // the scene (extras) or the command line set the background or environment
  std::vector<std::string> warnings;         // each unsupported feature named once
  std::vector<std::string> extensions_used;  // the file's extensionsUsed
  std::vector<std::string> variants;         // KHR_materials_variants names (LoadOptions::variant picks one)
  std::vector<AnimationDesc> animations;     // the file's animations, in order
  int motion_steps = 0;                      // motion blur: the poses across the shutter less one; 0: none
  std::vector<CameraDesc> camera_steps;      // motion blur: the camera at each pose (resolved)

  size_t triangles() const;
  Bounds bounds() const;
  SceneFeatures features() const;
  bool has_light() const;               // some triangle, the background or map, or a punctual light emits
  size_t punctual_light_count() const;  // punctual lights that emit (colour x intensity > 0)
};

// Unit normal of triangle (a, b, c) by its counter-clockwise winding; *area gets its area
// (the host twin of triangle_normal_area in cl/core/geometry.cl)
glm::vec3 triangle_normal_area(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, double* area);

// The bounds a camera is framed on: every mesh's but a backdrop's. A backdrop is a planar
// mesh (smallest side of its bounds under 1 % of its largest: a ground plane or a wall)
// more than 4 times as large as the bounds of the scene's non-planar meshes and spanning
// them across its plane (they stand on it or before it), so that an
// asset on a vast floor fills the frame rather than being a speck on it. Without
// non-planar meshes nothing is a backdrop. *backdrops (if given) gets how many were left out.
Bounds framing_bounds(const Scene& scene, size_t* backdrops = nullptr);

// Without a camera of the scene's: a perspective camera (yfov 45 degrees) looking at the
// centre of the scene's framing_bounds from an elevated three-quarter view, 30 degrees to the right
// of +Z (glTF's front) and 20 degrees up, or 50 degrees up for a flat horizontal scene (its
// height under 15 % of its width), so that no flat asset is seen edge-on and no box
// face-on; as close as keeps all eight corners of the bounds inside the frame of an image
// of width / height `aspect`, with 5 % to spare.
CameraDesc framing_camera(const Scene& scene, float aspect = 1.0f);
// The camera to render with: the scene's, else framing_camera. An unset focus distance
// becomes the distance from the camera to the framing_bounds' centre along the view axis (when
// that centre is not in front of the camera: the bounds' radius). Throws Error for an
// invalid camera (negative aperture, non-positive focus distance, a lens on an
// orthographic camera).
CameraDesc resolve_camera(const Scene& scene, float aspect = 1.0f);

}  // namespace candela
