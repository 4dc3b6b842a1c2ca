// The debug drawing of planes and groups.
#include <gtest/gtest.h>

#include "mono_plane_detection/viz/draw_planes.h"

using namespace mono_plane_detection;

TEST(DrawPlanes, ColoursDifferBetweenNeighbouringIds) {
  for (int id = 1; id < 20; ++id) EXPECT_GT(cv::norm(planeColour(id) - planeColour(id + 1)), 60);
}

TEST(DrawPlanes, PointsTakeTheirPlanesColour) {
  const cv::Mat grey(120, 160, CV_8UC1, cv::Scalar(0));
  PipelineResult r;
  r.status = "tracking (target)";
  r.pairs.ids = {10, 11};
  r.pairs.first = {{40, 60}, {100, 60}};
  r.pairs.second = {{40, 60}, {100, 60}};
  r.segmentation.labels = {1, 0};
  ImagePlane plane;
  plane.id = 3;
  plane.map_id = 7;
  plane.inlier_ids = {10};
  r.planes = {plane};
  r.segmentation.accepted_groups = {{0, 1, 0, 1, 0}};
  const cv::Mat out = drawPlanes(grey, r);
  ASSERT_EQ(out.type(), CV_8UC3);
  ASSERT_EQ(out.size(), grey.size());
  const cv::Vec3b on_plane = out.at<cv::Vec3b>(60, 40), off_plane = out.at<cv::Vec3b>(60, 100);
  const cv::Scalar map_colour = planeColour(7);  // the map's id wins over the image's
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(on_plane[c], map_colour[c], 2);
    EXPECT_EQ(off_plane[c], 128);
  }
}
