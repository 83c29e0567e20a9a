// KHR_materials_unlit: the surface has no BSDF; every ray that finds it sees its base colour
// (factor x texture x vertex colour) as radiance, and the path ends there
// (integrator_path.cl, CD_FEATURE_UNLIT).
float3 bsdf_unlit_radiance(const SceneData* sc, const SurfaceHit* s) {
  __global const Material* m = &sc->materials[s->material];
  return load3(m->base_color) * bsdf_texture(sc, m, TEX_BASE_COLOR, s).xyz * s->vertex_color;
}
