// Closest-hit traversal four ways on one OpenCL device (a benchmark, not a test), the same
// hits from each:
//   scalar:  the renderer's bvh_intersect, one ray per work-item;
//   group:   bvh_intersect_group (below), the same walk cut into loop-free steps with a
//            barrier after each, on scalars, which a CPU driver's work-group vectorizer could
//            run as SIMD across work-items;
//   lanes8:  eight rays per work-item in float8 lanes, each lane loading its own node or
//            triangle and keeping its own stack;
//   packet8: eight rays per work-item walking the same nodes, the renderer's bvh_intersect8.
// The scene's BVH as `candela render` builds it; two ray sets of `rays` rays each:
//   camera: a pinhole view of the whole scene from the +z side, in 8x8 pixel tiles (one
//           work-group of the scalar walks each; the eight-ray walks take rows of 8 pixels);
//   random: origins uniform in the scene's box, directions uniform on the sphere (bounce rays).
// One JSON line per ray set, kernel and round: seconds (launch to finish), nanoseconds per ray,
// the share of rays that hit, and how many rays' hits differ from the scalar walk's.
//
// Usage: candela_trace_probe SCENE.gltf [DEVICE_SUBSTRING (pocl)] [ROUNDS (3)] [RAYS (262144)]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "base/device_types.hpp"
#include "compile/scene_compiler.hpp"
#include "device/device.hpp"
#include "device/kernel_sources.hpp"
#include "gltf/gltf_loader.hpp"

using namespace candela;

