// Bilinear (or nearest-texel) lookup of textures in two shared texel arrays (RGBA8 and
// float RGBA). sRGB texels are decoded through a 256-entry table before filtering, so
// filtering happens in linear space. Each material slot is a TextureRef: texture, UV set
// and transform.

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

// The wrapped pair (i, i + 1) of a bilinear footprint: a repeating axis steps from i's
// wrapped index instead of dividing again (integer % is the slow part of a lookup)
int2 texture_wrap_pair(int i, int n, uint mode) {
  int i0 = texture_wrap(i, n, mode);
  if (mode == WRAP_CLAMP || mode == WRAP_MIRROR) return (int2)(i0, texture_wrap(i + 1, n, mode));
  return (int2)(i0, i0 + 1 == n ? 0 : i0 + 1);
}

// Texel (x, y) of tex, both already wrapped into the image
float4 texture_texel_at(const SceneData* sc, __global const TextureInfo* tex, int x, int y) {
  uint i = tex->offset + (uint)y * tex->width + (uint)x;
  if (tex->flags & TEXTURE_FLOAT) return vload4(0, sc->texelsf[i].rgba);
  Texel8 c = sc->texels8[i];
  if (tex->flags & TEXTURE_SRGB)
    return (float4)(sc->srgb_to_linear[c.r], sc->srgb_to_linear[c.g], sc->srgb_to_linear[c.b], c.a / 255.0f);
  return (float4)(c.r, c.g, c.b, c.a) / 255.0f;
}

float4 texture_texel(const SceneData* sc, __global const TextureInfo* tex, int x, int y) {
  return texture_texel_at(sc, tex, texture_wrap(x, (int)tex->width, tex->flags & 0xffu),
                          texture_wrap(y, (int)tex->height, (tex->flags >> 8) & 0xffu));
}

// uv in glTF convention: (0, 0) is the top-left corner of the image
float4 texture_sample(const SceneData* sc, __global const TextureInfo* tex, float2 uv) {
  // Texel centres at half-integers for bilinear filtering; nearest takes the texel uv lies in
  float centre = (tex->flags & TEXTURE_NEAREST) ? 0.0f : 0.5f;
  float x = uv.x * (float)tex->width - centre;
  float y = uv.y * (float)tex->height - centre;
  // Keep huge coordinates in range before converting to int (fmod is exact, and the
  // identity below 2^23, so only those beyond pay for the call)
  if (!(fabs(x) < 8388608.0f)) x = fmod(x, 8388608.0f);
  if (!(fabs(y) < 8388608.0f)) y = fmod(y, 8388608.0f);
  float fx = floor(x), fy = floor(y);
  if (tex->flags & TEXTURE_NEAREST) return texture_texel(sc, tex, (int)fx, (int)fy);
  float ax = x - fx, ay = y - fy;
  int2 xs = texture_wrap_pair((int)fx, (int)tex->width, tex->flags & 0xffu);
  int2 ys = texture_wrap_pair((int)fy, (int)tex->height, (tex->flags >> 8) & 0xffu);
  float4 c00 = texture_texel_at(sc, tex, xs.x, ys.x);
  float4 c10 = texture_texel_at(sc, tex, xs.y, ys.x);
  float4 c01 = texture_texel_at(sc, tex, xs.x, ys.y);
  float4 c11 = texture_texel_at(sc, tex, xs.y, ys.y);
  return mix(mix(c00, c10, ax), mix(c01, c11, ax), ay);
}

// The slot's texture at the surface's texture coordinates (uvs.xy = TEXCOORD_0,
// uvs.zw = TEXCOORD_1), after its KHR_texture_transform; white for an empty slot or when
// the scene has no textures compiled in
float4 textures_lookup(const SceneData* sc, __global const TextureRef* ref, float4 uvs) {
#if CD_FEATURE_TEXTURES
  if (ref->index != NO_TEXTURE) {
    float2 uv = ref->texcoord == 1u ? uvs.zw : uvs.xy;
    float2 st =
        (float2)(ref->m[0] * uv.x + ref->m[1] * uv.y + ref->m[2], ref->m[3] * uv.x + ref->m[4] * uv.y + ref->m[5]);
    return texture_sample(sc, &sc->textures[ref->index], st);
  }
#endif
  return (float4)(1.0f);
}
