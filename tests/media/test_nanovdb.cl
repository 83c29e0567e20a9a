// NanoVDB lookups (cl/media/nanovdb.cl): for world points p[i], out[i] = (index point, trilinear value)
#if CD_FEATURE_NANOVDB
__kernel void test_nanovdb_lookup(__global const uint* grid, __global const float4* p, __global float4* out) {
  uint i = get_global_id(0);
  NanoVdbGrid g = nanovdb_grid(grid);
  float3 q = nanovdb_world_to_index(&g, p[i].xyz);
  out[i] = (float4)(q, nanovdb_trilinear(&g, q));
}
#endif
