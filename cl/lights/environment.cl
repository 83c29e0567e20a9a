// Equirectangular environment maps: L_i(w) = I[theta/pi h, phi/2pi w] (the latitude-longitude
// mapping), and
// their importance sampling by a piecewise-constant 2D distribution (pbrt's
// marginal-over-rows, conditional-within-rows construction).
//
// Mapping (glTF is +Y up), for a direction d turned by -rotation about +Y:
//   theta = angle from +Y,  v = theta / pi         (row 0, the top of the image, looks up)
//   phi = atan2(-d.x, d.z) in [0, 2 pi),  u = phi / (2 pi)   (columns, left to right)
// so the image centre (u = 1/2) is seen along -Z, u = 3/4 along +X, u = 1/4 along -X and
// the left and right edges along +Z, as a viewer standing at the origin looking down -Z
// sees the middle of the panorama, with the right half of the image to its right.
// `rotation` (EnvironmentLight.rotation, radians) turns the map counter-clockwise seen from above
// (right-handed about +Y): at 90 degrees the image centre is seen along -X.
//
// Filter: nearest texel. A direction's radiance is the texel its (u, v) falls in, times the
// strength, and the sampling pdf is constant in (u, v) over each texel, in proportion to
// that texel's luminance x sin(theta at the row centre). So the pdf is > 0 wherever the
// radiance is > 0 (the host keeps every such texel's CDF step > 0 in float), and
// radiance / pdf is exactly what the estimator needs.
//
// env_distribution layout for a w x h map: floats [0, h] are the marginal CDF over rows
// (cdf[0] = 0, cdf[h] = total, not normalized), then row r's conditional CDF over its
// columns at (h + 1) + r (w + 1), w + 1 floats each. A step of zero is a cell that is never
// sampled (and has pdf 0). The solid-angle pdf is p(u, v) / (2 pi^2 sin theta), since
// dw = sin(theta) dtheta dphi = 2 pi^2 sin(theta) du dv. After the CDFs, at
// G = (h + 1) + h (w + 1), their guide tables (Chen & Asau 1974, the cutpoint method):
// the marginal's g(h) cells, then row r's g(w) cells at G + g(h) + r g(w), g(n) =
// environment_guide_cells(n) = max(1, (n + 3) / 4) (cl/shared); cell k of a CDF of n cells holds (as an
// integer-valued float) the largest i < n with cdf[i] <= k / g(n) x cdf[n], where the search
// for a u in [k / g(n), (k + 1) / g(n)) starts.

// The light's map (a TextureInfo index), or NO_TEXTURE for a constant environment
int environment_map(__global const Light* light) { return (int)light->params.environment.map; }

// (u, v) of a unit direction: the mapping above
float2 environment_uv(float3 dir, float rotation) {
  float u = (atan2_fast(-dir.x, dir.z) + rotation) * (0.5f * INV_PI_F);
  u -= floor(u);
  float v = atan2_fast(sqrt(dir.x * dir.x + dir.z * dir.z), dir.y) * INV_PI_F;  // theta
  return (float2)(u, v);
}

// The unit direction of (u, v): the inverse of environment_uv
float3 environment_direction(float2 uv, float rotation) {
  // theta = pi v, phi = 2 pi (u - rotation / 2 pi): sinpi/cospi reduce exactly (sincos_turn)
  float cos_theta = cospi(uv.y), sin_theta = sinpi(uv.y);
  float cos_phi, sin_phi = sincos_turn(uv.x - rotation * (0.5f * INV_PI_F), &cos_phi);
  return (float3)(-sin_theta * sin_phi, cos_theta, sin_theta * cos_phi);
}

// The texel (column, row) that (u, v) lies in
int2 environment_texel(__global const TextureInfo* tex, float2 uv) {
  int w = (int)tex->width, h = (int)tex->height;
  return (int2)(clamp((int)(uv.x * (float)w), 0, w - 1), clamp((int)(uv.y * (float)h), 0, h - 1));
}

// The texel that unit direction dir falls in
int2 environment_texel_of(__global const TextureInfo* tex, float3 dir, float rotation) {
  return environment_texel(tex, environment_uv(dir, rotation));
}

