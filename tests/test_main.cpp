#include <gtest/gtest.h>

#include <cstdlib>

int main(int argc, char** argv) {
  // Mesa's rusticl exposes llvmpipe only when asked; set before the ICD loader runs
  setenv("RUSTICL_ENABLE", "llvmpipe", 0);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
