// Light sampling test kernels: lights_sample and lights_pdf (cl/lights/lights.cl) from a fixed
// context on a compiled scene, bound as render_paths binds it.

// Flags of test_lights_sample
#define TL_OK 1u            // lights_sample returned true
#define TL_COMPARED 2u      // the ray along wi first meets the chosen light (escapes: environment)
#define TL_SHADOW_CLEAR 4u  // the integrator's shadow ray toward ls.target is unoccluded
#define TL_AT_INFINITY 8u
#define TL_DELTA 16u

LightSampleContext test_lights_context(float4 p, float4 n, uint transmits) {
  LightSampleContext ctx;
  ctx.p = p.xyz;
  ctx.n = n.xyz;
  ctx.ns = n.xyz;
  ctx.transmits = transmits != 0u;
  return ctx;
}

// One light sample per work-item. out[2i] = (wi, pdf); out[2i+1] = (radiance.x,
// lights_pdf(chosen light, wi), chosen light, flags); `check` = 0 skips lights_pdf and
// the traced rays (pdf_eval 0, no TL_COMPARED / TL_SHADOW_CLEAR)
__kernel void test_lights_sample(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params, float4 p,
                                 float4 n, uint transmits, uint seed, uint check, __global float4* out) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  LightSampleContext ctx = test_lights_context(p, n, transmits);
  Rng rng = rng_init(i, 0u, seed);
  uint x_select = rng_next_uint(&rng);
  float2 u;
  u.x = rng_next(&rng);
  u.y = rng_next(&rng);
  LightSample ls;
  ls.wi = ls.radiance = ls.target = (float3)(0.0f);
  ls.pdf = 0.0f;
  ls.is_delta = ls.at_infinity = false;
  float u_select = rng_next(&rng);
  bool ok = lights_sample(&sc, &ctx, x_select, u_select, u, &ls);
  uint index = ls.light;  // the light lights_sample picked
  __global const Light* light = &sc.lights[index];
  uint flags = ok ? TL_OK | (ls.at_infinity ? TL_AT_INFINITY : 0u) | (ls.is_delta ? TL_DELTA : 0u) : 0u;
  float pdf_eval = 0.0f;
  if (ok && check != 0u) {
    pdf_eval = lights_pdf(&sc, &ctx, index, ls.wi);
    Ray r = {ctx.p, ls.wi};
    Hit h = scene_intersect(&sc, r, INFINITY);
    if (light->type == LIGHT_TRIANGLE ? h.prim == (int)light->index : h.prim < 0) flags |= TL_COMPARED;
    if (!ls.at_infinity) {
      // The shadow ray as path_direct_light builds it
      Ray shadow;
      shadow.org = offset_ray_origin(ctx.p, dot(ls.wi, ctx.n) >= 0.0f ? ctx.n : -ctx.n);
      float3 d = ls.target - shadow.org;
      float tmax = length(d);
      shadow.dir = d / tmax;
      if (tmax > 0.0f && !scene_occluded(&sc, shadow, tmax)) flags |= TL_SHADOW_CLEAR;
    }
  }
  out[2 * i] = (float4)(ls.wi, ls.pdf);
  out[2 * i + 1] = (float4)(ls.radiance.x, pdf_eval, (float)index, (float)flags);
}

// Integral over each cell (cos0, cos1, phi0, phi1) of directions about the frame
// (ft, fb, fa) of the sum over lights of lights_pdf: midpoint rule on sub x sub points
// uniform in (cos theta, phi), where dw = dcos dphi.
// mode 1: a deliberately wrong pdf, triangle lights without the cosine of dw/dA.
__kernel void test_lights_pdf_cells(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params, float4 p,
                                    float4 n, uint transmits, float4 ft, float4 fb, float4 fa, uint sub, uint mode,
                                    __global const float4* cells, __global float* out) {
  uint c = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  LightSampleContext ctx = test_lights_context(p, n, transmits);
  float4 cell = cells[c];
  float sum = 0.0f;
  for (uint a = 0u; a < sub; ++a) {
    float ct = cell.x + ((float)a + 0.5f) / (float)sub * (cell.y - cell.x);
    float st = sqrt(fmax(0.0f, 1.0f - ct * ct));
    float row = 0.0f;
    for (uint b = 0u; b < sub; ++b) {
      float phi = cell.z + ((float)b + 0.5f) / (float)sub * (cell.w - cell.z);
      float cp, sp = sincos(phi, &cp);
      float3 wi = normalize(st * cp * ft.xyz + st * sp * fb.xyz + ct * fa.xyz);
      for (uint l = 0u; l < params->num_lights; ++l) {
        float pdf = lights_pdf(&sc, &ctx, l, wi);
        if (mode == 1u && sc.lights[l].type == LIGHT_TRIANGLE && pdf > 0.0f) {
          float3 v0, v1, v2;
          float area;
          scene_prim_positions(&sc, sc.lights[l].index, &v0, &v1, &v2);
          pdf *= fabs(dot(triangle_normal_area(v0, v1, v2, &area), wi));
        }
        row += pdf;
      }
    }
    sum += row;
  }
  out[c] = sum * (cell.y - cell.x) * (cell.w - cell.z) / (float)(sub * sub);
}

