// Camera rays: pinhole, thin lens and orthographic (Camera in device_types.h). The pixel
// filter decides where in the image a sample lands (filter.cl).

// (px, py) continuous pixel coordinates, (0, 0) at the top-left of the image; `lens` two
// uniforms in [0, 1) for the thin lens (unused by a pinhole or orthographic camera)
Ray camera_ray(const __global RenderParams* params, float px, float py, float2 lens) {
  __global const Camera* c = &params->camera;
  float x = 2.0f * px / (float)params->width - 1.0f;
  float y = 1.0f - 2.0f * py / (float)params->height;
  float3 right = load3(c->right), up = load3(c->up);
  Ray r;
  if (c->type == CAMERA_ORTHOGRAPHIC) {
    // Parallel rays from the image plane through the camera position
    r.org = load3(c->origin) + x * right + y * up;
    r.dir = load3(c->forward);
    return r;
  }
  float3 d = load3(c->forward) + x * right + y * up;  // reaches depth 1 along forward
  r.org = load3(c->origin);
  r.dir = normalize(d);
  if (c->lens_radius > 0.0f) {
    // Start on the lens disk and aim at where the pinhole ray meets the focus plane
    float2 l = c->lens_radius * sample_concentric_disk(lens.x, lens.y);
    float3 on_lens = l.x * normalize(right) + l.y * normalize(up);
    r.org += on_lens;
    r.dir = normalize(c->focus_distance * d - on_lens);
  }
  return r;
}

#if CD_MOTION_STEPS
// Motion blur: the camera at the time the scene carries (scene_set_time), each number of its
// record linear between the two poses around it (a turn follows their chord)
Camera camera_at_time(const SceneData* sc) {
  __global const float* a = (__global const float*)&sc->camera_steps[sc->motion_step];
  __global const float* b = (__global const float*)&sc->camera_steps[sc->motion_step + 1u];
  float v[16];
  for (int i = 0; i < 16; ++i) v[i] = mix(a[i], b[i], sc->motion_mix);
  Camera c;
  c.type = sc->camera_steps[sc->motion_step].type;
  c.lens_radius = v[7];
  c.focus_distance = v[11];
  vstore3(vload3(0, v), 0, c.origin);
  vstore3(normalize(vload3(0, v + 4)), 0, c.forward);
  vstore3(vload3(0, v + 8), 0, c.right);
  vstore3(vload3(0, v + 12), 0, c.up);
  return c;
}

// camera_ray through the camera `c` (camera_at_time)
Ray camera_ray_through(const __global RenderParams* params, const Camera* c, float px, float py, float2 lens) {
  float x = 2.0f * px / (float)params->width - 1.0f;
  float y = 1.0f - 2.0f * py / (float)params->height;
  float3 right = vload3(0, c->right), up = vload3(0, c->up), forward = vload3(0, c->forward);
  Ray r;
  if (c->type == CAMERA_ORTHOGRAPHIC) {
    r.org = vload3(0, c->origin) + x * right + y * up;
    r.dir = forward;
    return r;
  }
  float3 d = forward + x * right + y * up;
  r.org = vload3(0, c->origin);
  r.dir = normalize(d);
  if (c->lens_radius > 0.0f) {
    float2 l = c->lens_radius * sample_concentric_disk(lens.x, lens.y);
    float3 on_lens = l.x * normalize(right) + l.y * normalize(up);
    r.org += on_lens;
    r.dir = normalize(c->focus_distance * d - on_lens);
  }
  return r;
}
#endif

// Eight rays of a pinhole perspective camera (type CAMERA_PERSPECTIVE, lens_radius 0) at
// once, lane l at (px.sl, py.sl): camera_ray's rays bit for bit. The directions are made
// in SIMD lanes with camera_ray's operations in the same order, then normalized lane by
// lane (the library's normalize, whose arithmetic a float8 version need not repeat). The
// CPU packets' camera rays (render_paths, CD_PACKETS).
void camera_rays8(const __global RenderParams* params, float8 px, float8 py, Ray rays[8]) {
  __global const Camera* c = &params->camera;
  float8 x = 2.0f * px / (float)params->width - 1.0f;
  float8 y = 1.0f - 2.0f * py / (float)params->height;
  float3 f = load3(c->forward), right = load3(c->right), up = load3(c->up), org = load3(c->origin);
  float8 dx = f.x + x * right.x + y * up.x;
  float8 dy = f.y + x * right.y + y * up.y;
  float8 dz = f.z + x * right.z + y * up.z;
  float rx[8], ry[8], rz[8];
  vstore8(dx, 0, rx);
  vstore8(dy, 0, ry);
  vstore8(dz, 0, rz);
  for (int l = 0; l < 8; ++l) {
    rays[l].org = org;
    rays[l].dir = normalize((float3)(rx[l], ry[l], rz[l]));
  }
}
