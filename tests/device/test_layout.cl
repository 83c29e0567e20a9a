// Layout test kernel (tests/device/layout_test.cpp).

// Sizes and offsets of the shared structs as the device compiler lays them out, in the
// order of CD_LAYOUT (device_types.h), the list the host's static_asserts come from
#define TEST_LAYOUT_SIZE(type, bytes) out[n++] = (uint)sizeof(type);
#define TEST_LAYOUT_FIELD(type, field, offset)                \
  {                                                           \
    type object;                                              \
    out[n++] = (uint)((char*)&object.field - (char*)&object); \
  }
__kernel void test_struct_layout(__global uint* out) {
  if (get_global_id(0) != 0) return;
  uint n = 0u;
  CD_LAYOUT(TEST_LAYOUT_SIZE, TEST_LAYOUT_FIELD)
}

// The BSDF's lobe union (cl/bsdf/bsdf_common.cl) as the device lays it out: the number of
// BSDF_LOBE_TYPES members, the union's size, its words' bytes, BSDF_LOBE_BYTES, then the size of
// each member
#define TEST_LOBE_COUNT(type, member) +1u
#define TEST_LOBE_SIZE(type, member) out[n++] = (uint)sizeof(type);
__kernel void test_bsdf_lobe_layout(__global uint* out) {
  if (get_global_id(0) != 0) return;
  Bsdf b;
  uint n = 0u;
  out[n++] = 0u BSDF_LOBE_TYPES(TEST_LOBE_COUNT);
  out[n++] = (uint)sizeof(b.lobe);
  out[n++] = (uint)sizeof(b.lobe.words);
  out[n++] = (uint)BSDF_LOBE_BYTES;
  BSDF_LOBE_TYPES(TEST_LOBE_SIZE)
}
