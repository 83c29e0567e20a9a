// Structs that cross between host and device, defined once.
// Included by the OpenCL program (first in the source list) and by the host inside
// namespace candela::dev (host/device_types.hpp), which static_asserts every layout from
// CD_LAYOUT below; the device-side layout test checks the same list on each device.
// Only 4-byte scalars, arrays of them and unions of such structs: no float3, no vector types,
// explicit padding.

#ifndef CANDELA_DEVICE_TYPES_H
#define CANDELA_DEVICE_TYPES_H

// Kernel features: code a scene does without is compiled out of its kernel. CD_SCENE_FEATURES:
// X(name, macro, default, needs), one entry per feature, generates SceneFeatures
// (host/scene/scene.hpp: the field `name`, on when the scene has what `needs` says), the
// build options -Dmacro=0|1 in this order (part of the program-cache key) and the kernel's
// default without them, `#define macro default`, which host/device/kernel_sources.cpp
// prepends to the program. Kernel code tests `#if macro`.
// One entry per line, columns aligned:
// clang-format off
#define CD_SCENE_FEATURES(X)                                                                       \
  X(textures, CD_FEATURE_TEXTURES, 1, "some material slot has a texture")                          \
  X(uvs, CD_FEATURE_UVS, 1, "some mesh has TEXCOORD_0 or TEXCOORD_1")                              \
  X(tangents, CD_FEATURE_TANGENTS, 1, "some mesh has TANGENT")                                     \
  X(vertex_colors, CD_FEATURE_VERTEX_COLORS, 1, "some COLOR_0 is not white")                       \
  X(alpha, CD_FEATURE_ALPHA, 1, "a mesh's material is alpha-tested (alpha_tested)")                \
  X(media, CD_FEATURE_MEDIA, 1, "a global medium, or a mesh's material with an interior medium")   \
  X(nanovdb, CD_FEATURE_NANOVDB, CD_PNANOVDB_AVAILABLE, "a medium with a NanoVDB grid")            \
  X(gltf_bsdf, CD_FEATURE_GLTF_BSDF, 1, "a mesh's material shaded as MATERIAL_GLTF (kernel_type)") \
  X(conductor, CD_FEATURE_CONDUCTOR, 1, "a mesh's material shaded as MATERIAL_CONDUCTOR")          \
  X(sheen, CD_FEATURE_SHEEN, 1, "a glTF-shaded material with a KHR_materials_sheen colour")        \
  X(diffuse_transmission, CD_FEATURE_DIFFUSE_TRANSMISSION, 1, "a glTF diffuse transmission")       \
  X(diffuse_roughness, CD_FEATURE_DIFFUSE_ROUGHNESS, 1, "a glTF diffuse roughness (EON) above 0")  \
  X(dispersion, CD_FEATURE_DISPERSION, 1, "a refracting glTF material with dispersion > 0")         \
  X(iridescence, CD_FEATURE_IRIDESCENCE, 1, "a glTF-shaded KHR_materials_iridescence")             \
  X(anisotropy, CD_FEATURE_ANISOTROPY, 1, "a glTF or conductor lobe with anisotropy strength > 0")  \
  X(unlit, CD_FEATURE_UNLIT, 1, "a mesh's material is KHR_materials_unlit")                        \
  X(punctual, CD_FEATURE_PUNCTUAL, 1, "an emitting KHR_lights_punctual light")                     \
  X(environment, CD_FEATURE_ENVIRONMENT, 1, "an environment map or a constant background")        \
  X(light_tree, CD_FEATURE_LIGHT_TREE, 1, "the compiled scene has a light tree (compile_lights)")
// clang-format on

// Material types. CD_MATERIALS: X(id, name, feature), one entry per type, generates every
// dispatch on Material.type and Bsdf.type (cl/bsdf/bsdf.cl; the host's compile step and name
// table). Each type has its lobe in cl/bsdf/bsdf_NAME.cl with the five functions
//   void bsdf_NAME_params(const SceneData*, __global const Material*, const SurfaceHit*, Bsdf*)
//   uint bsdf_NAME_flags(const Bsdf*)
//   float3 bsdf_NAME_eval(const Bsdf*, float3 wo, float3 wi, float* pdf)
//   bool bsdf_NAME_sample(const Bsdf*, float3 wo, float uc, float2 u, BsdfSample*, BsdfLobes* l):
//     with l (not 0), also its lobes at wo into l, as bsdf_NAME_lobes gives them
//   void bsdf_NAME_lobes(const Bsdf*, float3 wo, BsdfLobes*): its lobes at wo (bsdf_common.cl)
// and on the host compile_material_NAME (host/compile/scene_compiler.cpp). `feature` is the
// CD_SCENE_FEATURES macro that compiles the type in, or 1 (always). The ids number the list.
#define MATERIAL_DIFFUSE 0u    // Lambertian, albedo = base color
#define MATERIAL_GLTF 1u       // glTF metallic-roughness with its KHR_materials_* extensions
#define MATERIAL_CONDUCTOR 2u  // measured conductor: complex index eta + i k, GGX roughness
// One entry per line, columns aligned:
// clang-format off
#define CD_MATERIALS(X)                        \
  X(MATERIAL_DIFFUSE, diffuse, 1)              \
  X(MATERIAL_GLTF, gltf, CD_FEATURE_GLTF_BSDF) \
  X(MATERIAL_CONDUCTOR, conductor, CD_FEATURE_CONDUCTOR)
