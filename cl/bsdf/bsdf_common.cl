// What every BSDF lobe (bsdf_*.cl) shares with the dispatch in bsdf.cl: the sample record
// and the BSDF record of a shading point.

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

// The BSDF of one shading point: frame, normals and the material evaluated there
typedef struct {
  Frame frame;  // shading frame; frame.n is the (mapped) shading normal on wo's side
  float3 ng;  // geometric normal on wo's side
  bool entering;  // wo is on the front face: refraction goes from outside (1) to inside (ior)
  uint type;  // MATERIAL_*
  float3 base_color;  // diffuse albedo, metal F0, transmission tint
  float metallic;
  Ggx ggx;  // specular roughness, ax along frame.t
  float eta;  // relative index across the surface seen from wo: eta_t / eta_i
  float3 spec_f0;  // dielectric reflectance at normal incidence (KHR_materials_ior, _specular)
  float spec_f90;  // dielectric reflectance at grazing incidence (KHR_materials_specular)
  float transmission;
  bool thin;  // a thin-walled sheet: transmission does not bend
  float coat;  // clearcoat weight
  Ggx coat_ggx;
  float3 cond_eta, cond_k;  // MATERIAL_CONDUCTOR
  float3 cond_f_avg;  // MATERIAL_CONDUCTOR: hemispherical average of its Fresnel term
  __global const float* ggx_albedo;  // GGX albedo table (energy.cl); 0: no energy compensation
} Bsdf;
