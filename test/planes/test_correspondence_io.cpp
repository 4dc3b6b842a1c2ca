#include <gtest/gtest.h>

#include <sstream>

#include "mono_plane_detection/planes/correspondence_io.h"

using namespace mono_plane_detection;

namespace {
Correspondences read(const std::string& text) {
  std::istringstream in(text);
  return readCorrespondences(in);
}
}  // namespace

TEST(CorrespondenceIo, ReadsNumbersCommentsAndBlankLines) {
  const auto c = read("# header\n1 2 3 4\n\n  5.5\t6e1 -7 8 # trailing comment\n");
  EXPECT_TRUE(c.error.empty());
  ASSERT_EQ(c.view1.size(), 2u);
  EXPECT_EQ(c.view1[1], cv::Point2d(5.5, 60));
  EXPECT_EQ(c.view2[1], cv::Point2d(-7, 8));
}

TEST(CorrespondenceIo, NamesTheBadLine) {
  auto c = read("1 2 3 4\n1 2 3\n");
  EXPECT_EQ(c.error_line, 2);
  EXPECT_NE(c.error.find("line 2"), std::string::npos);
  EXPECT_NE(c.error.find("4 numbers"), std::string::npos);
  c = read("1 2 3 4\n1 2 3 4\n1 nan 3 4\n");
  EXPECT_EQ(c.error_line, 3);
  EXPECT_NE(c.error.find("'nan'"), std::string::npos);
  c = read("1 2 3 x\n");
  EXPECT_EQ(c.error_line, 1);
  c = read("1 2 3 4 5\n");
  EXPECT_EQ(c.error_line, 1);
  c = read("1 2 3 1e999\n");  // overflows to infinity
  EXPECT_EQ(c.error_line, 1);
  c = read("1 2 3 4abc\n");
  EXPECT_EQ(c.error_line, 1);
}

TEST(CorrespondenceIo, EmptyInputIsNoPoints) {
  const auto c = read("");
  EXPECT_TRUE(c.error.empty());
  EXPECT_TRUE(c.view1.empty());
}