// clang-format on

// Material flags
#define MATERIAL_DOUBLE_SIDED 1u
#define MATERIAL_THIN_WALLED 2u     // transmission through a sheet (no KHR_materials_volume)
#define MATERIAL_ALPHA_MASK 4u      // alphaMode MASK: cut out below alpha_cutoff
#define MATERIAL_ALPHA_BLEND 8u     // alphaMode BLEND: stochastic opacity
#define MATERIAL_NULL_BOUNDARY 16u  // invisible (index-matched) surface bounding Material.medium
#define MATERIAL_UNLIT 32u          // KHR_materials_unlit: shows its base colour, ends paths

// Texture slots of a material (Material.textures): GLTF_TEXTURES (gltf_params.h)

// Light types. CD_LIGHTS: X(id, name, feature), one entry per type, generates every dispatch
// on Light.type (cl/lights/lights.cl; on the host light_power, light_bounds and the name
// table). Each type has its parameters, a struct of 32 bytes that is the member `name` of
// LightParams (below; Light.params.name), and in cl/lights/NAME.cl (or the file of its family)
//   bool lights_NAME_sample(const SceneData*, __global const Light*, const LightSampleContext*,
//                           float2 u, LightSample*)
//   float lights_NAME_pdf(const SceneData*, __global const Light*, const LightSampleContext*, float3 wi)
//   void lights_NAME_extent(const SceneData*, __global const Light*, float3 p, LightExtent*)
//   float lights_NAME_omega_bound(const SceneData*, __global const Light*, float3 p): an upper
//                           bound on its solid angle at p, cheaper than the extent (0: delta; < 0: none)
//   uint lights_NAME_prim(__global const Light*): the emissive primitive it is, or UINT_MAX
// and on the host light_power_NAME and light_bounds_NAME (its power, and its bounds in the
// light tree or none: host/compile/light_types.cpp). `feature` is the CD_SCENE_FEATURES
// macro that compiles the type in, or 1 (always). The ids number the list.
#define LIGHT_TRIANGLE 0u     // an emissive triangle (area light)
#define LIGHT_ENVIRONMENT 1u  // radiance arriving from infinitely far away: constant or a map
#define LIGHT_POINT 2u        // KHR_lights_punctual point: radiant intensity from a point
#define LIGHT_SPOT 3u         // KHR_lights_punctual spot: a point light restricted to a smooth cone
#define LIGHT_DIRECTIONAL 4u  // KHR_lights_punctual directional: parallel light from infinity
// One entry per line, columns aligned:
// clang-format off
#define CD_LIGHTS(X)                                        \
  X(LIGHT_TRIANGLE, triangle, 1)                            \
  X(LIGHT_ENVIRONMENT, environment, CD_FEATURE_ENVIRONMENT) \
  X(LIGHT_POINT, point, CD_FEATURE_PUNCTUAL)                \
  X(LIGHT_SPOT, spot, CD_FEATURE_PUNCTUAL)                  \
  X(LIGHT_DIRECTIONAL, directional, CD_FEATURE_PUNCTUAL)
// clang-format on

// Integration strategies (no MIS: each light path is counted by exactly one of them)
#define STRATEGY_NEE 0u
#define STRATEGY_BSDF 1u
#define STRATEGY_AUTO 2u  // per vertex and per light: whichever of the two has the lower second moment

// Camera projections (camera.cl)
#define CAMERA_PERSPECTIVE 0u   // pinhole, or a thin lens when lens_radius > 0
#define CAMERA_ORTHOGRAPHIC 1u  // parallel rays along forward

// Pixel filters (filter.cl), importance-sampled: film samples are offset from the pixel
// centre with the filter's density, so each pixel stays an unweighted mean
#define FILTER_BOX 0u       // uniform over the pixel (|dx|, |dy| < 1/2)
#define FILTER_TENT 1u      // separable tent of radius 1 pixel
#define FILTER_GAUSSIAN 2u  // isotropic Gaussian, sigma 1/2 pixel, not truncated

