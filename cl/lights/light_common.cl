// What light sampling works with (cl/lights/lights.cl): the context a light is sampled
// from (a surface point, or a point in a medium), a sample, and a light's extent as
// STRATEGY_AUTO sees it. Each light type's functions are in the file of its family
// (environment.cl, triangle.cl, punctual.cl); light selection in light_tree.cl and lights.cl.

typedef struct {
  float3 p;
  float3 n;        // geometric normal on the side light is gathered from; 0 at a point in a medium
  float3 ns;       // shading normal on the same side; 0 in a medium
  bool transmits;  // the BSDF (or phase function) also scatters light arriving from behind n
} LightSampleContext;

typedef struct {
  float3 wi;         // unit direction from ctx.p toward the light
  float3 radiance;   // emitted radiance arriving along -wi (intensity for delta lights)
  float pdf;         // solid-angle pdf of wi including the selection probability (delta: pmf)
  bool is_delta;     // a punctual or directional light: no BSDF-sampled ray can hit it
  bool at_infinity;  // shadow ray along wi without end
  float3 target;     // finite lights: the sampled point, moved off the light toward ctx.p
  uint light;        // index of the light picked
  float pmf;         // the probability of picking it (lights_select_pmf)
} LightSample;

// What STRATEGY_AUTO's choice between light and BSDF sampling needs of a light seen from a
// point (integrator_path.cl): its solid angle, the direction to its centre, and the
// probability with which light selection picks it
typedef struct {
  float3 dir;       // unit direction to the light's centre (an environment: its bright part's)
  float omega;      // solid angle (0: a delta light)
  float radius;     // angle from dir that holds the whole light
  float pmf;        // selection probability (set by path_nee_takes, not lights_extent)
  float integral;   // an environment: integral of its luminance over the sphere
  bool everywhere;  // an environment: it surrounds the point, overlapping every lobe
} LightExtent;

LightSampleContext light_context_at_surface(const SurfaceHit* s, const Bsdf* b) {
  LightSampleContext ctx;
  ctx.p = s->p;
  ctx.n = s->ng;
  ctx.ns = b->frame.n;  // the BSDF's shading normal (normal-mapped)
  ctx.transmits = (bsdf_flags(b) & BSDF_TRANSMISSION) != 0u;
  return ctx;
}
