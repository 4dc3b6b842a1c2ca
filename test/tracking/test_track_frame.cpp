// Validation of incoming track frames and matching by id.
#include <gtest/gtest.h>

#include <limits>

#include "mono_plane_detection/tracking/track_frame.h"

using namespace mono_plane_detection;

namespace {

TrackFrame good() {
  TrackFrame f;
  f.size = {640, 480};
  f.ids = {1, 2, 3};
  f.pixels = {{10, 10}, {641.4, 481.4}, {-2.4, 0}};  // within the 2 px border margin
  f.target_corner = {false, false, true};
  return f;
}

}  // namespace

TEST(TrackFrame, AcceptsAWellFormedFrame) { EXPECT_EQ(validateTrackFrame(good()), ""); }

TEST(TrackFrame, NamesWhatIsWrong) {
  TrackFrame f = good();
  f.pixels.pop_back();
  EXPECT_NE(validateTrackFrame(f).find("array lengths differ"), std::string::npos);
  f = good();
  f.reidentified = {true};  // (optional, but as long as the ids when given)
  EXPECT_NE(validateTrackFrame(f).find("1 re-identified"), std::string::npos);
  f.reidentified = {true, false, false};
  EXPECT_EQ(validateTrackFrame(f), "");
  f = good();
  f.pixels[1].x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(validateTrackFrame(f).find("non-finite"), std::string::npos);
  f = good();
  f.pixels[0].y = std::numeric_limits<double>::infinity();
  EXPECT_NE(validateTrackFrame(f).find("non-finite"), std::string::npos);
  f = good();
  f.pixels[0] = {700, 10};
  EXPECT_NE(validateTrackFrame(f).find("outside"), std::string::npos);
  f = good();
  f.pixels[0] = {10, 481.6};  // just beyond the margin
  EXPECT_NE(validateTrackFrame(f).find("outside"), std::string::npos);
  f = good();
  f.ids[2] = 1;
  EXPECT_NE(validateTrackFrame(f).find("appears twice"), std::string::npos);
  f = good();
  f.size = {0, 0};
  EXPECT_NE(validateTrackFrame(f).find("empty"), std::string::npos);
}

TEST(TrackFrame, EmptyFrameIsValid) {
  TrackFrame f;
  f.size = {320, 240};
  EXPECT_EQ(validateTrackFrame(f), "");
}

TEST(TrackFrame, MatchByIdPairsTheSamePoints) {
  TrackFrame a = good(), b = good();
  b.ids = {3, 9, 1};
  b.pixels = {{5, 5}, {6, 6}, {7, 7}};
  const TrackPairs c = matchById(a, b);
  ASSERT_EQ(c.ids.size(), 2u);
  EXPECT_EQ(c.ids[0], 3u);
  EXPECT_EQ(c.first[0], cv::Point2d(-2.4, 0));
  EXPECT_EQ(c.second[0], cv::Point2d(5, 5));
  EXPECT_EQ(c.ids[1], 1u);
  EXPECT_EQ(c.first[1], cv::Point2d(10, 10));
  EXPECT_EQ(c.second[1], cv::Point2d(7, 7));
}

TEST(TrackFrame, TrackerPointsBecomeAFrame) {
  std::vector<TrackedPoint> points(2);
  points[0].id = 7;
  points[0].uv = {10.5f, 20.25f};
  points[1].id = 9;
  points[1].uv = {30, 40};
  points[1].is_target_corner = true;
  points[0].is_reidentified = true;
  const TrackFrame f = trackFrameOf(points, 12.5, {640, 480});
  EXPECT_EQ(f.stamp, 12.5);
  EXPECT_EQ(f.size, cv::Size(640, 480));
  EXPECT_EQ(f.ids, (std::vector<std::uint64_t>{7, 9}));
  EXPECT_EQ(f.pixels[0], cv::Point2d(10.5, 20.25));
  EXPECT_EQ(f.target_corner, (std::vector<bool>{false, true}));
  EXPECT_EQ(f.reidentified, (std::vector<bool>{true, false}));
  EXPECT_EQ(validateTrackFrame(f), "");
}
