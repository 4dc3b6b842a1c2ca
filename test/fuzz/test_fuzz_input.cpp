// Regression test for the one crash `make fuzz` found: the fuzz harness's byte reader
// stepped past the end of short inputs, then read out of range.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "fuzz/fuzz_input.h"

using mono_plane_detection::FuzzInput;

TEST(FuzzInput, ReadsFloatsThenStopsAtTheEnd) {
  const float values[] = {1.5f, -2.0f};
  std::vector<uint8_t> bytes(sizeof values + 2, 0xFF);  // two floats and 2 stray bytes
  std::memcpy(bytes.data(), values, sizeof values);
  FuzzInput in(bytes.data(), bytes.size());
  EXPECT_EQ(in.nextFloat(), 1.5);
  EXPECT_EQ(in.nextFloat(), -2.0);
  EXPECT_EQ(in.left(), 2u);
  EXPECT_EQ(in.nextFloat(), 0.0);  // 2 bytes cannot make a float
  EXPECT_TRUE(in.empty());
  EXPECT_EQ(in.left(), 0u);
  for (int i = 0; i < 10; ++i) {  // reading on past the end stays at the end
    EXPECT_EQ(in.nextFloat(), 0.0);
    EXPECT_EQ(in.nextByte(), 0u);
  }
  EXPECT_EQ(in.left(), 0u);
}

TEST(FuzzInput, ReadsPointsXFirst) {
  const float values[] = {3.0f, 4.0f, 5.0f};
  std::vector<uint8_t> bytes(sizeof values);
  std::memcpy(bytes.data(), values, sizeof values);
  FuzzInput in(bytes.data(), bytes.size());
  EXPECT_EQ(in.nextPoint(), cv::Point2d(3, 4));
  EXPECT_EQ(in.nextPoint(), cv::Point2d(5, 0));  // y ran out
  EXPECT_TRUE(in.empty());
}

TEST(FuzzInput, ReadsBytesInOrder) {
  const std::vector<uint8_t> bytes = {7, 8};
  FuzzInput in(bytes.data(), bytes.size());
  EXPECT_EQ(in.nextByte(), 7u);
  EXPECT_EQ(in.nextByte(), 8u);
  EXPECT_EQ(in.nextByte(), 0u);
  EXPECT_TRUE(in.empty());
}