// Texture flags: wrap modes (glTF sampler wrapS in bits 0-7, wrapT in bits 8-15),
// colour encoding, texel storage and filter
#define WRAP_REPEAT 0u
#define WRAP_CLAMP 1u
#define WRAP_MIRROR 2u
#define TEXTURE_SRGB 0x10000u     // RGBA8 texels hold sRGB-encoded colour (alpha linear)
#define TEXTURE_FLOAT 0x20000u    // texels live in the float texel array, else in the RGBA8 one
#define TEXTURE_NEAREST 0x40000u  // nearest-texel lookup (glTF magFilter NEAREST), else bilinear

// GGX albedo table (cl/bsdf/energy.cl): two halves of GGX_ALBEDO_HALF floats, E (F = 1) then E5
// (Fresnel weight (1 - wo.h)^5, for Schlick's term); each holds the albedo at
// GGX_ALBEDO_N x GGX_ALBEDO_N nodes (y, roughness), y fastest (y: energy.cl's coordinate
// for mu), then its hemispherical average at GGX_ALBEDO_N roughnesses
#define GGX_ALBEDO_N 32
#define GGX_ALBEDO_HALF (GGX_ALBEDO_N * (GGX_ALBEDO_N + 1))
#define GGX_ALBEDO_QUADRATURE 64  // quadrature points per side of each entry
// Then the rough dielectric's albedo (cl/bsdf/energy_dielectric.cl): reflection plus
// transmission E(y, roughness, eta) for each side (0: eta >= 1, 1: eta < 1), y fastest, then
// its hemispherical averages by (roughness, eta, side)
#define DIEL_ALBEDO_OFFSET (2 * GGX_ALBEDO_HALF)
#define DIEL_ALBEDO_N 32           // nodes in y
#define DIEL_ALBEDO_R 16           // nodes in glTF roughness
#define DIEL_ALBEDO_F 16           // nodes in 2 (eta - 1) / (eta + 1), eta in [1, 3]
#define DIEL_ALBEDO_QUADRATURE 48  // quadrature points per side of each entry
#define DIEL_ALBEDO_ROWS (2 * DIEL_ALBEDO_F * DIEL_ALBEDO_R)
#define DIEL_ALBEDO_SIZE (DIEL_ALBEDO_ROWS * (DIEL_ALBEDO_N + 1))
// Then the anisotropic GGX lobe's E and E5 (ax != ay; cl/bsdf/energy.cl): two parts (E, then
// E5), each GGX_ANISO_N x GGX_ANISO_P x GGX_ANISO_R x GGX_ANISO_Q nodes (y or mu, the
// azimuth's t = sin^2 phi from the major axis, sqrt of the major alpha, the ratio
// sqrt(minor / major alpha)), y fastest, then its hemispherical averages by (roughness, ratio)
#define GGX_ANISO_OFFSET (DIEL_ALBEDO_OFFSET + DIEL_ALBEDO_SIZE)
#define GGX_ANISO_N 32
#define GGX_ANISO_P 8
#define GGX_ANISO_R 16
#define GGX_ANISO_Q 8
#define GGX_ANISO_QUADRATURE 32  // quadrature points per side of each entry
#define GGX_ANISO_ROWS (GGX_ANISO_P * GGX_ANISO_R * GGX_ANISO_Q)
#define GGX_ANISO_PART (GGX_ANISO_ROWS * GGX_ANISO_N + GGX_ANISO_R * GGX_ANISO_Q)
// Then the anisotropic rough dielectric's E (cl/bsdf/energy_dielectric.cl; quadrature only
// for a scene with anisotropic refracting glass): DIEL_ANISO_N x DIEL_ANISO_P x DIEL_ANISO_R x
// DIEL_ANISO_Q nodes (y, t, sqrt of the major alpha, the ratio's fourth root) for each eta node
// (as DIEL_ALBEDO_F's, fewer) and side, y fastest, then the averages by (roughness, ratio,
// eta, side)
#define DIEL_ANISO_OFFSET (GGX_ANISO_OFFSET + 2 * GGX_ANISO_PART)
#define DIEL_ANISO_N 24
#define DIEL_ANISO_P 8
#define DIEL_ANISO_R 10
#define DIEL_ANISO_Q 7
#define DIEL_ANISO_F 8
#define DIEL_ANISO_QUADRATURE 24                                           // quadrature points per side of each entry
#define DIEL_ANISO_NODES (2 * DIEL_ANISO_F * DIEL_ANISO_Q * DIEL_ANISO_R)  // (roughness, ratio, eta, side)
#define DIEL_ANISO_SIZE (DIEL_ANISO_NODES * (DIEL_ANISO_P * DIEL_ANISO_N + 1))
#define GGX_ALBEDO_SIZE (DIEL_ANISO_OFFSET + DIEL_ANISO_SIZE)  // the whole buffer

