// Random numbers for the kernels: one interface, two samplers chosen at build time.
//
//   Rng rng = rng_init(pixel, sample, seed);
//   float u = rng_next(&rng);        // uniform in [0, 1), 24 bits
//   uint x = rng_next_uint(&rng);    // uniform 32 bits (light selection)
//   float2 p = rng_next_2d(&rng);    // a 2D point (light sample, BSDF direction)
//
// Each call takes the next *dimension* (rng_next_2d the next two) of sample `sample` of
// pixel `pixel`. Every number is a pure function of (pixel, sample index, seed,
// dimension), so an image depends only on the seed and the sample count, never on how
// samples are split into launches or devices.
//
// CD_SAMPLER_SOBOL=1 (the default): a stratified, randomized quasi-Monte Carlo sampler.
//   Dimensions go in consecutive pairs (2k, 2k+1). Pair k of pixel p takes the 2D Sobol
//   (0,2)-sequence: van der Corput in the first coordinate, Sobol's second dimension
//   (generator matrix: Pascal's triangle mod 2) in the second. Following Burley 2020,
//   Practical Hash-based Owen Scrambling:
//   - the sample index is shuffled by a nested uniform (Owen) scramble of its 32 bits:
//     bit q is flipped by a hash of the seed and the bits above it, so the indices 0 .. 2^m - 1
//     become a permutation of one block j 2^m .. (j + 1) 2^m - 1 of the sequence, and
//     every block of a (0,2)-sequence is a (0,m,2)-net: any prefix of 2^m samples of a
//     pair is stratified, and the order stays progressive;
//   - each coordinate is then Owen-scrambled with its own seed, which keeps every net a
//     net and makes each point uniformly distributed. The first needs it too, as in
//     Burley's paper: shuffling the index flips index bit q by the bits *above* q, which
//     are the *less* significant digits of its van der Corput point, so the unscrambled
//     point of the first 2^m samples keeps the same 32 - m low digits in every sample (one
//     offset shared by all strata: a shifted lattice, not a jittered one). A pixel then
//     picks, e.g., the same light in every stratum of the light table, and the many-lights
//     scene disagreed between seeds by z^2 = 9.4 (the 1D stream: light selection).
//   The pairs form two streams. 1D draws (rng_next, rng_next_uint) take consecutive
//   dimensions of the even pairs 0, 2, 4, ...: each is stratified on its own, and two
//   rng_next starting at an even 1D dimension (the pixel position and the lens sample,
//   drawn first) are one pair, stratified in 2D. rng_next_2d (light samples, BSDF
//   directions) takes the next odd pair 1, 3, 5, ... whole. So a 2D point is always a
//   pair, whatever number of 1D draws came before it, nothing is wasted, and the pair a
//   vertex's light or BSDF sample takes depends only on the 2D draws before it.
//   The three seeds of pair k are a pcg4d hash of (pixel, k, seed), so pixels and pairs are
//   decorrelated. Every dimension costs the same (no table, no cap): a pcg4d hash per
//   pair, three hashes, four bit reversals and a few bit operations for the Sobol matrix.
//   Owen scrambling is done with a Laine-Karras style hash on the bit-reversed value:
//   adding the seed, multiplying by odd numbers and x ^= x * even flip each bit by a
//   function of the bits below it only, which is exactly a nested scramble of the
//   reversed bits (constants from Vegdahl 2021, "Building a better LK hash").
// CD_SAMPLER_SOBOL=0: independent uniform numbers, a pcg4d hash (Jarzynski and Olano
//   2020, Hash Functions for GPU Rendering) of (pixel, sample, seed, counter), the
//   sampler candela had before (bit for bit).
//
// Both samplers are always compiled (rng_independent_*, rng_sobol_*; the tests call them
// directly); CD_SAMPLER_SOBOL picks the one behind Rng.

#ifndef CD_SAMPLER_SOBOL
#define CD_SAMPLER_SOBOL 1
#endif

// Written once, as a macro over four variables of type uint or uint8, so that the
// eight-lane version (CPU packets) is the scalar one lane for lane
#define RNG_PCG4D(a, b, c, d)     \
  a = a * 1664525u + 1013904223u; \
  b = b * 1664525u + 1013904223u; \
  c = c * 1664525u + 1013904223u; \
  d = d * 1664525u + 1013904223u; \
  a += b * d;                     \
  b += c * a;                     \
  c += a * b;                     \
  d += b * c;                     \
  a ^= a >> 16u;                  \
  b ^= b >> 16u;                  \
  c ^= c >> 16u;                  \
  d ^= d >> 16u;                  \
  a += b * d;                     \
  b += c * a;                     \
  c += a * b;                     \
  d += b * c

uint4 rng_pcg4d(uint4 v) {
  uint a = v.x, b = v.y, c = v.z, d = v.w;
  RNG_PCG4D(a, b, c, d);
  return (uint4)(a, b, c, d);
}

// The user's seed, hashed once so that neighbouring seeds give unrelated images
uint rng_hash_seed(uint seed) { return rng_pcg4d((uint4)(seed, 0x9e3779b9u, 0x85ebca6bu, 0xc2b2ae35u)).x; }

