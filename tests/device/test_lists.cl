// Lists test kernel (tests/device/lists_test.cpp).

// The value of every CD_SCENE_FEATURES macro in this program, in list order
#define TEST_FEATURE_VALUE(name, macro, fallback, needs) out[n++] = (uint)(macro);
__kernel void test_feature_defaults(__global uint* out) {
  if (get_global_id(0) != 0) return;
  uint n = 0u;
  CD_SCENE_FEATURES(TEST_FEATURE_VALUE)
}