// Sheen albedo table (cl/bsdf/sheen.cl): the directional albedo E(mu) of the Charlie sheen
// lobe with colour 1 at SHEEN_ALBEDO_N x SHEEN_ALBEDO_N nodes (mu, sheen roughness), mu fastest,
// mu = (i / (SHEEN_ALBEDO_N - 1))^2, roughness = j / (SHEEN_ALBEDO_N - 1)
#define SHEEN_ALBEDO_N 32
#define SHEEN_ALBEDO_SIZE (SHEEN_ALBEDO_N * SHEEN_ALBEDO_N)
#define SHEEN_ALBEDO_QUADRATURE 64  // quadrature points per side of each entry

#define NO_TEXTURE (-1)
#define NO_LIGHT (-1)
#define NO_MEDIUM (-1)
#define GLOBAL_MEDIUM 0  // media[0] fills the scene (a vacuum record when none is declared)

// Medium types (media.cl)
#define MEDIUM_HOMOGENEOUS 0u
#define MEDIUM_GRID 1u     // coefficients scaled by a dense density grid (trilinear), delta tracking
#define MEDIUM_NANOVDB 2u  // as MEDIUM_GRID, the density from a NanoVDB float grid (nanovdb.cl)

// 4-wide BVH node, 128 bytes; its encoding is private to bvh_builder.cpp and
// bvh_traverse.cl. The four child boxes are stored by coordinate (structure of arrays) so
// that one float4 operation tests a slab of all four: lo_x[i] .. hi_z[i] bound child i.
// child[i]: >= 0 an inner node's index; < 0 a leaf, ~child[i] its first BvhTriangle (the
// leaf runs to the triangle flagged BVH_TRI_LAST). Unused slots have lo = +1e30 > hi =
// -1e30, which no ray enters, and child 0.
typedef struct {
  float lo_x[4];
  float hi_x[4];  // must follow lo_x (and hi_y lo_y, hi_z lo_z): traversal picks by offset
  float lo_y[4];
  float hi_y[4];
  float lo_z[4];
  float hi_z[4];
  int child[4];
  int pad[4];
} BvhNode;

// Traversal stack entries: at most 3 per node on the way down (the builder's
// depth limit keeps the tree within it)
#define BVH_STACK_SIZE 96

// A triangle as the BVH leaves store it (BVH order), 48 bytes; private to the BVH files.
#define BVH_TRI_ALPHA_TEST 1u  // hits must pass scene_alpha_passes (alphaMode MASK / BLEND)
#define BVH_TRI_LAST 2u        // the last triangle of its leaf
typedef struct {
  float v0[3];
  unsigned int prim;  // stable primitive index (Prim array)
  float v1[3];
  unsigned int flags;  // BVH_TRI_*
  float v2[3];
  unsigned int pad1;
} BvhTriangle;

// A triangle of the scene in its stable primitive order, 16 bytes: vertex indices into
// the per-vertex arrays (positions, normals, uv0, uv1, tangents, colors) and a material.
typedef struct {
  unsigned int v[3];
  unsigned int material;
} Prim;

// One texture slot of a material, 32 bytes: which texture, which TEXCOORD_n, and the
// KHR_texture_transform applied in the kernel: uv' = (m[0] u + m[1] v + m[2],
// m[3] u + m[4] v + m[5]).
typedef struct {
  int index;              // into TextureInfo, or NO_TEXTURE
  unsigned int texcoord;  // 0 or 1
  float m[6];
} TextureRef;

// Parameters of a MATERIAL_GLTF material: GltfMaterial, generated from GLTF_PARAMS (gltf_params.h)

// Parameters of a MATERIAL_CONDUCTOR material, 48 bytes: complex index eta + i k per channel
// (w unused), GGX roughness and KHR_materials_anisotropy as in GltfMaterial
typedef struct {
  float eta[4];
  float k[4];
  float roughness, anisotropy_strength, anisotropy_rotation;
  unsigned int pad;
} ConductorMaterial;

// A material type's own parameters (Material.type selects the member), GltfMaterial's size
typedef union {
  GltfMaterial gltf;
  ConductorMaterial conductor;
} MaterialParams;

// Material: what every type has (48 bytes), then its type's parameters and the texture slots.
// Colours are linear RGB; factors multiply their texture slots.
typedef struct {
  unsigned int type;   // MATERIAL_*
  unsigned int flags;  // MATERIAL_DOUBLE_SIDED | ...
  float alpha_cutoff;  // alphaMode MASK
  float normal_scale;
  float base_color[4];             // rgba factor
  float emission[3];               // rgb radiance (factor x strength)
  int medium;                      // the medium inside a closed surface (into `media`), or NO_MEDIUM
  MaterialParams params;           // by type
  TextureRef textures[TEX_SLOTS];  // TEX_* slots
} Material;