// Light selection's pmf (lights_select_pmf) of every light at contexts c: p = ps[c], n = ns[c]
// (n = 0: a point in a medium); one work-item per (c, l): out[c num_lights + l]
__kernel void test_lights_select_pmf(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params,
                                     __global const float4* ps, __global const float4* ns, __global float* out) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  uint n = params->num_lights;
  uint c = i / n, l = i % n;
  LightSampleContext ctx = test_lights_context(ps[c], ns[c], 0u);
  out[i] = lights_select_pmf(&sc, &ctx, l);
}

// One light selection (lights_select, its numbers drawn as the integrator draws them:
// lights_select_numbers) per work-item from (p, n):
// out[i] = (light, pmf, lights_select_pmf(light), selected ? 1 : 0)
__kernel void test_lights_select(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params, float4 p,
                                 float4 n, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  LightSampleContext ctx = test_lights_context(p, n, 0u);
  Rng rng = rng_init(i, 0u, seed);
  uint x_select;
  float u_select;
  lights_select_numbers(&sc, &rng, &x_select, &u_select);
  uint light = 0u;
  float pmf = 0.0f;
  bool ok = lights_select(&sc, &ctx, x_select, u_select, &light, &pmf);
  out[i] = (float4)((float)light, pmf, ok ? lights_select_pmf(&sc, &ctx, light) : 0.0f, ok ? 1.0f : 0.0f);
}

// STRATEGY_AUTO's shortcut (integrator_path.cl) for light `index` seen from points[i], with
// one to three lobes (cosine, or GGX-shaped of 10^-sharpest to 1 sr, random centres and
// weights) and a selection probability in [1e-3, 1] drawn from rng_init(i, 0, seed): out[i] =
// (lights_omega_bound, lights_extent's omega, path_nee_surely_takes,
// path_nee_takes_by_moments), the last two as 0 or 1; full[i]: path_nee_takes_by_moments
// without settling first by the lobes' own terms, 0 or 1
__kernel void test_lights_nee_shortcut(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params, uint index,
                                       uint seed, float sharpest, __global const float4* points, __global float4* out,
                                       __global float* full) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  LightSampleContext ctx = test_lights_context(points[i], (float4)(0.0f, 0.0f, 1.0f, 0.0f), 0u);
  Rng rng = rng_init(i, 0u, seed);
  BsdfLobes lobes;
  lobes.count = 0u;
  uint n = 1u + min((uint)(rng_next(&rng) * 3.0f), 2u);
  for (uint k = 0u; k < n; ++k) {
    float2 u = rng_next_2d(&rng);
    float kind = rng_next(&rng), size = rng_next(&rng), weight = 0.05f + rng_next(&rng);
    bsdf_lobes_add(&lobes, sample_uniform_sphere(u.x, u.y), kind < 0.4f ? PI_F : pow(10.0f, -sharpest * size), weight);
  }
  float pmf = pow(10.0f, -3.0f * rng_next(&rng));
  float bound = lights_omega_bound(&sc, index, ctx.p);
  LightExtent e = lights_extent(&sc, index, ctx.p);
  bool surely = path_nee_surely_takes(&lobes, bound, pmf);
  bool takes = path_nee_takes_by_moments(&sc, &lobes, &ctx, index, pmf, true);
  out[i] = (float4)(bound, e.omega, surely ? 1.0f : 0.0f, takes ? 1.0f : 0.0f);
  full[i] = path_nee_takes_by_moments(&sc, &lobes, &ctx, index, pmf, false) ? 1.0f : 0.0f;
}
