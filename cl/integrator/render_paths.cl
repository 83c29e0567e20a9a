// The render kernel, render_paths: the launch order of the pixels, the film's running
// sums, the camera rays of a pixel's samples (in packets of eight on CPU devices), and with
// CD_AOV the arbitrary output variables beside the film (aov.cl).

// The pixel (row-major index) of launch index i, 0 <= i < width * height: launches hand out
// the image in 8x8 tiles, a band of 8 rows at a time from the top and the band's tiles from
// the left; inside a whole tile the order is the Z-order (Morton 1966, A Computer Oriented
// Geodetic Data Base and a New Technique in File Sequencing: x in the even bits of the
// index, y in the odd ones), inside a tile cut by the right or bottom edge it is row-major.
// Neighbouring work-items (a work-group of 64 launch indices is about one tile) trace
// neighbouring primary rays. A bijection of [0, width * height) onto the pixels; the
// sample of a pixel depends on the pixel only, so the order changes no image.
uint pixel_of_launch_index(uint i, uint width, uint height) {
  uint band = i / (8u * width), in_band = i - band * 8u * width;
  uint th = min(8u, height - 8u * band);  // the band's height
  uint tile = in_band / (8u * th), k = in_band - tile * 8u * th;
  uint tw = min(8u, width - 8u * tile);  // the tile's width
  uint lx, ly;
  if (tw == 8u && th == 8u) {
    lx = (k & 1u) | ((k >> 1u) & 2u) | ((k >> 2u) & 4u);
    ly = ((k >> 1u) & 1u) | ((k >> 2u) & 2u) | ((k >> 3u) & 4u);
  } else {
    ly = k / tw;
    lx = k - ly * tw;
  }
  return (8u * band + ly) * width + 8u * tile + lx;
}

// A sample's radiance into the pixel's running mean and sum of squared deviations
// (Welford): mean.w counts kept samples, m2.w dropped (non-finite) ones
void film_add(float4* mean, float4* m2, float3 l) {
  if (!all_finite(l)) {
    m2->w += 1.0f;
    return;
  }
  float n = mean->w + 1.0f;
  float3 delta = l - mean->xyz;
  float3 new_mean = mean->xyz + delta / n;
  m2->xyz += delta * (l - new_mean);
  *mean = (float4)(new_mean, n);
}

// The camera ray through film position (fx, fy), with the lens sample's two numbers drawn
// next when the camera has a lens
Ray film_camera_ray(__global const RenderParams* params, float fx, float fy, Rng* rng) {
  float2 lens = (float2)(0.0f);
  if (params->camera.lens_radius > 0.0f) {
    lens.x = rng_next(rng);
    lens.y = rng_next(rng);
  }
  return camera_ray(params, fx, fy, lens);
}

// The camera ray of a pixel's sample, from its first random numbers
Ray pixel_camera_ray(__global const RenderParams* params, uint px, uint py, Rng* rng) {
  float jx = rng_next(rng), jy = rng_next(rng);
  float2 film = filter_sample(params->filter, jx, jy);
  return film_camera_ray(params, (float)px + film.x, (float)py + film.y, rng);
}

// CD_ADAPTIVE (adaptive sampling, host/render/adaptive.hpp): render_paths takes two more
// buffers: the pixels of the launch indices (the active pixels, a compacted list in place of
// pixel_of_launch_index), and per pixel the running mean, squared deviations and count
// (x, y, z) of the channel average of the samples with odd indices, from which the host
// decides which pixels go on (film_add_adaptive)
#ifndef CD_ADAPTIVE
#define CD_ADAPTIVE 0
#endif
#if CD_ADAPTIVE
#define ADAPTIVE_PARAM , __global const uint* active, __global float4* film_half
#define LAUNCH_PIXEL(i) active[i]
#define FILM_ADD(mean, m2, half_film, sample, l) film_add_adaptive(mean, m2, half_film, sample, l)
void film_add_adaptive(float4* mean, float4* m2, float4* half_film, uint sample, float3 l) {
  film_add(mean, m2, l);
  if ((sample & 1u) == 0u || !all_finite(l)) return;
  float v = (l.x + l.y + l.z) / 3.0f, n = half_film->z + 1.0f, delta = v - half_film->x;
  half_film->x += delta / n;
  half_film->y += delta * (v - half_film->x);
  half_film->z = n;
}
#else
#define ADAPTIVE_PARAM
#define LAUNCH_PIXEL(i) pixel_of_launch_index(i, params->width, params->height)
#define FILM_ADD(mean, m2, half_film, sample, l) film_add(mean, m2, l)
#endif

