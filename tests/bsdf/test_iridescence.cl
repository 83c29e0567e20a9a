// Iridescence test kernel (KHR_materials_iridescence): the film's reflectance of
// cl/bsdf/iridescence.cl alone. The BSDF through the real dispatch uses test_sheen_sample and
// test_sheen_eval (test_sheen.cl).

// iridescence_fresnel(film ior, thickness, base F0, cos) for queries[i] = (film ior,
// thickness in nm, cos, _) and f0[i].xyz; zeros in a program built without CD_FEATURE_IRIDESCENCE
__kernel void test_iridescence_fresnel(__global const float4* queries, __global const float4* f0,
                                       __global float4* out) {
  uint i = get_global_id(0);
#if CD_FEATURE_IRIDESCENCE
  float4 q = queries[i];
  out[i] = (float4)(iridescence_fresnel(q.x, q.y, f0[i].xyz, q.z), 0.0f);
#else
  out[i] = (float4)(0.0f);
#endif
}
