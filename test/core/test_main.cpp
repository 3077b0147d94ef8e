// Entry point of the test_core executable: catkin_add_gtest links GTest::gtest only (no
// gtest_main), so the core test files share this main().
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
