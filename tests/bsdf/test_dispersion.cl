// KHR_materials_dispersion test kernels (tests/bsdf/dispersion_test.cpp): only in a program
// built with CD_FEATURE_DISPERSION on (the shared test program has it off)
#if CD_FEATURE_DISPERSION
// out[i] = dispersion_ior(ior, dispersion, wavelength in nm) of in[i] = (ior, dispersion, wavelength)
__kernel void test_dispersion_ior(__global const float4* in, __global float* out) {
  uint i = get_global_id(0);
  out[i] = dispersion_ior(in[i].x, in[i].y, in[i].z);
}

// test_bsdf_sample's records (test_bsdf_sample_at: (wi, pdf), (f, eta), (bsdf_eval,
// bsdf_pdf)) of material 0 shaded at RGB channel `channel` (-1: none)
__kernel void test_dispersion_sample(__global const Material* materials, int channel, float4 ng, float4 ns,
                                     float4 tangent, float4 wo, uint seed, __global float4* out) {
  uint i = get_global_id(0);
  SceneData sc = test_bsdf_scene(materials);
  SurfaceHit s = test_bsdf_hit(ng.xyz, ns.xyz, tangent.xyz, wo.xyz, 0u);
  Bsdf b = bsdf_at_channel(&sc, &s, channel);
  BsdfSample bs;
  if (!test_bsdf_sample_i(&b, wo.xyz, i, seed, &bs)) {
    out[3 * i] = out[3 * i + 1] = out[3 * i + 2] = (float4)(0.0f);
    return;
  }
  out[3 * i] = (float4)(bs.wi, bs.pdf);
  out[3 * i + 1] = (float4)(bs.f, bs.eta);
  out[3 * i + 2] = test_bsdf_eval_pdf(&b, wo.xyz, bs.wi);
}
#endif
