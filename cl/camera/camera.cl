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
