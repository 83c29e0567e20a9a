// Bilinear lookup of linear RGBA textures in one shared texel array.

#ifndef CD_FEATURE_TEXTURES
#define CD_FEATURE_TEXTURES 1
#endif

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

float4 texture_texel(__global const TextureInfo* tex, __global const float4* texels, int x,
                     int y) {
  int w = (int)tex->width, h = (int)tex->height;
  x = texture_wrap(x, w, tex->wrap & 0xffu);
  y = texture_wrap(y, h, (tex->wrap >> 8) & 0xffu);
  return texels[tex->offset + (uint)(y * w + x)];
}

// uv in glTF convention: (0, 0) is the top-left corner of the image
float4 texture_sample(__global const TextureInfo* tex, __global const float4* texels, float2 uv) {
  float x = uv.x * (float)tex->width - 0.5f;
  float y = uv.y * (float)tex->height - 0.5f;
  // Keep huge coordinates in range before converting to int
  x = fmod(x, 8388608.0f);
  y = fmod(y, 8388608.0f);
  float fx = floor(x), fy = floor(y);
  float ax = x - fx, ay = y - fy;
  int ix = (int)fx, iy = (int)fy;
  float4 c00 = texture_texel(tex, texels, ix, iy);
  float4 c10 = texture_texel(tex, texels, ix + 1, iy);
  float4 c01 = texture_texel(tex, texels, ix, iy + 1);
  float4 c11 = texture_texel(tex, texels, ix + 1, iy + 1);
  return mix(mix(c00, c10, ax), mix(c01, c11, ax), ay);
}