namespace {

const char* kSource = R"CLC(
// bvh_intersect's walk (cl/accel/bvh_traverse.cl) cut into steps that have no loop in them: each step tests one node
// and then, where the walk stands in a leaf, one triangle, and pops one stack entry where
// the walk needs one; a barrier follows every step. On PoCL the code between two barriers
// runs as a loop over the work-group's work-items with nothing looping inside it, which its
// vectorizer can turn into SIMD across work-items (a loop inside a work-item keeps it
// scalar: docs/performance.md, SIMD across paths) if that code has scalar values only: the
// step is bvh_intersect's arithmetic written without vector types, in the same order
// (PoCL 3.1's earlier SLP pass still pairs the four children's and three vertices' scalars
// into <2 x float>, which its loop vectorizer then refuses: the measurement this probe makes). Every
// work-item of the group must call it (`active` false: it only takes part in the steps);
// `steps` is three ints of __local memory the group shares: step k sets slot k mod 3 where a
// walk goes on and clears the next one, while the previous slot may still be read (the read
// after a barrier and the next step's writes share a region). Same nodes, triangles and
// order as bvh_intersect: the same hit, bit for bit.
#define BVH_WALK_DONE (-0x7fffffff - 1)
#define BVH_WALK_POP (-0x7fffffff)

// Coordinate k (0, 1, 2) of (x, y, z) by selects, not an indexed load
float bvh_pick(uint k, float x, float y, float z) { return k == 0u ? x : (k == 1u ? y : z); }

// One child's entry distance as bvh_node_children computes it (INFINITY: missed)
CD_ALWAYS_INLINE float bvh_child_entry(__global const float* b, int j, int nx, int ny, int nz, float ox, float oy,
                                       float oz, float ix, float iy, float iz, float tmax) {
  float tx = (b[nx + j] - ox) * ix, ty = (b[ny + j] - oy) * iy, tz = (b[nz + j] - oz) * iz;
  float ux = (b[(nx ^ 4) + j] - ox) * ix, uy = (b[(ny ^ 4) + j] - oy) * iy, uz = (b[(nz ^ 4) + j] - oz) * iz;
  float txy = tx > ty ? tx : ty, tz0 = tz > 0.0f ? tz : 0.0f;
  float enter = txy > tz0 ? txy : tz0;
  float uxy = ux < uy ? ux : uy, uzt = uz < tmax ? uz : tmax;
  float exit = uxy < uzt ? uxy : uzt;
  return enter <= exit * 1.000001f ? enter : INFINITY;
}

Hit bvh_intersect_group(const struct SceneData* sc, __global const BvhNode* nodes, __global const BvhTriangle* tris,
                        Ray ray, float tmax, bool active, __local int* steps) {
#pragma OPENCL FP_CONTRACT OFF
  float ht = tmax, hb1 = 0.0f, hb2 = 0.0f;
  int hprim = -1;
  float ox = ray.org.x, oy = ray.org.y, oz = ray.org.z;
  float dx = ray.dir.x, dy = ray.dir.y, dz = ray.dir.z;
  // watertight_ray's permutation and shear, on scalars
  float adx = fabs(dx), ady = fabs(dy), adz = fabs(dz);
  uint kz = adx >= ady ? (adx >= adz ? 0u : 2u) : (ady >= adz ? 1u : 2u);
  uint kx = kz == 2u ? 0u : kz + 1u;
  uint ky = kx == 2u ? 0u : kx + 1u;
  float pdx = bvh_pick(kx, dx, dy, dz), pdy = bvh_pick(ky, dx, dy, dz), pdz = bvh_pick(kz, dx, dy, dz);
  bool swap_xy = pdz < 0.0f;
  uint kt = kx;
  kx = swap_xy ? ky : kx;
  ky = swap_xy ? kt : ky;
  float qdx = swap_xy ? pdy : pdx, qdy = swap_xy ? pdx : pdy;
  float sx = qdx / pdz, sy = qdy / pdz, sz = 1.0f / pdz;
  // safe_inverse, on scalars
  const float tiny = 1e-30f;
  float ix = 1.0f / (fabs(dx) > tiny ? dx : copysign(tiny, dx));
  float iy = 1.0f / (fabs(dy) > tiny ? dy : copysign(tiny, dy));
  float iz = 1.0f / (fabs(dz) > tiny ? dz : copysign(tiny, dz));
  int nx = ix >= 0.0f ? 0 : 4, ny = iy >= 0.0f ? 8 : 12, nz = iz >= 0.0f ? 16 : 20;
  int stack[BVH_STACK_SIZE];
  float stack_entry[BVH_STACK_SIZE];
  int sp = 0;
  int ref = active ? 0 : BVH_WALK_DONE;  // >= 0: a node; < 0: triangle ~ref of a leaf; or POP, DONE
  uint lid = get_local_id(0);
  if (lid == 0u) steps[0] = 0;
  barrier(CLK_LOCAL_MEM_FENCE);
  uint slot = 0u;
  int go = 1;
  while (go) {
    if (ref >= 0) {
      __global const float* b = (__global const float*)&nodes[ref];
      float d0 = bvh_child_entry(b, 0, nx, ny, nz, ox, oy, oz, ix, iy, iz, ht);
      float d1 = bvh_child_entry(b, 1, nx, ny, nz, ox, oy, oz, ix, iy, iz, ht);
      float d2 = bvh_child_entry(b, 2, nx, ny, nz, ox, oy, oz, ix, iy, iz, ht);
      float d3 = bvh_child_entry(b, 3, nx, ny, nz, ox, oy, oz, ix, iy, iz, ht);
      __global const int* k = nodes[ref].child;
      int c0 = k[0], c1 = k[1], c2 = k[2], c3 = k[3];
      BVH_SORT2(d0, c0, d1, c1);
      BVH_SORT2(d2, c2, d3, c3);
      BVH_SORT2(d0, c0, d2, c2);
      BVH_SORT2(d1, c1, d3, c3);
      BVH_SORT2(d1, c1, d2, c2);
      bvh_push_farther(stack, stack_entry, &sp, d1, c1, d2, c2, d3, c3);
      ref = d0 != INFINITY ? c0 : BVH_WALK_POP;
    }
    if (ref < 0 && ref > BVH_WALK_POP) {
      // intersect_triangle's arithmetic on scalars
      int i = ~ref;
      __global const BvhTriangle* tri = &tris[i];
      uint flags = tri->flags;
      float a0 = tri->v0[0] - ox, a1 = tri->v0[1] - oy, a2 = tri->v0[2] - oz;
      float b0 = tri->v1[0] - ox, b1v = tri->v1[1] - oy, b2v = tri->v1[2] - oz;
      float e0 = tri->v2[0] - ox, e1 = tri->v2[1] - oy, e2 = tri->v2[2] - oz;
      float az = bvh_pick(kz, a0, a1, a2), bz = bvh_pick(kz, b0, b1v, b2v), cz = bvh_pick(kz, e0, e1, e2);
      float ax = bvh_pick(kx, a0, a1, a2) - sx * az, ay = bvh_pick(ky, a0, a1, a2) - sy * az;
      float bx = bvh_pick(kx, b0, b1v, b2v) - sx * bz, by = bvh_pick(ky, b0, b1v, b2v) - sy * bz;
      float cx = bvh_pick(kx, e0, e1, e2) - sx * cz, cy = bvh_pick(ky, e0, e1, e2) - sy * cz;
      float u = edge_function(bx, by, cx, cy);
      float v = edge_function(cx, cy, ax, ay);
      float w = edge_function(ax, ay, bx, by);
      bool inside = !((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f));
      float det = u + v + w;
      float tt = u * (sz * az) + v * (sz * bz) + w * (sz * cz);
      bool in_range = det > 0.0f ? !(tt <= 0.0f || tt >= ht * det) : !(tt >= 0.0f || tt <= ht * det);
      bool hit = inside && det != 0.0f && in_range;
#if CD_FEATURE_ALPHA
      if (hit && (flags & BVH_TRI_ALPHA_TEST)) {
        float inv = 1.0f / det;
        hit = scene_alpha_passes(sc, tri->prim, v * inv, w * inv, ray);
      }
#endif
      if (hit) {
        float inv_det = 1.0f / det;
        ht = tt * inv_det;
        hb1 = v * inv_det;
        hb2 = w * inv_det;
        hprim = i;
      }
      ref = (flags & BVH_TRI_LAST) ? BVH_WALK_POP : ~(i + 1);
    }
    if (ref == BVH_WALK_POP) {
      // One entry per step; one that starts beyond the closest hit leaves the walk popping
      if (sp == 0) {
        ref = BVH_WALK_DONE;
      } else {
        --sp;
        ref = stack_entry[sp] > ht ? BVH_WALK_POP : stack[sp];
      }
    }
    uint next = slot == 2u ? 0u : slot + 1u;
    if (ref != BVH_WALK_DONE) steps[slot] = 1;
    if (lid == 0u) steps[next] = 0;
    barrier(CLK_LOCAL_MEM_FENCE);
    go = steps[slot];
    slot = next;
  }
  Hit hit;
  hit.t = ht;
  hit.b1 = hb1;
  hit.b2 = hb2;
  hit.prim = hprim >= 0 ? (int)tris[hprim].prim : -1;
  return hit;
}


Ray probe_ray(__global const float4* rays, uint i) {
  Ray r;
  r.org = rays[2u * i].xyz;
  r.dir = rays[2u * i + 1u].xyz;
  return r;
}
float4 probe_hit(Hit h) { return (float4)(h.t, h.b1, h.b2, as_float(h.prim)); }
// Rays first..first+7 (fields written one by one: llvmpipe mistranslated a struct returned
// straight into an array element)
void probe_rays8(__global const float4* rays, uint first, Ray* r, float* tmax) {
  for (uint l = 0u; l < 8u; ++l) {
    r[l].org = rays[2u * (first + l)].xyz;
    r[l].dir = rays[2u * (first + l) + 1u].xyz;
    tmax[l] = rays[2u * (first + l)].w;
  }
}
__kernel void probe_trace_scalar(__global const BvhNode* nodes, __global const BvhTriangle* tris,
                                 __global const float4* rays, __global float4* out) {
  uint i = get_global_id(0);
  out[i] = probe_hit(bvh_intersect(0, nodes, tris, probe_ray(rays, i), rays[2u * i].w));
}
__kernel void probe_trace_group(__global const BvhNode* nodes, __global const BvhTriangle* tris,
                                __global const float4* rays, __global float4* out) {
  __local int steps[3];
  uint i = get_global_id(0);
  out[i] = probe_hit(bvh_intersect_group(0, nodes, tris, probe_ray(rays, i), rays[2u * i].w, true, steps));
}

// Explicit lanes: one work-item walks eight rays, its values in float8/int8 where the eight
// do the same arithmetic (the node test, the triangle test, the nearest-first order), each
// lane loading its own node or triangle, and the stacks per lane. A step tests a node in the
// lanes that stand at one and a triangle in the lanes in a leaf, then pops where a lane needs
// it; the walk ends when every lane is done. Same nodes, triangles and order per ray as
// bvh_intersect, so the same hits bit for bit (the alpha test is not compiled in here).
float8 lanes_gather(__global const float* base, int8 k) {
  return (float8)(base[k.s0], base[k.s1], base[k.s2], base[k.s3], base[k.s4], base[k.s5], base[k.s6], base[k.s7]);
}
int8 lanes_gather_int(__global const int* base, int8 k) {
  return (int8)(base[k.s0], base[k.s1], base[k.s2], base[k.s3], base[k.s4], base[k.s5], base[k.s6], base[k.s7]);
}
float8 lanes_entry(__global const float* nf, int8 base, int j, int8 nx, int8 ny, int8 nz, float8 ox, float8 oy,
                   float8 oz, float8 ix, float8 iy, float8 iz, float8 tmax) {
  float8 tx = (lanes_gather(nf, base + nx + j) - ox) * ix, ty = (lanes_gather(nf, base + ny + j) - oy) * iy;
  float8 tz = (lanes_gather(nf, base + nz + j) - oz) * iz;
  float8 ux = (lanes_gather(nf, base + (nx ^ 4) + j) - ox) * ix, uy = (lanes_gather(nf, base + (ny ^ 4) + j) - oy) * iy;
  float8 uz = (lanes_gather(nf, base + (nz ^ 4) + j) - oz) * iz;
  float8 txy = select(ty, tx, tx > ty), tz0 = select((float8)(0.0f), tz, tz > 0.0f);
  float8 enter = select(tz0, txy, txy > tz0);
  float8 uxy = select(uy, ux, ux < uy), uzt = select(tmax, uz, uz < tmax);
  float8 exit = select(uzt, uxy, uxy < uzt);
  return select((float8)(INFINITY), enter, enter <= exit * 1.000001f);
}
#define LANES_SORT2(da, ca, db, cb) \
  {                                 \
    int8 s_ = db < da;              \
    float8 dt_ = select(da, db, s_);  \
    int8 ct_ = select(ca, cb, s_);    \
    db = select(db, da, s_);          \
    cb = select(cb, ca, s_);          \
    da = dt_;                         \
    ca = ct_;                         \
  }

__kernel void probe_trace_lanes8(__global const BvhNode* nodes, __global const BvhTriangle* tris,
                                 __global const float4* rays, __global float4* out) {
  uint first = 8u * (uint)get_global_id(0);
  Ray r8[8];
  float tm[8];
  probe_rays8(rays, first, r8, tm);
  BvhRays8 r = bvh_rays8(r8);
  float8 ox = r.ox, oy = r.oy, oz = r.oz, ix = r.ix, iy = r.iy, iz = r.iz;
  int8 nx = select((int8)(4), (int8)(0), ix >= 0.0f), ny = select((int8)(12), (int8)(8), iy >= 0.0f);
  int8 nz = select((int8)(20), (int8)(16), iz >= 0.0f);
  float8 ht = vload8(0, tm), hb1 = (float8)(0.0f), hb2 = (float8)(0.0f);
  int8 hprim = (int8)(-1);
  int8 ref = (int8)(0);
  int sp[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int stack[8][BVH_STACK_SIZE];
  float stack_entry[8][BVH_STACK_SIZE];
  __global const float* nf = (__global const float*)nodes;
  __global const int* ni = (__global const int*)nodes;
  __global const float* tf = (__global const float*)tris;
  __global const int* ti = (__global const int*)tris;
  while (any(ref != BVH_WALK_DONE)) {
    int8 at_node = ref >= 0;
    if (any(at_node)) {
      int8 base = select((int8)(0), ref * 32, at_node);
      float8 d0 = lanes_entry(nf, base, 0, nx, ny, nz, ox, oy, oz, ix, iy, iz, ht);
      float8 d1 = lanes_entry(nf, base, 1, nx, ny, nz, ox, oy, oz, ix, iy, iz, ht);
      float8 d2 = lanes_entry(nf, base, 2, nx, ny, nz, ox, oy, oz, ix, iy, iz, ht);
      float8 d3 = lanes_entry(nf, base, 3, nx, ny, nz, ox, oy, oz, ix, iy, iz, ht);
      int8 c0 = lanes_gather_int(ni, base + 24), c1 = lanes_gather_int(ni, base + 25);
      int8 c2 = lanes_gather_int(ni, base + 26), c3 = lanes_gather_int(ni, base + 27);
      LANES_SORT2(d0, c0, d1, c1);
      LANES_SORT2(d2, c2, d3, c3);
      LANES_SORT2(d0, c0, d2, c2);
      LANES_SORT2(d1, c1, d3, c3);
      LANES_SORT2(d1, c1, d2, c2);
      float dd[4][8];
      int cc[4][8], at[8];
      vstore8(d1, 0, dd[1]), vstore8(d2, 0, dd[2]), vstore8(d3, 0, dd[3]);
      vstore8(c1, 0, cc[1]), vstore8(c2, 0, cc[2]), vstore8(c3, 0, cc[3]);
      vstore8(at_node, 0, at);
      for (int l = 0; l < 8; ++l) {
        if (!at[l]) continue;
        for (int j = 3; j >= 1; --j) {
          stack[l][sp[l]] = cc[j][l];
          stack_entry[l][sp[l]] = dd[j][l];
          sp[l] += dd[j][l] != INFINITY;
        }
      }
      ref = select(ref, select((int8)(BVH_WALK_POP), c0, d0 != INFINITY), at_node);
    }
    int8 at_tri = ref < 0 && ref > BVH_WALK_POP;
    if (any(at_tri)) {
      int8 i = select((int8)(0), ~ref, at_tri);
      int8 tb = i * 12;
      int8 flags = lanes_gather_int(ti, tb + 7);
      float8 v[9];
      for (int c = 0; c < 3; ++c) {
        v[c] = lanes_gather(tf, tb + c);
        v[3 + c] = lanes_gather(tf, tb + 4 + c);
        v[6 + c] = lanes_gather(tf, tb + 8 + c);
      }
      float8 t, b1, b2;
      int8 hit = at_tri & intersect_triangle8(&r, v, ht, &t, &b1, &b2);
      ht = select(ht, t, hit);
      hb1 = select(hb1, b1, hit);
      hb2 = select(hb2, b2, hit);
      hprim = select(hprim, i, hit);
      ref = select(ref, select(~(i + 1), (int8)(BVH_WALK_POP), (flags & (int)BVH_TRI_LAST) != 0), at_tri);
    }
    int r[8];
    float t8[8];
    vstore8(ref, 0, r);
    vstore8(ht, 0, t8);
    for (int l = 0; l < 8; ++l) {
      if (r[l] != BVH_WALK_POP) continue;
      if (sp[l] == 0) {
        r[l] = BVH_WALK_DONE;
      } else {
        --sp[l];
        r[l] = stack_entry[l][sp[l]] > t8[l] ? BVH_WALK_POP : stack[l][sp[l]];
      }
    }
    ref = vload8(0, r);
  }
  float fb1[8], fb2[8], ft[8];
  int fp[8];
  vstore8(ht, 0, ft), vstore8(hb1, 0, fb1), vstore8(hb2, 0, fb2), vstore8(hprim, 0, fp);
  for (int l = 0; l < 8; ++l) {
    Hit h;
    h.t = ft[l];
    h.b1 = fb1[l];
    h.b2 = fb2[l];
    h.prim = fp[l] >= 0 ? (int)tris[fp[l]].prim : -1;
    out[first + l] = probe_hit(h);
  }
}

// Packets: the renderer's bvh_intersect8 (cl/accel/bvh_traverse.cl), eight rays per work-item
__kernel void probe_trace_packet8(__global const BvhNode* nodes, __global const BvhTriangle* tris,
                                  __global const float4* rays, __global float4* out) {
  uint first = 8u * (uint)get_global_id(0);
  Ray r[8];
  float tmax[8];
  probe_rays8(rays, first, r, tmax);
  Hit h[8];
  bvh_intersect8(0, nodes, tris, r, tmax, h);
  for (uint l = 0u; l < 8u; ++l) out[first + l] = probe_hit(h[l]);
}
)CLC";

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE.gltf [DEVICE_SUBSTRING] [ROUNDS] [RAYS, a multiple of 64]\n", argv[0]);
    return 2;
  }
  std::string want = argc > 2 ? argv[2] : "pocl";
  int rounds = argc > 3 ? std::atoi(argv[3]) : 3;
  size_t count = argc > 4 ? size_t(std::atoll(argv[4])) : size_t(1) << 18;
  if (rounds < 1 || count < 64 || count % 64 != 0) {
    std::fprintf(stderr, "%s: ROUNDS >= 1 and RAYS a multiple of 64\n", argv[0]);
    return 2;
  }
  try {
    CompiledScene c = compile_scene(load_gltf(argv[1]));
    const auto& b = c.buffers;
    DeviceEntry device = select_device(want);
    cl::Context context(device.device);
    cl::CommandQueue queue(context, device.device);
    cl::Program program(context, renderer_program_source() + kSource);
    try {
      program.build({device.device}, ("-cl-std=CL1.2 " + c.features.build_options()).c_str());
    } catch (const cl::BuildError& e) {
      for (const auto& log : e.getBuildLog()) std::fprintf(stderr, "%s\n", log.second.c_str());
      throw;
    }
    // The scene's box from its vertex positions
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i + 2 < b.positions.size(); i += 3)
      for (int a = 0; a < 3; ++a)
        lo[a] = std::fmin(lo[a], b.positions[i + a]), hi[a] = std::fmax(hi[a], b.positions[i + a]);
    float center[3], extent = 0.0f;
    for (int a = 0; a < 3; ++a) center[a] = 0.5f * (lo[a] + hi[a]), extent = std::fmax(extent, hi[a] - lo[a]);
    std::vector<std::vector<cl_float4>> sets(2);
    size_t side = size_t(std::sqrt(double(count))) / 8 * 8;
    side = side < 8 ? 8 : side;
    for (size_t i = 0; i < count; ++i) {  // camera: 8x8 tiles, row-major inside a tile, the tiles row-major
      size_t tile = (i / 64) % ((side / 8) * (side / 8)), k = i % 64;
      size_t x = (tile % (side / 8)) * 8 + k % 8, y = (tile / (side / 8)) * 8 + k / 8;
      float u = (float(x) + 0.5f) / float(side) * 2.0f - 1.0f, v = 1.0f - (float(y) + 0.5f) / float(side) * 2.0f;
      float d[3] = {0.6f * u, 0.6f * v, -1.0f}, n = std::sqrt(d[0] * d[0] + d[1] * d[1] + 1.0f);
      sets[0].push_back({{center[0], center[1], center[2] + 1.5f * extent, INFINITY}});
      sets[0].push_back({{d[0] / n, d[1] / n, d[2] / n, 0.0f}});
    }
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    for (size_t i = 0; i < count; ++i) {
      float z = 2.0f * u01(rng) - 1.0f, phi = 6.2831853f * u01(rng), r = std::sqrt(std::fmax(0.0f, 1.0f - z * z));
      sets[1].push_back({{lo[0] + (hi[0] - lo[0]) * u01(rng), lo[1] + (hi[1] - lo[1]) * u01(rng),
                          lo[2] + (hi[2] - lo[2]) * u01(rng), INFINITY}});
      sets[1].push_back({{r * std::cos(phi), r * std::sin(phi), z, 0.0f}});
    }
    cl::Buffer nodes(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, b.bvh_nodes.size() * sizeof(b.bvh_nodes[0]),
                     const_cast<dev::BvhNode*>(b.bvh_nodes.data()));
    cl::Buffer tris(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, b.bvh_tris.size() * sizeof(b.bvh_tris[0]),
                    const_cast<dev::BvhTriangle*>(b.bvh_tris.data()));
    cl::Buffer out(context, CL_MEM_WRITE_ONLY, count * sizeof(cl_float4));
    const char* set_names[] = {"camera", "random"};
    const char* kernels[] = {"probe_trace_scalar", "probe_trace_group", "probe_trace_lanes8", "probe_trace_packet8"};
    for (int s = 0; s < 2; ++s) {
      cl::Buffer rays(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sets[s].size() * sizeof(cl_float4),
                      sets[s].data());
      std::vector<cl_float4> reference;
      for (int round = 0; round <= rounds; ++round)  // round 0 warms the driver's lazy code generation up
        for (const char* name : kernels) {
          cl::Kernel k(program, name);
          k.setArg(0, nodes);
          k.setArg(1, tris);
          k.setArg(2, rays);
          k.setArg(3, out);
          auto t0 = std::chrono::steady_clock::now();
          bool lanes = std::strcmp(name, "probe_trace_lanes8") == 0 || std::strcmp(name, "probe_trace_packet8") == 0;
          queue.enqueueNDRangeKernel(k, cl::NullRange, cl::NDRange(lanes ? count / 8 : count),
                                     cl::NDRange(lanes ? 8 : 64));
          queue.finish();
          double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          std::vector<cl_float4> hits(count);
          queue.enqueueReadBuffer(out, CL_TRUE, 0, count * sizeof(cl_float4), hits.data());
          if (reference.empty()) reference = hits;
          size_t differ = 0;  // rays whose hit is not the scalar walk's bit for bit
          for (size_t i = 0; i < count; ++i) differ += std::memcmp(&hits[i], &reference[i], sizeof(cl_float4)) != 0;
          size_t hit = 0;
          for (const cl_float4& h : hits) {
            int prim;
            std::memcpy(&prim, &h.s[3], sizeof prim);
            hit += prim >= 0;
          }
          if (round > 0)
            std::printf(
                "{\"scene\": \"%s\", \"device\": \"%s\", \"rays\": \"%s\", \"kernel\": \"%s\", \"round\": %d, "
                "\"count\": %zu, \"seconds\": %.4f, \"ns_per_ray\": %.1f, \"hit_share\": %.3f, "
                "\"differ_from_scalar\": %zu}\n",
                argv[1], device.description().c_str(), set_names[s], name + 12, round, count, sec,
                1e9 * sec / double(count), double(hit) / double(count), differ);
        }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "candela_trace_probe: %s\n", e.what());
    return 1;
  }
  return 0;
}