// Radiance of texel t: strength x the texel
float3 environment_radiance_at(const SceneData* sc, __global const Light* light, __global const TextureInfo* tex,
                               int2 t) {
  return light->params.environment.strength * texture_texel(sc, tex, t.x, t.y).xyz;
}

// Radiance arriving along -dir: strength x the nearest texel
float3 environment_radiance(const SceneData* sc, __global const Light* light, float3 dir) {
  __global const TextureInfo* tex = &sc->textures[environment_map(light)];
  return environment_radiance_at(sc, light, tex, environment_texel_of(tex, dir, light->params.environment.rotation));
}

// Density in (u, v) of texel t: (marginal step / total) h x (conditional step / total) w
float environment_pdf_uv(const SceneData* sc, __global const TextureInfo* tex, int2 t) {
  int w = (int)tex->width, h = (int)tex->height;
  __global const float* rows = sc->env_distribution;
  __global const float* cols = rows + (h + 1) + t.y * (w + 1);
  float p_row = (rows[t.y + 1] - rows[t.y]) / rows[h];
  float p_col = (cols[t.x + 1] - cols[t.x]) / cols[w];
  if (!(p_row > 0.0f && p_col > 0.0f)) return 0.0f;
  return p_row * p_col * (float)w * (float)h;
}

// Solid-angle pdf with which environment_sample picks dir, t being dir's texel
float environment_pdf_at(const SceneData* sc, __global const TextureInfo* tex, float3 dir, int2 t) {
  float sin_theta = sqrt(dir.x * dir.x + dir.z * dir.z);  // accurate near the poles
  if (!(sin_theta > 0.0f)) return 0.0f;
  return environment_pdf_uv(sc, tex, t) / (2.0f * PI_F * PI_F * sin_theta);
}

// Solid-angle pdf with which environment_sample picks dir
float environment_pdf(const SceneData* sc, __global const Light* light, float3 dir) {
  __global const TextureInfo* tex = &sc->textures[environment_map(light)];
  return environment_pdf_at(sc, tex, dir, environment_texel_of(tex, dir, light->params.environment.rotation));
}

// A coordinate in [0, 1) distributed by one CDF of n cells: the cell i with
// cdf[i] <= x < cdf[i+1] for x = u cdf[n], then uniform within it. The search starts at
// the guide's cell of u and steps down while cdf[i] > x, then up while cdf[i + 1] <= x: the
// largest i < n with cdf[i] <= x (as a binary search finds it) whatever the guide says, in
// about n / g(n) steps over neighbouring floats.
float environment_sample_cdf(__global const float* cdf, int n, __global const float* guide, float u, int* index) {
  float total = cdf[n];
  float x = fmin(u * total, nextafter(total, 0.0f));  // x < total: a cell of positive step
  int cells = environment_guide_cells(n);
  int lo = (int)guide[clamp((int)(u * (float)cells), 0, cells - 1)];
  while (lo > 0 && cdf[lo] > x) --lo;
  while (lo < n - 1 && cdf[lo + 1] <= x) ++lo;
  *index = lo;
  float t = (x - cdf[lo]) / (cdf[lo + 1] - cdf[lo]);
  return ((float)lo + clamp(t, 0.0f, 1.0f)) / (float)n;
}

// A direction distributed by the map's luminance x sin(theta): a row by the marginal CDF
// (u.y), a column within it by the row's conditional CDF (u.x). *pdf is environment_pdf of
// the returned direction (0 when it should not be used), *radiance environment_radiance.
float3 environment_sample(const SceneData* sc, __global const Light* light, float2 u, float* pdf, float3* radiance) {
  __global const TextureInfo* tex = &sc->textures[environment_map(light)];
  int w = (int)tex->width, h = (int)tex->height;
  int row, col;
  __global const float* guides = sc->env_distribution + (h + 1) + h * (w + 1);
  float v = environment_sample_cdf(sc->env_distribution, h, guides, u.y, &row);
  float uu = environment_sample_cdf(sc->env_distribution + (h + 1) + row * (w + 1), w,
                                    guides + environment_guide_cells(h) + row * environment_guide_cells(w), u.x, &col);
  float3 dir = environment_direction((float2)(uu, v), light->params.environment.rotation);
  // Both from the direction itself (its texel found once), so that sample, pdf and radiance
  // agree exactly even where rounding puts dir across a texel edge
  int2 t = environment_texel_of(tex, dir, light->params.environment.rotation);
  *pdf = environment_pdf_at(sc, tex, dir, t);
  *radiance = environment_radiance_at(sc, light, tex, t);
  return dir;
}

