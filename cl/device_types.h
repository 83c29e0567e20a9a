// Structs that cross between host and device, defined once.
// Included by the OpenCL program (first in the source list) and by the host inside
// namespace candela::dev (host/device_types.hpp), which static_asserts every layout.
// Only 4-byte scalars and arrays of them: no float3, no vector types, explicit padding.

#ifndef CANDELA_DEVICE_TYPES_H
#define CANDELA_DEVICE_TYPES_H

// Material types (switch-dispatched in bsdf.cl)
#define MATERIAL_DIFFUSE 0u

// Light types (light-selection table in lights.cl)
#define LIGHT_TRIANGLE 0u
#define LIGHT_BACKGROUND 1u

// Integration strategies (no MIS: each light path is counted by exactly one of them)
#define STRATEGY_NEE 0u
#define STRATEGY_BSDF 1u

// Texture flags: wrap modes (glTF sampler wrapS in bits 0-7, wrapT in bits 8-15)
// and colour encoding
#define WRAP_REPEAT 0u
#define WRAP_CLAMP 1u
#define WRAP_MIRROR 2u
#define TEXTURE_SRGB 0x10000u

#define NO_TEXTURE (-1)

// BVH node, 32 bytes. Interior: count == 0, children at `left` and `right`.
// Leaf: count > 0 triangles starting at `first` (left == first).
typedef struct {
  float bmin[3];
  int left;  // interior: left child; leaf: first triangle
  float bmax[3];
  int right;  // interior: right child; leaf: -(triangle count)
} BvhNode;

// Triangle positions in BVH order, 48 bytes.
typedef struct {
  float v0[3];
  unsigned int material;
  float v1[3];
  unsigned int prim;  // index into TriangleShading (original order)
  float v2[3];
  unsigned int pad0;
} Triangle;

// Per-vertex shading data of one triangle, 64 bytes.
typedef struct {
  float n0[3];
  float uv0_u;
  float n1[3];
  float uv0_v;
  float n2[3];
  float uv1_u;
  float uv1_v;
  float uv2_u;
  float uv2_v;
  float pad0;
} TriangleShading;

// Vertex colors (glTF COLOR_0, linear RGB) of one triangle, 48 bytes; uploaded only for
// scenes that have them (CD_FEATURE_VERTEX_COLORS).
typedef struct {
  float c0[4];
  float c1[4];
  float c2[4];
} TriangleColors;

// Material, 64 bytes. Colours are linear RGB.
typedef struct {
  unsigned int type;  // MATERIAL_*
  int base_color_texture;  // index into TextureInfo or NO_TEXTURE
  unsigned int double_sided;
  int emission_texture;  // index into TextureInfo or NO_TEXTURE; scales `emission`
  float base_color[4];  // rgba factor
  float emission[4];  // rgb radiance (factor x strength), w unused
  float params[4];  // reserved: roughness, metallic, ior, anisotropy
} Material;

// A texture inside the shared texel array (RGBA8 texels), 16 bytes.
typedef struct {
  unsigned int offset;  // first texel
  unsigned int width;
  unsigned int height;
  unsigned int flags;  // wrap_s | wrap_t << 8 | TEXTURE_SRGB
} TextureInfo;

// One entry of the light-selection table, 32 bytes. Light i is selected when a uniform
// 32-bit integer x satisfies threshold[i-1] <= x < threshold[i] (threshold[n-1] is 2^32,
// not stored); `pmf` is exactly that probability, so the estimator divides by what the
// kernel realizes.
typedef struct {
  unsigned int type;  // LIGHT_*
  unsigned int index;  // LIGHT_TRIANGLE: index into Triangle array
  float area;  // LIGHT_TRIANGLE: triangle area (world units)
  float pmf;  // selection probability
  float radiance[4];  // emitted radiance, rgb
} Light;

// Pinhole camera, 64 bytes: ray direction = forward + (2x-1) right + (1-2y) up.
typedef struct {
  float origin[3];
  float pad0;
  float forward[3];
  float pad1;
  float right[3];  // scaled by tan(xfov/2)
  float pad2;
  float up[3];  // scaled by tan(yfov/2)
  float pad3;
} Camera;

// Everything one launch needs besides buffers, 128 bytes.
typedef struct {
  Camera camera;
  float background[4];  // constant radiance of escaping rays, rgb
  unsigned int width;
  unsigned int height;
  unsigned int seed;
  unsigned int max_depth;  // scattering events; 0 = emission seen directly only
  unsigned int strategy;  // STRATEGY_*
  unsigned int num_lights;
  unsigned int sample_begin;  // first sample index of this launch
  unsigned int sample_count;  // samples per pixel in this launch
  unsigned int rr_depth;  // Russian roulette starts after this many bounces
  unsigned int pixel_begin;  // first pixel of this launch (row-major)
  unsigned int pixel_end;  // one past the last pixel of this launch
  unsigned int pad0;
} RenderParams;

#endif  // CANDELA_DEVICE_TYPES_H
