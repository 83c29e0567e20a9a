// Environment map test kernels: environment_sample / environment_pdf / environment_radiance
// (cl/lights/environment.cl) of the scene's environment light, on a compiled scene bound as
// render_paths binds it.

// Direction of (theta, phi) in the world frame of cl/lights/environment.cl (phi = atan2(-x, z))
float3 test_environment_direction(float theta, float phi) {
  float ct, st = sincos(theta, &ct);
  float cp, sp = sincos(phi, &cp);
  return (float3)(-st * sp, ct, st * cp);
}

// One sample per work-item: out[2i] = (dir, pdf), out[2i+1] = (environment_pdf(dir), the
// sample's radiance rgb), the pdf slot NaN when that radiance is not environment_radiance(dir);
// the light is the scene's environment light
__kernel void test_environment_sample(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params, uint seed,
                                      __global float4* out) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  __global const Light* env = &sc.lights[params->environment_light];
  Rng rng = rng_init(i, 0u, seed);
  float2 u;
  u.x = rng_next(&rng);
  u.y = rng_next(&rng);
  float pdf = 0.0f;
  float3 l;
  float3 dir = environment_sample(&sc, env, u, &pdf, &l);
  // The sample's radiance is the one a ray along dir sees (else the pdf slot says NaN)
  bool same = all(l == environment_radiance(&sc, env, dir));
  out[2 * i] = (float4)(dir, pdf);
  out[2 * i + 1] = (float4)(same ? environment_pdf(&sc, env, dir) : NAN, l);
}

// Integral of environment_pdf over each cell (cos0, cos1, phi0, phi1) of (cos theta, phi)
// about +Y: midpoint rule on sub x sub points uniform in (theta, phi), where
// dw = sin(theta) dtheta dphi. mode 1: a deliberately wrong pdf without the 1 / sin(theta)
// of the (u, v) -> direction Jacobian.
__kernel void test_environment_pdf_cells(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params, uint sub,
                                         uint mode, __global const float4* cells, __global float* out) {
  uint c = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  __global const Light* env = &sc.lights[params->environment_light];
  float4 cell = cells[c];
  float theta0 = acos(cell.y), theta1 = acos(cell.x);  // cos1 > cos0: theta1 > theta0
  float sum = 0.0f;
  for (uint a = 0u; a < sub; ++a) {
    float theta = theta0 + ((float)a + 0.5f) / (float)sub * (theta1 - theta0);
    float row = 0.0f;
    for (uint b = 0u; b < sub; ++b) {
      float phi = cell.z + ((float)b + 0.5f) / (float)sub * (cell.w - cell.z);
      float3 dir = test_environment_direction(theta, phi);
      float pdf = environment_pdf(&sc, env, dir);
      if (mode == 1u) pdf *= sqrt(dir.x * dir.x + dir.z * dir.z);
      row += pdf;
    }
    sum += row * sin(theta);
  }
  out[c] = sum * (theta1 - theta0) * (cell.w - cell.z) / (float)(sub * sub);
}

// Radiance the path tracer's missed rays see along each direction (lights.cl), out[i].xyz
__kernel void test_environment_radiance(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params,
                                        __global const float4* dirs, __global float4* out) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  out[i] = (float4)(lights_environment_radiance(&sc, normalize(dirs[i].xyz)), 0.0f);
}