// A texture inside one of the shared texel arrays, 16 bytes.
typedef struct {
  unsigned int offset;  // first texel
  unsigned int width;
  unsigned int height;
  unsigned int flags;  // wrap_s | wrap_t << 8 | TEXTURE_SRGB | TEXTURE_FLOAT | TEXTURE_NEAREST
} TextureInfo;

// RGBA8 texel, 4 bytes
typedef struct {
  unsigned char r, g, b, a;
} Texel8;

// Float RGBA texel (HDR images, later grids), 16 bytes
typedef struct {
  float rgba[4];
} TexelF;

// One bin of the light-selection alias table, 8 bytes (sample_discrete_alias in
// sampling.cl): a uniform 32-bit x picks bin b = floor(x n / 2^32); the low 32 bits of
// x n then keep b when below `threshold`, else select `alias`.
typedef struct {
  unsigned int threshold;
  unsigned int alias;
} AliasBin;

// The parameters of each light type (LightParams, by CD_LIGHTS name), 32 bytes each.
// LIGHT_TRIANGLE: the emissive primitive is Light.index; its radiance comes from the
// primitive's material.
typedef struct {
  float area;
  float centre[3];  // centroid (in float) of the bounding sphere lights_triangle_omega_bound uses
  float radius;     // of that sphere: it holds the triangle's float corners
  unsigned int pad[3];
} TriangleLight;

// LIGHT_ENVIRONMENT: without a map (map = NO_TEXTURE), radiance = Light.radiance, constant.
// With an equirectangular map (cl/lights/environment.cl): radiance = strength x texel, and
// its sampling distribution is the env_distribution buffer. Both, for STRATEGY_AUTO's
// choice, L the luminance before strength: solid_angle = the effective solid angle
// (integral L)^2 / integral L^2 (4 pi for a constant), direction = the unit direction L^2
// is centred on (zero: none), integral = integral of L over the sphere.
typedef struct {
  float map;       // its TextureInfo index (an integer stored as float), or NO_TEXTURE
  float strength;  // of the map
  float rotation;  // of the map about +Y, radians
  float solid_angle;
  float direction[3];
  float integral;
} EnvironmentLight;

// LIGHT_POINT: Light.radiance = colour x intensity (radiant intensity, W/sr),
// Light.radiance[3] = range (0: infinite).
typedef struct {
  float position[3];
  unsigned int pad[5];
} PointLight;

// LIGHT_SPOT: as LIGHT_POINT, restricted to a cone: the intensity toward a direction at
// cosine c to the axis is scaled by spot_profile(c, cone_scale, cone_offset)
// (cl/shared/light_profiles.h; KHR_lights_punctual).
typedef struct {
  float position[3];
  float axis[3];      // unit axis the cone points along
  float cone_scale;   // 1 / max(0.001, cos(inner) - cos(outer))
  float cone_offset;  // -cos(outer) x cone_scale
} SpotLight;

// LIGHT_DIRECTIONAL: Light.radiance = colour x intensity (irradiance at normal incidence).
typedef struct {
  unsigned int pad0[3];
  float direction[3];  // unit direction the light travels
  unsigned int pad[2];
} DirectionalLight;

// A light type's own parameters (Light.type selects the member, named as its CD_LIGHTS
// entry), 32 bytes; every member spans the union (the host asserts it from the list)
typedef union {
  TriangleLight triangle;
  EnvironmentLight environment;
  PointLight point;
  SpotLight spot;
  DirectionalLight directional;
} LightParams;

// A light, 64 bytes: a type, its selection probability, and the type's parameters.
// Lights are selected through the alias table (light_alias, one bin per light, O(1));
// `pmf` is exactly the probability it realizes, counted over all 2^32 integers, so the
// estimator divides by what the kernel does.
typedef struct {
  unsigned int type;  // LIGHT_*
  float pmf;
  unsigned int index;  // LIGHT_TRIANGLE: the stable primitive index
  unsigned int pad0;
  float radiance[4];   // rgb
  LightParams params;  // by type
} Light;

