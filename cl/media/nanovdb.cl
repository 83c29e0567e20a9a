// NanoVDB float grids on the device (compiled in with CD_FEATURE_NANOVDB): NanoVDB's own
// pointer-less C port, PNanoVDB.h (libnanovdb-dev), reads a grid's linear buffer as the
// host wrote it (one grid per run of 32-bit words in the `nanovdb` scene buffer). This file
// is the only one that includes the header; media.cl uses the functions at its end.
//
// The header is compiled with its C platform (PNANOVDB_C), which is C99, with these
// adaptations to OpenCL C 1.2, none of them vendor extensions:
// - the buffer is ours (PNANOVDB_BUF_CUSTOM): a __global pointer, 32-bit byte addresses
//   (PNANOVDB_ADDRESS_32: a grid below 4 GiB), 64-bit words read as two 32-bit ones;
// - the fixed-width types are typedefs of OpenCL's, and the host removes the header's
//   `#include <stdint.h>` and puts its program-scope tables in __constant
//   (pnanovdb_opencl_text in host/kernel_sources.cpp, which also resolves the #include);
// - the header's `double` is `pnanovdb_double_t`, a float (the host renames the type in its
//   text): devices without cl_khr_fp64 (rusticl on llvmpipe) reject `double`, and only its
//   double-precision accessors (the map's matd, the world bounding box), which this file
//   never calls, use it;
// - its memcpy (PNANOVDB_MEMCPY_CUSTOM) is a byte copy, which the compiler turns into one
//   move.
// NanoVDB reads the float map (matf, invmatf, vecf) for world <-> index.

#if CD_FEATURE_NANOVDB

typedef uint uint32_t;
typedef int int32_t;
typedef ulong uint64_t;
typedef long int64_t;

#define PNANOVDB_C
#define PNANOVDB_ADDRESS_32
#define PNANOVDB_BUF_CUSTOM
#define PNANOVDB_MEMCPY_CUSTOM

typedef __global const uint* pnanovdb_buf_t;
typedef uint pnanovdb_grid_type_t;
#define PNANOVDB_GRID_TYPE_GET(grid_type, name) pnanovdb_grid_type_constants[grid_type].name

static inline uint pnanovdb_buf_read_uint32(pnanovdb_buf_t buf, uint byte_offset) { return buf[byte_offset >> 2u]; }

static inline ulong pnanovdb_buf_read_uint64(pnanovdb_buf_t buf, uint byte_offset) {
  uint w = byte_offset >> 2u;
  return (ulong)buf[w] | ((ulong)buf[w + 1u] << 32);
}

typedef float pnanovdb_double_t;

// The header reinterprets the bits of a private scalar as another type of the same size
// with memcpy(&to, &from, sizeof(to)) (float from uint; the double one is never called)
static inline void pnanovdb_memcpy(void* dst, const void* src, size_t n) {
  for (size_t i = 0; i < n; ++i) ((uchar*)dst)[i] = ((const uchar*)src)[i];
}

#include <nanovdb/PNanoVDB.h>

// A float grid and a read accessor (which caches the nodes of the last lookup: neighbouring
// lookups, such as the 8 of a trilinear one, skip the walk from the root)
typedef struct {
  pnanovdb_buf_t buf;
  pnanovdb_grid_handle_t grid;
  pnanovdb_readaccessor_t acc;
} NanoVdbGrid;

// The grid whose buffer starts at `words` (the host checked that it is a float grid)
NanoVdbGrid nanovdb_grid(__global const uint* words) {
  NanoVdbGrid g;
  g.buf = words;
  g.grid.address.byte_offset = 0u;
  pnanovdb_root_handle_t root = pnanovdb_tree_get_root(g.buf, pnanovdb_grid_get_tree(g.buf, g.grid));
  pnanovdb_readaccessor_init(&g.acc, root);
  return g;
}

// World point to index space through the grid's map (any affine map: rotation, shear,
// non-uniform scale); voxel ijk sits at index point ijk
float3 nanovdb_world_to_index(const NanoVdbGrid* g, float3 p) {
  pnanovdb_vec3_t v = {p.x, p.y, p.z};
  pnanovdb_vec3_t r = pnanovdb_grid_world_to_indexf(g->buf, g->grid, &v);
  return (float3)(r.x, r.y, r.z);
}

// World direction to index space (the map's linear part only)
float3 nanovdb_world_to_index_dir(const NanoVdbGrid* g, float3 d) {
  pnanovdb_vec3_t v = {d.x, d.y, d.z};
  pnanovdb_vec3_t r = pnanovdb_grid_world_to_index_dirf(g->buf, g->grid, &v);
  return (float3)(r.x, r.y, r.z);
}

// The value of voxel ijk (the background, or a tile's value, where no voxel is stored)
float nanovdb_value(NanoVdbGrid* g, int x, int y, int z) {
  pnanovdb_coord_t ijk = {x, y, z};
  pnanovdb_address_t a = pnanovdb_readaccessor_get_value_address(PNANOVDB_GRID_TYPE_FLOAT, g->buf, &g->acc, &ijk);
  return pnanovdb_read_float(g->buf, a);
}

// Trilinear interpolation between the 8 voxels around index point q
float nanovdb_trilinear(NanoVdbGrid* g, float3 q) {
  float3 f0 = floor(q);
  float3 f = q - f0;
  int x = (int)f0.x, y = (int)f0.y, z = (int)f0.z;
  float c00 = mix(nanovdb_value(g, x, y, z), nanovdb_value(g, x + 1, y, z), f.x);
  float c10 = mix(nanovdb_value(g, x, y + 1, z), nanovdb_value(g, x + 1, y + 1, z), f.x);
  float c01 = mix(nanovdb_value(g, x, y, z + 1), nanovdb_value(g, x + 1, y, z + 1), f.x);
  float c11 = mix(nanovdb_value(g, x, y + 1, z + 1), nanovdb_value(g, x + 1, y + 1, z + 1), f.x);
  return mix(mix(c00, c10, f.y), mix(c01, c11, f.y), f.z);
}

#endif  // CD_FEATURE_NANOVDB
