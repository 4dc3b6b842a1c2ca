#include <gtest/gtest.h>

#include "mono_plane_detection/viz/draw_tracks.h"

using namespace mono_plane_detection;

namespace {
cv::Vec3b pixelAt(const cv::Mat& img, const cv::Point& p) { return img.at<cv::Vec3b>(p); }
}  // namespace

TEST(DrawTracks, ColoursByState) {
  const cv::Mat grey(100, 100, CV_8UC1, cv::Scalar(0));
  TrackedPoint tracked, fresh;
  tracked.uv = {30, 50};
  tracked.is_tracked = true;
  fresh.uv = {70, 50};
  fresh.is_new = true;
  const cv::Mat out = drawTracks(grey, {tracked, fresh});
  ASSERT_EQ(out.type(), CV_8UC3);
  ASSERT_EQ(out.size(), grey.size());
  // The circle of radius 3 passes through (x+3, y).
  const cv::Vec3b red = pixelAt(out, {33, 50});
  const cv::Vec3b blue = pixelAt(out, {73, 50});
  EXPECT_GT(red[2], 100);
  EXPECT_LT(red[0], 50);
  EXPECT_GT(blue[0], 100);
  EXPECT_LT(blue[2], 50);
  EXPECT_EQ(cv::countNonZero(grey), 0);  // input untouched
}

TEST(DrawTracks, ColourInputKeepsItsPixelsElsewhere) {
  const cv::Mat bgr(50, 50, CV_8UC3, cv::Scalar(10, 20, 30));
  TrackedPoint p;
  p.uv = {10, 10};
  p.is_tracked = true;
  const cv::Mat out = drawTracks(bgr, {p});
  EXPECT_GT(cv::norm(out, bgr, cv::NORM_INF), 0.0);                 // the point is drawn ...
  EXPECT_EQ(out.at<cv::Vec3b>(40, 40), cv::Vec3b(10, 20, 30));       // ... not elsewhere
  const cv::Mat as_given(50, 50, CV_8UC3, cv::Scalar(10, 20, 30));
  EXPECT_EQ(cv::norm(bgr, as_given, cv::NORM_INF), 0.0);  // the caller's image untouched
}