// A node of the light tree, 224 bytes (cl/lights/light_tree.cl; Conty Estevez & Kulla 2018,
// Importance Sampling of Many Lights with Adaptive Tree Splitting). The tree holds the
// finite lights (triangles, points, spots), one per leaf; a node has up to four children,
// stored by field across its slots (centre[axis][slot], ...) so that the kernel weighs all
// four in one pass of float4 arithmetic; the root is node 0. Each slot bounds its child's
// lights: their positions (a sphere about `centre`, the one around their bounding box), the
// directions they emit in (every light's emission axis lies within theta_o of `axis`, and
// each emits only within theta_e beyond its axis) and their summed peak radiant intensity
// (luminance; a triangle: L A); intensity 0 marks an empty slot. A node inside a planar
// emitter made of several triangles (a quad light; host/compile/light_tree.cpp) is a
// cluster: it takes its children by their share of its intensity instead of by importance.
// A scene without finite lights, or one compiled for power selection, has one node of share
// 0: every light goes through the alias table.
#define LIGHT_TREE_INTERIOR 0u
#define LIGHT_TREE_LEAF 1u
#define LIGHT_TREE_WIDTH 4u
typedef struct {
  float centre[3][4];      // [axis][slot]
  float radius[4];         // of the sphere about centre that holds the child's lights
  float axis[3][4];        // [axis][slot]
  float intensity[4];      // 0: no child in the slot
  float cos_o[4];          // cos theta_o
  float sin_o[4];          // sin theta_o
  float cos_e[4];          // cos theta_e
  unsigned int child[4];   // LIGHT_TREE_LEAF slot: its light; LIGHT_TREE_INTERIOR: the child node
  unsigned int leaf[4];    // LIGHT_TREE_INTERIOR or LIGHT_TREE_LEAF
  unsigned int cluster;    // 1: children by their share of the intensity, not by importance
  unsigned int holds_all;  // root: 1 when every light is in the tree (share is then 1)
  float share;             // root: probability that selection goes into the tree
  float min_prob;          // root: least weight of a child that can light the point, as a
                           // fraction of the sum of the importances (see light_tree.cl)
} LightTreeNode;

// The path from the root of the light tree to a light's leaf, 32 bytes: step k (k < depth)
// takes slot (bits[k / 16] >> (2 (k % 16))) & 3. Lights outside the tree have depth
// LIGHT_TREE_NONE.
#define LIGHT_TREE_NONE 0xffffffffu
#define LIGHT_TREE_MAX_DEPTH 64u
typedef struct {
  unsigned int bits[4];
  unsigned int depth;
  unsigned int pad[3];
} LightTreeTrail;

// A participating medium, 128 bytes (media.cl). Coefficients are per unit length in linear
// RGB at density 1; MEDIUM_GRID and MEDIUM_NANOVDB multiply them by the density at the point
// (grid value x density_scale). `emission` is radiance emitted per unit length (L_e(z)
// of the radiative transfer equation). MEDIUM_NANOVDB uses the grid fields differently: grid_offset is the
// grid's first word in `nanovdb`, grid_size is unused, and grid_min/grid_max are the box in
// the grid's index space that the majorant cells split (the active voxels and one voxel
// around them); rays are mapped to index space once per segment (the map is affine, so the
// ray parameter t is the same in both spaces).
typedef struct {
  float sigma_a[4];            // absorption, rgb (w unused)
  float sigma_s[4];            // scattering, rgb
  float emission[3];           // emitted radiance per unit length, rgb
  unsigned int emission_grid;  // 0: emission x density; else the media record (a MEDIUM_GRID,
                               // density_scale = emission_scale, no majorant) whose grid
                               // scales emission in place of the density
  float g;                     // Henyey-Greenstein asymmetry, in (-1, 1)
  unsigned int type;           // MEDIUM_*
  float density_scale;         // MEDIUM_GRID: density = scale x grid value
  float majorant;              // MEDIUM_GRID: bound of density x max channel of sigma_t over the box
  unsigned int grid_offset;    // MEDIUM_GRID: first value in `densities`, x fastest, then y, z
  unsigned int grid_size[3];   // MEDIUM_GRID: nodes along x, y, z (each >= 2)
  float grid_min[4];           // MEDIUM_GRID: the box the nodes span (w unused); density 0 outside
  float grid_max[4];
  unsigned int majorant_offset;   // MEDIUM_GRID: first majorant cell in `densities`
  unsigned int majorant_size[3];  // MEDIUM_GRID: cells along x, y, z splitting the box evenly;
                                  // each holds a bound of sigma_t over its part of the box
} Medium;

// Camera, 64 bytes. Pixel (x, y) in [-1, 1]^2 (x right, y up) maps to
//   CAMERA_PERSPECTIVE:  direction forward + x right + y up from origin, with right and
//                        up scaled by tan(xfov/2) and tan(yfov/2). A thin lens
//                        (lens_radius > 0) starts the ray at a uniform point of the lens
//                        disk around origin and aims it at the point where the pinhole ray
//                        crosses the focus plane, focus_distance along forward.
//   CAMERA_ORTHOGRAPHIC: direction forward from origin + x right + y up, with right and
//                        up scaled by the half-width and half-height of the view (xmag, ymag).
typedef struct {
  float origin[3];
  unsigned int type;  // CAMERA_*
  float forward[3];   // unit
  float lens_radius;  // thin-lens aperture radius in scene units; 0 = pinhole
  float right[3];
  float focus_distance;  // thin lens: distance of the sharp plane along forward
  float up[3];
  float pad0;
} Camera;

