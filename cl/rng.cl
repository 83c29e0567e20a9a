// Counter-based RNG: every random number is a hash of (pixel, sample index, seed,
// counter), so an image depends only on the seed and the sample count, never on how
// samples are split into launches or devices.
// Hash: pcg4d (Jarzynski and Olano 2020, Hash Functions for GPU Rendering).

typedef struct {
  uint4 key;  // pixel, sample, hashed seed, block counter
  uint4 block;  // four outputs of the last hash
  uint used;  // outputs of `block` already handed out
} Rng;

uint4 rng_pcg4d(uint4 v) {
  v = v * 1664525u + 1013904223u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  v ^= v >> 16u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  return v;
}

Rng rng_init(uint pixel, uint sample, uint seed) {
  Rng r;
  uint4 s = rng_pcg4d((uint4)(seed, 0x9e3779b9u, 0x85ebca6bu, 0xc2b2ae35u));
  r.key = (uint4)(pixel, sample, s.x, 0u);
  r.block = (uint4)(0u);
  r.used = 4u;
  return r;
}

uint rng_next_uint(Rng* r) {
  if (r->used == 4u) {
    r->block = rng_pcg4d(r->key);
    r->key.w += 1u;
    r->used = 0u;
  }
  uint x = r->used == 0u ? r->block.x
         : r->used == 1u ? r->block.y
         : r->used == 2u ? r->block.z
                         : r->block.w;
  r->used += 1u;
  return x;
}

// Uniform float in [0, 1) with 24 random bits
float rng_next(Rng* r) { return (float)(rng_next_uint(r) >> 8) * 0x1.0p-24f; }
