// Bilinear lookup of RGBA8 textures in one shared texel array. sRGB texels are decoded
// through a 256-entry table before filtering, so filtering happens in linear space.

#ifndef CD_FEATURE_TEXTURES
#define CD_FEATURE_TEXTURES 1
#endif

// Every texture of the scene
typedef struct {
  __global const TextureInfo* info;
  __global const uchar4* texels;
  __global const float* srgb_to_linear;  // 256 entries
} TextureSet;

int texture_wrap(int i, int n, uint mode) {
  if (mode == WRAP_CLAMP) return clamp(i, 0, n - 1);
  if (mode == WRAP_MIRROR) {
    int period = 2 * n;
    int m = i % period;
    if (m < 0) m += period;
    return m < n ? m : period - 1 - m;
  }
  int m = i % n;
  return m < 0 ? m + n : m;
}

float4 texture_texel(__global const TextureInfo* tex, __global const uchar4* texels,
                     __global const float* srgb_to_linear, int x, int y) {
  int w = (int)tex->width, h = (int)tex->height;
  x = texture_wrap(x, w, tex->flags & 0xffu);
  y = texture_wrap(y, h, (tex->flags >> 8) & 0xffu);
  uchar4 c = texels[tex->offset + (uint)y * (uint)w + (uint)x];
  if (tex->flags & TEXTURE_SRGB)
    return (float4)(srgb_to_linear[c.x], srgb_to_linear[c.y], srgb_to_linear[c.z], c.w / 255.0f);
  return convert_float4(c) / 255.0f;
}

// uv in glTF convention: (0, 0) is the top-left corner of the image
float4 texture_sample(__global const TextureInfo* tex, __global const uchar4* texels,
                      __global const float* srgb_to_linear, float2 uv) {
  float x = uv.x * (float)tex->width - 0.5f;
  float y = uv.y * (float)tex->height - 0.5f;
  // Keep huge coordinates in range before converting to int
  x = fmod(x, 8388608.0f);
  y = fmod(y, 8388608.0f);
  float fx = floor(x), fy = floor(y);
  float ax = x - fx, ay = y - fy;
  int ix = (int)fx, iy = (int)fy;
  float4 c00 = texture_texel(tex, texels, srgb_to_linear, ix, iy);
  float4 c10 = texture_texel(tex, texels, srgb_to_linear, ix + 1, iy);
  float4 c01 = texture_texel(tex, texels, srgb_to_linear, ix, iy + 1);
  float4 c11 = texture_texel(tex, texels, srgb_to_linear, ix + 1, iy + 1);
  return mix(mix(c00, c10, ax), mix(c01, c11, ax), ay);
}

// Texture `index` of the set at uv; white when the scene has no textures compiled in
float4 textures_lookup(const TextureSet* set, int index, float2 uv) {
#if CD_FEATURE_TEXTURES
  if (index != NO_TEXTURE)
    return texture_sample(&set->info[index], set->texels, set->srgb_to_linear, uv);
#endif
  return (float4)(1.0f);
}