// Everything one launch needs besides buffers, 120 bytes.
typedef struct {
  Camera camera;
  unsigned int width;
  unsigned int height;
  unsigned int seed;
  unsigned int max_depth;  // scattering events; 0 = emission seen directly only
  unsigned int strategy;   // STRATEGY_*
  unsigned int num_lights;
  int environment_light;             // index of the LIGHT_ENVIRONMENT light, or NO_LIGHT
  unsigned int rr_depth;             // Russian roulette starts after this many bounces
  unsigned int sample_begin;         // first sample index of this launch
  unsigned int sample_count;         // samples per pixel in this launch
  unsigned int pixel_begin;          // first launch index (pixel_of_launch_index: tiles, not rows)
  unsigned int pixel_end;            // one past the last launch index of this launch
  unsigned int energy_compensation;  // 1: multiple-scattering compensation of GGX lobes (energy.cl)
  unsigned int filter;               // FILTER_*: the density of film sample offsets (filter.cl)
} RenderParams;

// Cells of the guide table that follows each CDF of n cells in env_distribution (one per
// four cells, at least one; cl/lights/environment.cl reads them, the host's
// environment_distribution writes them)
static inline int environment_guide_cells(int n) { return (n + 3) / 4 > 1 ? (n + 3) / 4 : 1; }

// Every scene buffer, in kernel-argument order: X(element type, name). This one list
// generates the kernel's parameters and SceneData (cl/scene/scene_data.cl) and the host's
// SceneBuffers, upload and argument binding (host/scene_compiler.hpp, renderer.cpp).
// Per-vertex arrays hold 3 (positions, normals, colors), 2 (uv) or 4 (tangents) floats a
// vertex (positions and normals CD_MOTION_STEPS + 1 poses a vertex, with motion blur); an array the scene
// does not need holds one dummy element. nanovdb holds the NanoVDB
// grids of MEDIUM_NANOVDB media, each a NanoVDB buffer starting on a 32-byte boundary. env_distribution holds
// the environment map's sampling CDFs (cl/lights/environment.cl), one dummy without a map. camera_steps holds
// the camera at each pose of the shutter with motion blur (CD_MOTION_STEPS), else one dummy. ggx_albedo and
// sheen_albedo are no part of the scene: each renderer computes them on its device (GGX_ALBEDO_SIZE floats,
// energy.cl; SHEEN_ALBEDO_SIZE floats, sheen.cl, only for a kernel with CD_FEATURE_SHEEN).
// One entry per line, columns aligned:
// clang-format off
#define CD_SCENE_BUFFERS(X)  \
  X(BvhNode, bvh_nodes)      \
  X(BvhTriangle, bvh_tris)   \
  X(Prim, prims)             \
  X(float, positions)        \
  X(float, normals)          \
  X(float, uv0)              \
  X(float, uv1)              \
  X(float, tangents)         \
  X(float, colors)           \
  X(Material, materials)     \
  X(TextureInfo, textures)   \
  X(Texel8, texels8)         \
  X(TexelF, texelsf)         \
  X(float, srgb_to_linear)   \
  X(Light, lights)           \
  X(AliasBin, light_alias)   \
  X(LightTreeNode, light_tree) \
  X(LightTreeTrail, light_trails) \
  X(float, env_distribution) \
  X(Medium, media)           \
  X(float, densities)        \
  X(unsigned int, nanovdb)   \
  X(Camera, camera_steps)    \
  X(float, ggx_albedo)       \
  X(float, sheen_albedo)
// clang-format on

