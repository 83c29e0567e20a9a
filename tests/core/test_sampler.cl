// Sampler tests (tests/sampler_test.cpp): draws of the real samplers in cl/core/rng.cl.

// Work-item i draws `dims` dimensions (32-bit fractions) of sample sample_begin + i % samples
// of pixel pixel_begin + i / samples into out[i * dims + d]; which: 0 the Sobol sampler
// (dimension d is coordinate d % 2 of pair d / 2), 1 the independent one
__kernel void test_sampler_draw(uint which, uint pixel_begin, uint sample_begin, uint samples, uint seed, uint dims,
                                __global uint* out) {
  uint i = get_global_id(0);
  uint pixel = pixel_begin + i / samples, sample = sample_begin + i % samples;
  if (which == 0u) {
    uint sample_reversed = rng_reverse_bits(sample), hashed_seed = rng_hash_seed(seed);
    for (uint d = 0u; d < dims; ++d) {
      uint2 p = rng_sobol_pair(pixel, sample_reversed, hashed_seed, d / 2u);
      out[i * dims + d] = d % 2u == 0u ? p.x : p.y;
    }
  } else {
    RngIndependent r = rng_independent_init(pixel, sample, seed);
    for (uint d = 0u; d < dims; ++d) out[i * dims + d] = rng_independent_next_uint(&r);
  }
}

// The interface the kernels use (the build's Rng): sample sample_begin + i % samples of
// pixel pixel_begin + i / samples makes the calls ops[0 .. n_ops): 0 rng_next, 1
// rng_next_uint (written as rng_uint_to_float of it), 2 rng_next_2d (two outputs), `outputs`
// floats in all, into out[i * outputs ..]
__kernel void test_sampler_interface(uint pixel_begin, uint sample_begin, uint samples, uint seed,
                                     __global const uint* ops, uint n_ops, uint outputs, __global float* out) {
  uint i = get_global_id(0);
  Rng r = rng_init(pixel_begin + i / samples, sample_begin + i % samples, seed);
  __global float* o = out + i * outputs;
  for (uint k = 0u; k < n_ops; ++k) {
    if (ops[k] == 0u) {
      *o++ = rng_next(&r);
    } else if (ops[k] == 1u) {
      *o++ = rng_uint_to_float(rng_next_uint(&r));
    } else {
      float2 p = rng_next_2d(&r);
      *o++ = p.x;
      *o++ = p.y;
    }
  }
}

// rng_sobol_pair8 against rng_sobol_pair: work-item i draws pair `pair` of sample
// samples[i] for the eight pixels pixels[8i .. 8i + 8) both ways; out[i] = 1 when all eight
// lanes agree bit for bit with the scalar pairs
__kernel void test_sampler_pair8(__global const uint* pixels, __global const uint* samples, uint seed, uint pair,
                                 __global uint* out) {
  uint i = get_global_id(0);
  uint lanes[8];
  for (int l = 0; l < 8; ++l) lanes[l] = pixels[8u * i + (uint)l];
  uint sample_reversed = rng_reverse_bits(samples[i]), hashed_seed = rng_hash_seed(seed);
  uint8 x, y;
  rng_sobol_pair8(vload8(0, lanes), sample_reversed, hashed_seed, pair, &x, &y);
  uint xs[8], ys[8];
  vstore8(x, 0, xs);
  vstore8(y, 0, ys);
  uint same = 1u;
  for (int l = 0; l < 8; ++l) {
    uint2 p = rng_sobol_pair(lanes[l], sample_reversed, hashed_seed, pair);
    same &= (uint)(p.x == xs[l] && p.y == ys[l]);
  }
  out[i] = same;
}