#if CD_MOTION_STEPS
// Motion blur: pixel_camera_ray's ray at the sample's time, a uniform point of the shutter
// drawn after the film position's numbers, which *sc takes for the path (scene_set_time)
Ray pixel_camera_ray_in_time(SceneData* sc, uint px, uint py, Rng* rng) {
  __global const RenderParams* params = sc->params;
  float jx = rng_next(rng), jy = rng_next(rng);
  float2 film = filter_sample(params->filter, jx, jy);
  scene_set_time(sc, (float)CD_MOTION_STEPS * rng_next(rng));
  Camera c = camera_at_time(sc);
  float2 lens = (float2)(0.0f);
  if (c.lens_radius > 0.0f) {
    lens.x = rng_next(rng);
    lens.y = rng_next(rng);
  }
  return camera_ray_through(params, &c, (float)px + film.x, (float)py + film.y, lens);
}
#if CD_PACKETS
#error "motion blur (CD_MOTION_STEPS) traces camera rays one by one: no CD_PACKETS"
#endif
#endif

// With CD_AOV, render_paths takes one more buffer: two float4 per pixel, the running means of
// (albedo, alpha) and (normal, depth) over the pixel's samples (aov_add), n = mean.w + m2.w
#if CD_AOV
#define AOV_FILM_PARAM , __global float4* film_aov
#else
#define AOV_FILM_PARAM
#endif

// CD_PACKETS=1 (CPU devices, set by the host): a work-item takes eight consecutive launch
// indices (a 4x2 block of a tile) and traces their camera rays as one packet
// (bvh_intersect8), then each path on its own. The same samples, bit for bit, as one
// work-item per index, but where a camera ray meets two triangles within rounding of one
// distance (the packet may test them in another order and keep the other).
#if CD_PACKETS
// (Loops over the eight lanes have a fixed trip count, and structs reach the arrays from
// locals: llvmpipe mistranslated a lane loop with a data-dependent bound and a struct
// returned straight into an array element.)

// The camera rays and random number states of eight pixels' sample `sample`: lane for
// lane pixel_camera_ray's after rng_init, bit for bit (hashed_seed: rng_hash_seed of the
// render's seed, for the Sobol sampler). With the Sobol sampler the film
// positions' numbers (pair 0) are drawn in SIMD lanes (the tent and Gaussian filters then
// map them lane by lane), and so are a pinhole camera's ray directions (normalized lane by
// lane: camera_rays8); a lens or an orthographic camera goes lane by lane, and so does the
// independent sampler.
void packet_camera_rays(__global const RenderParams* params, const uint pixel[8], uint sample, uint hashed_seed,
                        Rng rng[8], Ray rays[8]) {
#if CD_SAMPLER_SOBOL
  uint sample_reversed = rng_reverse_bits(sample);
  uint8 pixels = vload8(0, pixel), ux, uy;
  rng_sobol_pair8(pixels, sample_reversed, hashed_seed, 0u, &ux, &uy);
  uint y_bits[8];
  vstore8(uy, 0, y_bits);
  // Where each sample lands on the film: the box filter's is the uniform jitter itself
  float8 jx = convert_float8(ux >> 8) * 0x1.0p-24f, jy = convert_float8(uy >> 8) * 0x1.0p-24f;  // rng_uint_to_float
  float8 fx = convert_float8(pixels % params->width), fy = convert_float8(pixels / params->width);
  if (params->filter == FILTER_BOX) {
    fx += jx;
    fy += jy;
  } else {
    float ax[8], ay[8], bx[8], by[8];
    vstore8(jx, 0, ax);
    vstore8(jy, 0, ay);
    vstore8(fx, 0, bx);
    vstore8(fy, 0, by);
    for (int l = 0; l < 8; ++l) {
      float2 film = filter_sample(params->filter, ax[l], ay[l]);
      bx[l] += film.x;
      by[l] += film.y;
    }
    fx = vload8(0, bx);
    fy = vload8(0, by);
  }
  for (int l = 0; l < 8; ++l) {
    Rng r = rng_sobol_after_pair0(pixel[l], sample_reversed, hashed_seed, y_bits[l]);
    rng[l] = r;
  }
  if (params->camera.type == CAMERA_PERSPECTIVE && !(params->camera.lens_radius > 0.0f)) {
    camera_rays8(params, fx, fy, rays);
    return;
  }
  float px[8], py[8];
  vstore8(fx, 0, px);
  vstore8(fy, 0, py);
  for (int l = 0; l < 8; ++l) {
    Rng r = rng[l];
    Ray ray = film_camera_ray(params, px[l], py[l], &r);
    rng[l] = r;
    rays[l] = ray;
  }
#else
  for (int l = 0; l < 8; ++l) {
    Rng r = rng_init(pixel[l], sample, params->seed);
    Ray ray = pixel_camera_ray(params, pixel[l] % params->width, pixel[l] / params->width, &r);
    rng[l] = r;
    rays[l] = ray;
  }
#endif
}

