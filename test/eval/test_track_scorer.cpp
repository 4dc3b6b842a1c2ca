#include <gtest/gtest.h>

#include "mono_plane_detection/sim/synthetic_views.h"
#include "mono_plane_detection/eval/track_scorer.h"

using namespace mono_plane_detection;

TEST(TrackScorer, ErrorIsDistanceFromWhereTheBirthPixelWent) {
  TrackScorer score;
  TrackedPoint p;
  p.id = 7;
  p.uv = {10, 20};
  score.observe({p}, similarity(0, {}, {0, 0}));  // born on texture pixel (10, 20)
  EXPECT_TRUE(score.errors().empty());
  p.is_tracked = true;
  p.uv = {15.5f, 20};
  score.observe({p}, similarity(0, {}, {5, 0}));  // truth (15, 20)
  ASSERT_EQ(score.errors().size(), 1u);
  EXPECT_NEAR(score.errors()[0], 0.5, 1e-6);
  EXPECT_EQ(score.texturePixel(7), cv::Point2d(10, 20));
  EXPECT_THROW(score.texturePixel(8), std::out_of_range);
  p.uv = {18, 24};
  score.observe({p}, similarity(0, {}, {5, 0}));  // 3-4-5 off
  EXPECT_NEAR(score.meanError(), 2.75, 1e-6);
  EXPECT_NEAR(score.maxError(), 5.0, 1e-6);
}

TEST(TrackScorer, UntrackedPointsAreNotScored) {
  TrackScorer score;
  TrackedPoint p;
  p.id = 1;
  score.observe({p}, cv::Matx33d::eye());
  p.uv = {100, 100};  // a new point reusing nothing: not tracked, no error
  score.observe({p}, cv::Matx33d::eye());
  EXPECT_TRUE(score.errors().empty());
}

TEST(Percentile, OfValues) {
  EXPECT_EQ(percentile({}, 0.5), 0.0);
  EXPECT_EQ(percentile({3, 1, 2, 5, 4}, 0.5), 3.0);
  EXPECT_EQ(percentile({3, 1, 2, 5, 4}, 1.0), 5.0);
  EXPECT_EQ(percentile({3, 1, 2, 5, 4}, 0.0), 1.0);
}