// The environment as a light (CD_LIGHTS entry environment; EnvironmentLight): a constant,
// or the equirectangular map above
__global const Light* lights_environment(const SceneData* sc) {
  int i = sc->params->environment_light;
  return i == NO_LIGHT ? 0 : &sc->lights[i];
}

// Radiance arriving along -dir from infinitely far away
float3 lights_environment_radiance(const SceneData* sc, float3 dir) {
#if CD_FEATURE_ENVIRONMENT
  __global const Light* env = lights_environment(sc);
  if (!env) return (float3)(0.0f);
  if (environment_map(env) != NO_TEXTURE) return environment_radiance(sc, env, dir);
  return load3(env->radiance);
#else
  return (float3)(0.0f);
#endif
}

// Reflection-only surfaces see the environment over the hemisphere of n (sampled by the
// cosine to n); points in media and transmissive surfaces over the whole sphere
bool lights_environment_hemisphere(const LightSampleContext* ctx) {
  return !ctx->transmits && dot(ctx->n, ctx->n) > 0.0f;
}

// A map is importance-sampled over the whole sphere, whatever the context
float lights_environment_pdf(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx,
                             float3 wi) {
  __global const Light* env = lights_environment(sc);
  if (env && environment_map(env) != NO_TEXTURE) return environment_pdf(sc, env, wi);
  if (lights_environment_hemisphere(ctx)) return sample_cosine_hemisphere_pdf(dot(wi, ctx->n));
  return sample_uniform_sphere_pdf();
}

bool lights_environment_sample(const SceneData* sc, __global const Light* light, const LightSampleContext* ctx,
                               float2 u, LightSample* ls) {
  __global const Light* env = lights_environment(sc);
  if (env && environment_map(env) != NO_TEXTURE) {
    ls->wi = environment_sample(sc, env, u, &ls->pdf, &ls->radiance);
    ls->at_infinity = true;
    return ls->pdf > 0.0f;
  }
  if (lights_environment_hemisphere(ctx)) {
    Frame f = frame_from_z(ctx->n);
    ls->wi = frame_from_local(&f, sample_cosine_hemisphere(u.x, u.y));
  } else {
    ls->wi = sample_uniform_sphere(u.x, u.y);
  }
  ls->pdf = lights_environment_pdf(sc, light, ctx, ls->wi);
  ls->radiance = lights_environment_radiance(sc, ls->wi);
  ls->at_infinity = true;
  return ls->pdf > 0.0f;
}

uint lights_environment_prim(__global const Light* light) { return UINT_MAX; }

// An environment seen from anywhere: its bright part as a cone of its effective solid angle
// (integral L)^2 / integral L^2 about the direction its L^2 is centred on (the whole
// sphere for a constant), and integral L, L its luminance (computed on the host:
// EnvironmentLight's solid_angle, direction and integral)
void lights_environment_extent(const SceneData* sc, __global const Light* light, float3 p, LightExtent* e) {
  __global const EnvironmentLight* env = &light->params.environment;
  e->omega = env->solid_angle;
  e->everywhere = true;
  e->dir = (float3)(env->direction[0], env->direction[1], env->direction[2]);
  e->radius = dot(e->dir, e->dir) > 0.0f ? acos_fast(1.0f - e->omega * (0.5f * INV_PI_F)) : PI_F;
  bool map = environment_map(light) != NO_TEXTURE;
  e->integral = env->integral * (map ? env->strength : luminance(load3(light->radiance)));
}

// An environment surrounds every point: no bound smaller than its extent
float lights_environment_omega_bound(const SceneData* sc, __global const Light* light, float3 p) { return -1.0f; }
