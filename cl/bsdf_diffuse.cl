// Lambertian BSDF: f = albedo / pi, cosine-weighted sampling around the shading normal.
// Directions below the geometric surface are rejected so that sampling and evaluation
// describe the same integrand.

float3 bsdf_diffuse_eval(float3 albedo, float3 wi, float3 ns, float3 ng) {
  if (dot(wi, ns) <= 0.0f || dot(wi, ng) <= 0.0f) return (float3)(0.0f);
  return albedo * INV_PI_F;
}

float bsdf_diffuse_pdf(float3 wi, float3 ns, float3 ng) {
  if (dot(wi, ng) <= 0.0f) return 0.0f;
  return sample_cosine_hemisphere_pdf(dot(wi, ns));
}

bool bsdf_diffuse_sample(float3 albedo, float3 ns, float3 ng, float2 u, float3* wi, float3* f,
                         float* pdf) {
  float3 dir_local = sample_cosine_hemisphere(u.x, u.y);
  *wi = frame_to_world(dir_local, ns);
  *pdf = sample_cosine_hemisphere_pdf(dir_local.z);
  *f = bsdf_diffuse_eval(albedo, *wi, ns, ng);
  return *pdf > 0.0f && max_component(*f) > 0.0f;
}