__kernel void render_paths(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params,
                           __global float4* film_mean, __global float4* film_m2 AOV_FILM_PARAM ADAPTIVE_PARAM) {
  uint first = params->pixel_begin + 8u * (uint)get_global_id(0);
  if (first >= params->pixel_end) return;
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  if (!params->energy_compensation) sc.ggx_albedo = 0;  // no table: no energy compensation
  uint pixel[8];
  float4 mean[8], m2[8];
  float tmax[8];
#if CD_AOV
  float4 aov0[8], aov1[8];
#endif
#if CD_ADAPTIVE
  float4 hm[8];
#endif
  for (uint l = 0u; l < 8u; ++l) {
    // A lane past the launch's end repeats the first lane's pixel, finds nothing (tmax 0)
    // and is never written
    bool inside = first + l < params->pixel_end;
    pixel[l] = LAUNCH_PIXEL(inside ? first + l : first);
    tmax[l] = inside ? INFINITY : 0.0f;
    mean[l] = film_mean[pixel[l]];
    m2[l] = film_m2[pixel[l]];
#if CD_AOV
    aov0[l] = film_aov[2u * pixel[l]];
    aov1[l] = film_aov[2u * pixel[l] + 1u];
#endif
#if CD_ADAPTIVE
    hm[l] = film_half[pixel[l]];
#endif
  }
  uint hashed_seed = rng_hash_seed(params->seed);
  for (uint k = 0u; k < params->sample_count; ++k) {
    Rng rng[8];
    Ray rays[8];
    packet_camera_rays(params, pixel, params->sample_begin + k, hashed_seed, rng, rays);
    Hit hits[8];
    scene_intersect8(&sc, rays, tmax, hits);
    for (uint l = 0u; l < 8u; ++l) {
      if (first + l >= params->pixel_end) continue;
      Ray ray = rays[l];
      Hit hit = hits[l];
      Rng r = rng[l];
#if CD_AOV
      PathAov a = aov_start();
      float4 m = mean[l], v = m2[l], a0 = aov0[l], a1 = aov1[l];
      FILM_ADD(&m, &v, &hm[l], params->sample_begin + k, path_trace(&sc, ray, &hit, &r, &a));
      aov_add(&a0, &a1, &a, m.w + v.w);
      mean[l] = m;
      m2[l] = v;
      aov0[l] = a0;
      aov1[l] = a1;
#else
      FILM_ADD(&mean[l], &m2[l], &hm[l], params->sample_begin + k, path_trace(&sc, ray, &hit, &r));
#endif
    }
  }
  for (uint l = 0u; l < 8u; ++l) {
    if (first + l >= params->pixel_end) continue;
    film_mean[pixel[l]] = mean[l];
    film_m2[pixel[l]] = m2[l];
#if CD_AOV
    film_aov[2u * pixel[l]] = aov0[l];
    film_aov[2u * pixel[l] + 1u] = aov1[l];
#endif
#if CD_ADAPTIVE
    film_half[pixel[l]] = hm[l];
#endif
  }
}
#else
__kernel void render_paths(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params,
                           __global float4* film_mean, __global float4* film_m2 AOV_FILM_PARAM ADAPTIVE_PARAM) {
  uint index = params->pixel_begin + (uint)get_global_id(0);
  if (index >= params->pixel_end) return;
  uint pixel = LAUNCH_PIXEL(index);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  if (!params->energy_compensation) sc.ggx_albedo = 0;  // no table: no energy compensation
  uint px = pixel % params->width, py = pixel / params->width;
  float4 mean = film_mean[pixel];
  float4 m2 = film_m2[pixel];
#if CD_AOV
  float4 a0 = film_aov[2u * pixel], a1 = film_aov[2u * pixel + 1u];
#endif
#if CD_ADAPTIVE
  float4 hm = film_half[pixel];
#endif
  for (uint k = 0u; k < params->sample_count; ++k) {
    Rng rng = rng_init(pixel, params->sample_begin + k, params->seed);
#if CD_MOTION_STEPS
    Ray ray = pixel_camera_ray_in_time(&sc, px, py, &rng);
#else
    Ray ray = pixel_camera_ray(params, px, py, &rng);
#endif
#if CD_AOV
    PathAov a = aov_start();
    FILM_ADD(&mean, &m2, &hm, params->sample_begin + k, path_trace(&sc, ray, 0, &rng, &a));
    aov_add(&a0, &a1, &a, mean.w + m2.w);
#else
    FILM_ADD(&mean, &m2, &hm, params->sample_begin + k, path_trace(&sc, ray, 0, &rng));
#endif
  }
  film_mean[pixel] = mean;
  film_m2[pixel] = m2;
#if CD_AOV
  film_aov[2u * pixel] = a0;
  film_aov[2u * pixel + 1u] = a1;
#endif
#if CD_ADAPTIVE
  film_half[pixel] = hm;
#endif
}
#endif
