// The search trigger (paper II-C) and the closest-wins matching (paper II-D).
#include <gtest/gtest.h>

#include "mono_plane_detection/tracking/feature_tracker.h"

using namespace mono_plane_detection;

TEST(ShouldSearch, TwoThirdsLostTriggers) {
  TrackerParams p;
  EXPECT_TRUE(shouldSearch(30, 10, 1, p));   // 20 of 30 lost
  EXPECT_FALSE(shouldSearch(30, 11, 1, p));  // 19 of 30 lost
  EXPECT_TRUE(shouldSearch(3, 1, 1, p));
  EXPECT_FALSE(shouldSearch(3, 2, 1, p));
}

TEST(ShouldSearch, EveryNFrames) {
  TrackerParams p;
  p.redetect_every = 10;
  EXPECT_FALSE(shouldSearch(50, 50, 9, p));
  EXPECT_TRUE(shouldSearch(50, 50, 10, p));
  p.redetect_every = 0;  // disabled
  EXPECT_FALSE(shouldSearch(50, 50, 1000, p));
}

TEST(ShouldSearch, NothingLeftAlwaysSearches) {
  TrackerParams p;
  EXPECT_TRUE(shouldSearch(0, 0, 1, p));
  EXPECT_TRUE(shouldSearch(50, 0, 1, p));
}

TEST(MatchCorners, WithinRadiusOnly) {
  const std::vector<cv::Point2f> points{{100, 100}, {200, 200}};
  const std::vector<cv::Point2f> corners{{102, 100}, {200, 204}, {150, 150}};
  const auto m = matchCornersToPoints(corners, points, 3.0);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0], 0);
  EXPECT_EQ(m[1], -1);  // 4 px away
  EXPECT_EQ(m[2], -1);
}

TEST(MatchCorners, ClosestWinsWhenTwoPickOnePoint) {
  const std::vector<cv::Point2f> points{{100, 100}};
  const std::vector<cv::Point2f> corners{{102, 100}, {100.5f, 100}, {99, 101}};
  const auto m = matchCornersToPoints(corners, points, 3.0);
  EXPECT_EQ(m[0], -1);
  EXPECT_EQ(m[1], 0);
  EXPECT_EQ(m[2], -1);
}

TEST(MatchCorners, EachCornerPicksItsNearestPoint) {
  const std::vector<cv::Point2f> points{{10, 10}, {13, 10}};
  const std::vector<cv::Point2f> corners{{12, 10}, {10.5f, 10}};
  const auto m = matchCornersToPoints(corners, points, 3.0);
  EXPECT_EQ(m[0], 1);
  EXPECT_EQ(m[1], 0);
}

TEST(MatchCorners, EmptyInputs) {
  EXPECT_TRUE(matchCornersToPoints({}, {{1, 1}}, 3.0).empty());
  const auto m = matchCornersToPoints({{1, 1}}, {}, 3.0);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0], -1);
}

TEST(ClosestClaimWins, LowestCostPerTargetFirstOnTies) {
  const auto r = closestClaimWins({0, 0, 1, -1, 1}, {3.0, 1.0, 2.0, 0.0, 2.0}, 2);
  EXPECT_EQ(r, (std::vector<int>{-1, 0, 1, -1, -1}));
  EXPECT_TRUE(closestClaimWins({}, {}, 3).empty());
}
