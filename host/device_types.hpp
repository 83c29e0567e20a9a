// Host view of cl/device_types.h, the one definition of every struct that crosses to
// the device, with its layout pinned down. tests/layout_test.cpp checks the same
// numbers on the device itself.
#pragma once

#include <cstddef>

namespace candela::dev {
#include "cl/device_types.h"
}  // namespace candela::dev

namespace candela::dev {
static_assert(sizeof(float) == 4 && sizeof(int) == 4 && sizeof(unsigned int) == 4);

static_assert(sizeof(BvhNode) == 32);
static_assert(offsetof(BvhNode, left) == 12 && offsetof(BvhNode, bmax) == 16);
static_assert(offsetof(BvhNode, right) == 28);

static_assert(sizeof(Triangle) == 48);
static_assert(offsetof(Triangle, material) == 12 && offsetof(Triangle, v1) == 16);
static_assert(offsetof(Triangle, prim) == 28 && offsetof(Triangle, v2) == 32);
static_assert(offsetof(Triangle, pad0) == 44);

static_assert(sizeof(TriangleShading) == 64);
static_assert(offsetof(TriangleShading, uv0_u) == 12 && offsetof(TriangleShading, n1) == 16);
static_assert(offsetof(TriangleShading, uv2_v) == 56);

static_assert(sizeof(TriangleColors) == 48 && offsetof(TriangleColors, c2) == 32);
static_assert(sizeof(Material) == 64);
static_assert(offsetof(Material, base_color) == 16 && offsetof(Material, emission) == 32);
static_assert(offsetof(Material, params) == 48 && offsetof(Material, emission_texture) == 12);

static_assert(sizeof(TextureInfo) == 16);
static_assert(sizeof(Light) == 32 && offsetof(Light, radiance) == 16);

static_assert(sizeof(Camera) == 64);
static_assert(offsetof(Camera, forward) == 16 && offsetof(Camera, right) == 32);
static_assert(offsetof(Camera, up) == 48);

static_assert(sizeof(RenderParams) == 128);
static_assert(offsetof(RenderParams, background) == 64 && offsetof(RenderParams, width) == 80);
static_assert(offsetof(RenderParams, strategy) == 96 && offsetof(RenderParams, rr_depth) == 112);
static_assert(offsetof(RenderParams, pixel_begin) == 116 && offsetof(RenderParams, pixel_end) == 120);
}  // namespace candela::dev
