// Ground-truth reader: the `t x y phi` format with comments and blank lines, and clear errors.
#include "evidential_slam/io/ground_truth.h"

#include <gtest/gtest.h>

#include <sstream>

#include "test_util.h"

namespace evidential_slam {
namespace io {
namespace {

TEST(GroundTruth, ReadsLinesSkipsCommentsAndBlanks) {
  const auto path = test::scratchDir() / "gt.txt";
  test::writeText(path,
                  "# t x y phi\n"
                  "\n"
                  "1464600320.989009 0.000 0.000 0.000\n"
                  "   % another comment style\n"
                  "1.5\t-2.25 3e-1 -3.14159\r\n"
                  "  2 +1 -1 0.5   \n");
  std::vector<StampedPose> poses;
  std::string error;
  ASSERT_TRUE(readGroundTruth(path.string(), &poses, &error)) << error;
  ASSERT_EQ(poses.size(), 3u);
  EXPECT_DOUBLE_EQ(poses[0].stamp, 1464600320.989009);
  EXPECT_DOUBLE_EQ(poses[1].stamp, 1.5);
  EXPECT_DOUBLE_EQ(poses[1].pose.x, -2.25);
  EXPECT_DOUBLE_EQ(poses[1].pose.y, 0.3);
  EXPECT_NEAR(poses[1].pose.theta, -3.14159, 1e-12);
  EXPECT_DOUBLE_EQ(poses[2].pose.x, 1.0);
}

TEST(GroundTruth, ReadsCommittedFixture) {
  std::vector<StampedPose> poses;
  std::string error;
  ASSERT_TRUE(readGroundTruth(test::dataPath("sim.GT.txt"), &poses, &error)) << error;
  EXPECT_EQ(poses.size(), 159u);
  for (size_t i = 1; i < poses.size(); ++i) EXPECT_GT(poses[i].stamp, poses[i - 1].stamp);
}

TEST(GroundTruth, MalformedLinesAreErrorsWithFileAndLine) {
  const auto dir = test::scratchDir();
  const std::vector<std::string> bad = {
      "1 2 3\n",        // three fields
      "1 2 3 4 5\n",    // five
      "1 2 three 4\n",  // not a number
      "1 2 3 4x\n",     // trailing junk
      "1 nan 3 4\n",    // not finite
      "1 2 3 inf\n",
  };
  for (size_t i = 0; i < bad.size(); ++i) {
    const auto path = dir / ("bad" + std::to_string(i) + ".txt");
    test::writeText(path, "# header\n0 0 0 0\n" + bad[i]);
    std::vector<StampedPose> poses;
    std::string error;
    EXPECT_FALSE(readGroundTruth(path.string(), &poses, &error)) << bad[i];
    EXPECT_TRUE(poses.empty());
    EXPECT_NE(error.find(path.string() + ":3:"), std::string::npos) << error;
    EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  }
}

TEST(GroundTruth, RawBytesOfALineAreShownEscaped) {
  const auto path = test::scratchDir() / "binary.txt";
  test::writeText(path, std::string("0 0 0 0\n\x1b]0;x\x07\xfe 1 2\n", 20));
  std::vector<StampedPose> poses;
  std::string error;
  EXPECT_FALSE(readGroundTruth(path.string(), &poses, &error));
  EXPECT_NE(error.find(":2: expected 't x y phi', got '\\x1b]0;x\\x07\\xfe 1 2'"),
            std::string::npos)
      << error;
  for (char c : error) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << error;
}

TEST(GroundTruth, ReadsFromAStream) {
  std::istringstream in("# t x y phi\n1 2 3 0.5\n\n2, 3, 4, 0.25\n");
  std::vector<StampedPose> poses;
  std::string error;
  ASSERT_TRUE(readGroundTruth(in, "memory", &poses, &error)) << error;
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_DOUBLE_EQ(poses[1].pose.theta, 0.25);
  std::istringstream bad("1 2 3\n");
  EXPECT_FALSE(readGroundTruth(bad, "memory", &poses, &error));
  EXPECT_NE(error.find("memory:1:"), std::string::npos) << error;
}

TEST(GroundTruth, MissingFile) {
  std::vector<StampedPose> poses;
  std::string error;
  EXPECT_FALSE(readGroundTruth("/nonexistent/gt.txt", &poses, &error));
  EXPECT_NE(error.find("cannot open"), std::string::npos);
}

TEST(GroundTruth, ParseLine) {
  StampedPose p;
  EXPECT_TRUE(parseGroundTruthLine("0.5 1 2 3", &p));
  EXPECT_FALSE(parseGroundTruthLine("", &p));
  EXPECT_FALSE(parseGroundTruthLine("0.5 1 2", &p));
}

}  // namespace
}  // namespace io
}  // namespace evidential_slam
