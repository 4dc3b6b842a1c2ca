#include "mono_plane_detection/geometry/camera_model.h"

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

namespace mono_plane_detection {
namespace {

TEST(CameraModel, ProjectsTheOpticalAxisOnThePrincipalPoint) {
  const CameraModel cam;
  const cv::Point2d p = cam.project({0, 0, 3});
  EXPECT_DOUBLE_EQ(p.x, cam.cx);
  EXPECT_DOUBLE_EQ(p.y, cam.cy);
}

TEST(CameraModel, AgreesWithOpenCVsProjectionWithDistortion) {
  CameraModel cam;
  cam.k1 = -0.2;
  cam.k2 = 0.05;
  const cv::Vec3d x(0.8, -0.4, 2.0);
  std::vector<cv::Point2d> expected;
  cv::projectPoints(std::vector<cv::Point3d>{{x[0], x[1], x[2]}}, cv::Vec3d(0, 0, 0),
                    cv::Vec3d(0, 0, 0), cam.K(), cam.distortion(), expected);
  const cv::Point2d p = cam.project(x);
  EXPECT_NEAR(p.x, expected[0].x, 1e-9);
  EXPECT_NEAR(p.y, expected[0].y, 1e-9);
}

}  // namespace
}  // namespace mono_plane_detection
