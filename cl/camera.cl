// Pinhole camera. (The box pixel filter is the integrator's uniform jitter within a pixel.)

// (px, py) continuous pixel coordinates, (0, 0) at the top-left of the image
Ray camera_ray(const __global RenderParams* params, float px, float py) {
  __global const Camera* c = &params->camera;
  float x = 2.0f * px / (float)params->width - 1.0f;
  float y = 1.0f - 2.0f * py / (float)params->height;
  Ray r;
  r.org = load3(c->origin);
  r.dir = normalize(load3(c->forward) + x * load3(c->right) + y * load3(c->up));
  return r;
}