// Uniform float in [0, 1) from the top 24 bits (at most 1 - 2^-24)
float rng_uint_to_float(uint x) { return (float)(x >> 8) * 0x1.0p-24f; }

// ---- Independent sampler ------------------------------------------------------------

typedef struct {
  uint4 key;    // pixel, sample, hashed seed, block counter
  uint4 block;  // four outputs of the last hash
  uint used;    // outputs of `block` already handed out
} RngIndependent;

RngIndependent rng_independent_init(uint pixel, uint sample, uint seed) {
  RngIndependent r;
  r.key = (uint4)(pixel, sample, rng_hash_seed(seed), 0u);
  r.block = (uint4)(0u);
  r.used = 4u;
  return r;
}

uint rng_independent_next_uint(RngIndependent* r) {
  if (r->used == 4u) {
    r->block = rng_pcg4d(r->key);
    r->key.w += 1u;
    r->used = 0u;
  }
  uint x = r->used == 0u ? r->block.x : r->used == 1u ? r->block.y : r->used == 2u ? r->block.z : r->block.w;
  r->used += 1u;
  return x;
}

// ---- Owen-scrambled Sobol sampler ---------------------------------------------------

// The bit operations below are written once, as macros over a variable x of type uint or
// uint8, so that the eight-lane versions (CPU packets) are the scalar ones lane for lane
#define RNG_REVERSE_BITS(x)                                \
  x = (x << 16) | (x >> 16);                               \
  x = ((x & 0x00ff00ffu) << 8) | ((x >> 8) & 0x00ff00ffu); \
  x = ((x & 0x0f0f0f0fu) << 4) | ((x >> 4) & 0x0f0f0f0fu); \
  x = ((x & 0x33333333u) << 2) | ((x >> 2) & 0x33333333u); \
  x = ((x & 0x55555555u) << 1) | ((x >> 1) & 0x55555555u)

uint rng_reverse_bits(uint x) {
  RNG_REVERSE_BITS(x);
  return x;
}

// A seeded hash in which each bit of the result is that bit of x flipped by a function of
// the seed and the lower bits of x only: a bijection, and a nested (Owen) scramble of the
// bits read from the least significant one up. So reverse(rng_lk_hash(reverse(x), seed))
// Owen-scrambles the 32-bit binary fraction x: its most significant bit is flipped by the
// seed alone, every lower bit by the seed and the bits above it.
#define RNG_LK_HASH(x, seed) \
  x ^= x * 0x3d20adeau;      \
  x += seed;                 \
  x *= (seed >> 16) | 1u;    \
  x ^= x * 0x05526c56u;      \
  x ^= x * 0x53a22864u

uint rng_lk_hash(uint x, uint seed) {
  RNG_LK_HASH(x, seed);
  return x;
}

// Second dimension of the Sobol sequence at index i, with its bits reversed (bit r is the
// digit of 2^-(r+1)). Its generator matrix is Pascal's triangle mod 2: index bit b adds
// C(b, r) mod 2 to digit r, and by Lucas' theorem C(b, r) is odd exactly when the bits of
// r are a subset of those of b. So digit r is the XOR of the index bits b over the
// supersets b of r: a superset-XOR transform over the 5-bit bit positions, one step per
// position bit (equal to XOR-ing the columns v_0 = 1/2, v_{b+1} = v_b ^ (v_b >> 1) of the
// index's set bits)
#define RNG_SOBOL_DIM1_REVERSED(i) \
  i ^= (i >> 1) & 0x55555555u;     \
  i ^= (i >> 2) & 0x33333333u;     \
  i ^= (i >> 4) & 0x0f0f0f0fu;     \
  i ^= (i >> 8) & 0x00ff00ffu;     \
  i ^= (i >> 16) & 0x0000ffffu

uint rng_sobol_dim1_reversed(uint i) {
  RNG_SOBOL_DIM1_REVERSED(i);
  return i;
}

// Dimensions (2 pair, 2 pair + 1) of sample `sample` of `pixel`, as 32-bit fractions;
// hashed_seed = rng_hash_seed(seed), sample_reversed = rng_reverse_bits(sample)
uint2 rng_sobol_pair(uint pixel, uint sample_reversed, uint hashed_seed, uint pair) {
  uint4 h = rng_pcg4d((uint4)(pixel, pair, hashed_seed, 0x736f626cu));
  // The shuffled index is the sample index Owen-scrambled (a permutation of each 2^m
  // block). The first coordinate, van der Corput, is the reversed index, Owen-scrambled as
  // reverse(lk_hash(reverse(x))) = reverse(lk_hash(index)); the second is Owen-scrambled
  // the same way, and comes out of rng_sobol_dim1_reversed already reversed.
  uint index = rng_reverse_bits(rng_lk_hash(sample_reversed, h.x));
  uint x = rng_reverse_bits(rng_lk_hash(index, h.y));
  uint y = rng_reverse_bits(rng_lk_hash(rng_sobol_dim1_reversed(index), h.z));
  return (uint2)(x, y);
}

