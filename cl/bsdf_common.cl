// What every BSDF lobe (bsdf_*.cl) returns from sampling, shared with the dispatch in
// bsdf.cl.

// BsdfSample flags (pbrt-v4's BxDFFlags): what kind of lobe produced the sample
#define BSDF_REFLECTION 1u
#define BSDF_TRANSMISSION 2u
#define BSDF_DIFFUSE 4u
#define BSDF_GLOSSY 8u
#define BSDF_DELTA 16u  // a Dirac lobe: only BSDF sampling can find it

typedef struct {
  float3 wi;  // sampled direction (world space out of bsdf_sample)
  float3 f;  // BSDF value for (wo, wi); for a delta lobe the weight of its Dirac
  float pdf;  // solid-angle pdf of wi (for a delta lobe, the discrete probability)
  uint flags;  // BSDF_*
  float eta;  // relative index of refraction across a transmission, else 1
} BsdfSample;
