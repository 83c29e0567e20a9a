// Arbitrary output variables (CD_AOV, a build option the host sets only when an AOV is
// asked for: the default kernel holds none of this). Per camera sample, taken as Open Image
// Denoise asks of its guides, at the path's first vertex whose sampled lobe is not a delta
// lobe (mirrors and smooth glass show what they reflect or transmit):
//   albedo  the BSDF sample's weight f |cos| / pdf there, whose mean over the samples is the
//           directional albedo; an escaped ray: the environment's radiance clamped to 1
//   normal  the world-space shading normal there (normal mapping included), on the side the
//           ray came from; 0 when none
//   depth   the distance along the camera ray to its first surface; 0 when it escapes
//   alpha   1 - the throughput (its channels' mean) with which the camera path escapes to the
//           environment through delta transmissions, alpha-blended surfaces and null
//           boundaries alone (any other event makes the path opaque)
// render_paths folds them into running means over the pixel's samples beside the film.
// CD_TRANSPARENT: the environment that such a path finds is left out of the radiance (the
// image is premultiplied by alpha); the environment still lights the scene.
#ifndef CD_AOV
#define CD_AOV 0
#endif
#ifndef CD_TRANSPARENT
#define CD_TRANSPARENT 0
#endif

typedef struct {
  float3 albedo, normal;
  float depth, alpha;
  float travelled;   // along the camera ray, over null boundaries passed
  bool found;        // the vertex of albedo and normal met (or the ray escaped first)
  bool see_through;  // only delta transmissions and pass-throughs so far
} PathAov;

PathAov aov_start(void) {
  PathAov a;
  a.albedo = a.normal = (float3)(0.0f);
  a.depth = a.travelled = 0.0f;
  a.alpha = 1.0f;
  a.found = false;
  a.see_through = true;
  return a;
}

// The path escapes with throughput beta toward radiance le
void aov_escape(PathAov* a, float3 beta, float3 le) {
  if (a->see_through) a->alpha = 1.0f - (beta.x + beta.y + beta.z) / 3.0f;
  if (!a->found) a->albedo = clamp(le, 0.0f, 1.0f);
  a->found = true;
}

// A surface vertex: its BSDF sample (sampled false: none) and shading normal n
void aov_vertex(PathAov* a, const BsdfSample* bs, bool sampled, float3 n) {
  bool delta = sampled && (bs->flags & BSDF_DELTA) != 0u;
  a->see_through = a->see_through && delta && (bs->flags & BSDF_TRANSMISSION) != 0u;
  if (a->found || delta) return;
  a->found = true;
  a->normal = n;
  if (sampled) a->albedo = bs->f * (fabs(dot(bs->wi, n)) / bs->pdf);
}

// A surface that ends the path with its own radiance (unlit): its colour, clamped to 1
void aov_unlit(PathAov* a, float3 colour, float3 n) {
  a->see_through = false;
  if (a->found) return;
  a->found = true;
  a->normal = n;
  a->albedo = clamp(colour, 0.0f, 1.0f);
}

float3 aov_finite3(float3 v) { return all_finite(v) ? v : (float3)(0.0f); }

// One sample's AOVs into the pixel's running means (a0: albedo, alpha; a1: normal, depth)
// over n samples, this one included
void aov_add(float4* a0, float4* a1, const PathAov* a, float n) {
  float alpha = isfinite(a->alpha) ? a->alpha : 1.0f;
  float4 x0 = (float4)(aov_finite3(a->albedo), alpha);
  float4 x1 = (float4)(aov_finite3(a->normal), isfinite(a->depth) ? a->depth : 0.0f);
  *a0 += (x0 - *a0) / n;
  *a1 += (x1 - *a1) / n;
}