// Two streams of pairs: 1D draws (rng_next, rng_next_uint) take consecutive dimensions
// of the even pairs 0, 2, 4, ..., 2D draws (rng_next_2d) one whole odd pair 1, 3, 5, ...
typedef struct {
  uint pixel, sample_reversed, seed;  // seed hashed
  uint dimension_1d;                  // 1D draws so far; 1D draw d is coordinate d % 2 of pair 2 (d / 2)
  uint pending;                       // the second coordinate of the current even pair, when dimension_1d is odd
  uint draws_2d;                      // 2D draws so far: the next is pair 2 draws_2d + 1
} RngSobol;

RngSobol rng_sobol_init(uint pixel, uint sample, uint seed) {
  RngSobol r;
  r.pixel = pixel;
  r.sample_reversed = rng_reverse_bits(sample);
  r.seed = rng_hash_seed(seed);
  r.dimension_1d = 0u;
  r.pending = 0u;
  r.draws_2d = 0u;
  return r;
}

// The next dimension of the 1D stream, as a 32-bit fraction
uint rng_sobol_next_1d(RngSobol* r) {
  uint x;
  if ((r->dimension_1d & 1u) == 0u) {
    uint2 p = rng_sobol_pair(r->pixel, r->sample_reversed, r->seed, r->dimension_1d);  // d even: pair d
    x = p.x;
    r->pending = p.y;
  } else {
    x = r->pending;
  }
  r->dimension_1d += 1u;
  return x;
}

// The next pair of the 2D stream
uint2 rng_sobol_next_2d(RngSobol* r) {
  uint2 p = rng_sobol_pair(r->pixel, r->sample_reversed, r->seed, 2u * r->draws_2d + 1u);
  r->draws_2d += 1u;
  return p;
}

// ---- Eight pixels' first pair at once (CPU packets) -------------------------------------
// rng_pcg4d, rng_lk_hash, rng_reverse_bits and rng_sobol_dim1_reversed lane for lane on
// uint8, from the same macros: the same integer operations, so the same bits, in SIMD
// lanes. A work-item that traces eight camera rays as a packet draws their film
// positions (pair 0) this way.

void rng_pcg4d8(uint8* x, uint8* y, uint8* z, uint8* w) {
  uint8 a = *x, b = *y, c = *z, d = *w;
  RNG_PCG4D(a, b, c, d);
  *x = a;
  *y = b;
  *z = c;
  *w = d;
}

uint8 rng_lk_hash8(uint8 x, uint8 seed) {
  RNG_LK_HASH(x, seed);
  return x;
}

uint8 rng_reverse_bits8(uint8 x) {
  RNG_REVERSE_BITS(x);
  return x;
}

uint8 rng_sobol_dim1_reversed8(uint8 i) {
  RNG_SOBOL_DIM1_REVERSED(i);
  return i;
}

// rng_sobol_pair of eight pixels (lane l: pixel.sl) for one sample and pair
void rng_sobol_pair8(uint8 pixel, uint sample_reversed, uint hashed_seed, uint pair, uint8* x, uint8* y) {
  uint8 hx = pixel, hy = (uint8)(pair), hz = (uint8)(hashed_seed), hw = (uint8)(0x736f626cu);
  rng_pcg4d8(&hx, &hy, &hz, &hw);
  uint8 index = rng_reverse_bits8(rng_lk_hash8((uint8)(sample_reversed), hx));
  *x = rng_reverse_bits8(rng_lk_hash8(index, hy));
  *y = rng_reverse_bits8(rng_lk_hash8(rng_sobol_dim1_reversed8(index), hz));
}

// The state rng_sobol_init(pixel, sample, seed) is in after its first two 1D draws (pair 0,
// whose second coordinate is y), from the sample's reversed index and the hashed seed
RngSobol rng_sobol_after_pair0(uint pixel, uint sample_reversed, uint hashed_seed, uint y) {
  RngSobol r;
  r.pixel = pixel;
  r.sample_reversed = sample_reversed;
  r.seed = hashed_seed;
  r.dimension_1d = 2u;
  r.pending = y;
  r.draws_2d = 0u;
  return r;
}

// ---- The interface ------------------------------------------------------------------

#if CD_SAMPLER_SOBOL
typedef RngSobol Rng;
Rng rng_init(uint pixel, uint sample, uint seed) { return rng_sobol_init(pixel, sample, seed); }
uint rng_next_uint(Rng* r) { return rng_sobol_next_1d(r); }
float rng_next(Rng* r) { return rng_uint_to_float(rng_sobol_next_1d(r)); }
float2 rng_next_2d(Rng* r) {
  uint2 p = rng_sobol_next_2d(r);
  return (float2)(rng_uint_to_float(p.x), rng_uint_to_float(p.y));
}
#else
typedef RngIndependent Rng;
Rng rng_init(uint pixel, uint sample, uint seed) { return rng_independent_init(pixel, sample, seed); }
uint rng_next_uint(Rng* r) { return rng_independent_next_uint(r); }
float rng_next(Rng* r) { return rng_uint_to_float(rng_independent_next_uint(r)); }
float2 rng_next_2d(Rng* r) {
  float x = rng_next(r);
  return (float2)(x, rng_next(r));
}
#endif
