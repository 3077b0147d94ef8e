// gtest entry point of the io/ test binaries (catkin_add_gtest links gtest without a main).
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