// Every shared struct's size and the offsets that pin its layout: SIZE(type, bytes) and
// FIELD(type, field, offset). The host static_asserts these; tests/cl checks them on
// each device.
// One entry per line, columns aligned:
// clang-format off
#define CD_LAYOUT(SIZE, FIELD)                                                                                \
  SIZE(BvhNode, 128) FIELD(BvhNode, hi_x, 16) FIELD(BvhNode, lo_y, 32) FIELD(BvhNode, hi_y, 48)               \
    FIELD(BvhNode, lo_z, 64) FIELD(BvhNode, hi_z, 80) FIELD(BvhNode, child, 96) FIELD(BvhNode, pad, 112)      \
  SIZE(BvhTriangle, 48) FIELD(BvhTriangle, prim, 12) FIELD(BvhTriangle, v1, 16) FIELD(BvhTriangle, flags, 28) \
    FIELD(BvhTriangle, v2, 32)                                                                                \
  SIZE(Prim, 16) FIELD(Prim, material, 12)                                                                    \
  SIZE(TextureRef, 32) FIELD(TextureRef, texcoord, 4) FIELD(TextureRef, m, 8)                                 \
  GLTF_MATERIAL_LAYOUT(SIZE, FIELD)                                                                           \
  SIZE(ConductorMaterial, 48) FIELD(ConductorMaterial, k, 16) FIELD(ConductorMaterial, roughness, 32)         \
    FIELD(ConductorMaterial, pad, 44)                                                                         \
  SIZE(MaterialParams, GLTF_MATERIAL_BYTES)                                                                   \
  SIZE(Material, 48 + GLTF_MATERIAL_BYTES + 32 * TEX_SLOTS) FIELD(Material, normal_scale, 12)                \
    FIELD(Material, base_color, 16) FIELD(Material, emission, 32) FIELD(Material, medium, 44)                 \
    FIELD(Material, params, 48)                                                                               \
    FIELD(Material, textures, 48 + GLTF_MATERIAL_BYTES)                                                      \
  SIZE(TextureInfo, 16) FIELD(TextureInfo, flags, 12)                                                         \
  SIZE(Texel8, 4) FIELD(Texel8, a, 3)                                                                         \
  SIZE(TexelF, 16)                                                                                            \
  SIZE(AliasBin, 8) FIELD(AliasBin, alias, 4)                                                                 \
  SIZE(TriangleLight, 32) FIELD(TriangleLight, centre, 4) FIELD(TriangleLight, radius, 16)                    \
  SIZE(EnvironmentLight, 32) FIELD(EnvironmentLight, strength, 4) FIELD(EnvironmentLight, rotation, 8)        \
    FIELD(EnvironmentLight, solid_angle, 12) FIELD(EnvironmentLight, direction, 16)                           \
    FIELD(EnvironmentLight, integral, 28)                                                                     \
  SIZE(PointLight, 32) SIZE(SpotLight, 32) FIELD(SpotLight, axis, 12) FIELD(SpotLight, cone_scale, 24)        \
    FIELD(SpotLight, cone_offset, 28)                                                                         \
  SIZE(DirectionalLight, 32) FIELD(DirectionalLight, direction, 12)                                           \
  SIZE(LightParams, 32)                                                                                       \
  SIZE(Light, 64) FIELD(Light, pmf, 4) FIELD(Light, index, 8) FIELD(Light, radiance, 16)                      \
    FIELD(Light, params, 32)                                                                                  \
  SIZE(LightTreeNode, 224) FIELD(LightTreeNode, radius, 48) FIELD(LightTreeNode, axis, 64)                    \
    FIELD(LightTreeNode, intensity, 112) FIELD(LightTreeNode, cos_o, 128) FIELD(LightTreeNode, sin_o, 144)    \
    FIELD(LightTreeNode, cos_e, 160) FIELD(LightTreeNode, child, 176) FIELD(LightTreeNode, leaf, 192)         \
    FIELD(LightTreeNode, cluster, 208) FIELD(LightTreeNode, holds_all, 212) FIELD(LightTreeNode, share, 216)  \
    FIELD(LightTreeNode, min_prob, 220)                                                                       \
  SIZE(LightTreeTrail, 32) FIELD(LightTreeTrail, depth, 16)                                                   \
  SIZE(Medium, 128) FIELD(Medium, sigma_s, 16) FIELD(Medium, emission, 32) FIELD(Medium, g, 48)               \
    FIELD(Medium, emission_grid, 44) FIELD(Medium, majorant, 60) FIELD(Medium, grid_size, 68)                 \
    FIELD(Medium, grid_min, 80) FIELD(Medium, grid_max, 96) FIELD(Medium, majorant_offset, 112)               \
    FIELD(Medium, majorant_size, 116)                                                                         \
  SIZE(Camera, 64) FIELD(Camera, type, 12) FIELD(Camera, forward, 16) FIELD(Camera, lens_radius, 28)          \
    FIELD(Camera, right, 32) FIELD(Camera, focus_distance, 44) FIELD(Camera, up, 48) FIELD(Camera, pad0, 60)  \
  SIZE(RenderParams, 120) FIELD(RenderParams, width, 64) FIELD(RenderParams, strategy, 80)                    \
    FIELD(RenderParams, environment_light, 88) FIELD(RenderParams, rr_depth, 92)                              \
    FIELD(RenderParams, pixel_begin, 104) FIELD(RenderParams, pixel_end, 108)                                 \
    FIELD(RenderParams, energy_compensation, 112) FIELD(RenderParams, filter, 116)
// clang-format on

#endif  // CANDELA_DEVICE_TYPES_H
