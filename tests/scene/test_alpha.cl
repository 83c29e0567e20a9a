// Alpha test kernels: scene ray queries (cl/scene/alpha.cl through the BVH) and texture
// lookups on a compiled scene, bound as render_paths binds it.

// rays: (org, tmax) then (dir, 0); out: (t, b1, b2, prim) of scene_intersect;
// occluded: scene_occluded over the same (0, tmax)
__kernel void test_alpha_trace(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params,
                               __global const float4* rays, __global float4* out, __global int* occluded) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  Ray r;
  r.org = rays[2 * i].xyz;
  r.dir = rays[2 * i + 1].xyz;
  float tmax = rays[2 * i].w;
  Hit h = scene_intersect(&sc, r, tmax);
  out[i] = (float4)(h.t, h.b1, h.b2, (float)h.prim);
  occluded[i] = scene_occluded(&sc, r, tmax) ? 1 : 0;
}

// The base colour slot of material `material` at texture coordinates uvs[i] (TEXCOORD_0)
__kernel void test_alpha_texture_lookup(CD_SCENE_BUFFERS(CD_SCENE_PARAM) __global const RenderParams* params,
                                        uint material, __global const float2* uvs, __global float4* out) {
  uint i = get_global_id(0);
  SceneData sc = {CD_SCENE_BUFFERS(CD_SCENE_INIT) params};
  out[i] = textures_lookup(&sc, &sc.materials[material].textures[TEX_BASE_COLOR], (float4)(uvs[i], 0.0f, 0.0f));
}

// alpha_random for n rays from one origin along jittered directions around +z
__kernel void test_alpha_random(uint prim, float4 org, __global const float4* dirs, __global float* out) {
  uint i = get_global_id(0);
  Ray r;
  r.org = org.xyz;
  r.dir = dirs[i].xyz;
  out[i] = alpha_random(prim, r);
}
