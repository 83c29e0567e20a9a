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
