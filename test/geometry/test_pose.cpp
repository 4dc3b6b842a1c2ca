#include "mono_plane_detection/geometry/pose.h"

#include <gtest/gtest.h>

namespace mono_plane_detection {
namespace {

// 90 deg about z, then 1 m along x.
Pose aFromB() { return {cv::Matx33d(0, -1, 0, 1, 0, 0, 0, 0, 1), cv::Vec3d(1, 0, 0)}; }

TEST(Pose, ApplyRotatesThenTranslates) {
  EXPECT_LT(cv::norm(aFromB().apply({1, 0, 0}) - cv::Vec3d(1, 1, 0)), 1e-12);
}

TEST(Pose, InverseUndoesApply) {
  const cv::Vec3d x(0.3, -2, 5);
  EXPECT_LT(cv::norm(aFromB().inverse().apply(aFromB().apply(x)) - x), 1e-12);
}

TEST(Pose, ProductChainsFrames) {
  const Pose b_from_c{cv::Matx33d::eye(), cv::Vec3d(0, 0, 2)};
  const cv::Vec3d x(1, 2, 3);
  EXPECT_LT(cv::norm((aFromB() * b_from_c).apply(x) - aFromB().apply(b_from_c.apply(x))), 1e-12);
}

TEST(Pose, RotationAngleIsHowFarItTurns) {
  EXPECT_NEAR(rotationAngleDeg(aFromB().R), 90.0, 1e-9);
  EXPECT_NEAR(rotationAngleDeg(cv::Matx33d::eye()), 0.0, 1e-9);
  EXPECT_NEAR(rotationAngleDeg(cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1)), 180.0, 1e-9);
  // Rounding past +-1 in the trace is no NaN.
  EXPECT_NEAR(rotationAngleDeg(cv::Matx33d::eye() * (1 + 1e-12)), 0.0, 1e-3);
}

// In the target's frame (y up, z out of the wall): a camera facing the wall upright, the
// same camera rolled on its side (a sheet it would call portrait), and one pitched down
// 35 or 60 deg at a sheet on the floor (there the target's y runs along the floor, away).
TEST(Pose, CameraUpAngleIsHowFarTheImagesUpIsFromAnAxis) {
  const cv::Vec3d y(0, 1, 0);
  const Pose facing_wall{cv::Matx33d(1, 0, 0, 0, -1, 0, 0, 0, -1), {0, 0, 2}};
  EXPECT_NEAR(cameraUpAngleDeg(facing_wall, y), 0.0, 1e-9);
  EXPECT_NEAR(cameraUpAngleDeg(facing_wall, -y), 180.0, 1e-9);
  EXPECT_NEAR(cameraUpAngleDeg(facing_wall, 3 * y), 0.0, 1e-9);  // any length
  const Pose rolled{facing_wall.R * cv::Matx33d(0, -1, 0, 1, 0, 0, 0, 0, 1), facing_wall.t};
  EXPECT_NEAR(cameraUpAngleDeg(rolled, y), 90.0, 1e-9);
  for (double pitch : {35.0, 60.0}) {
    const double s = std::sin(pitch * CV_PI / 180), c = std::cos(pitch * CV_PI / 180);
    // Columns: the camera's x, y (image down) and z (optical axis) in the target's frame.
    const Pose over_floor{cv::Matx33d(1, 0, 0, 0, -s, c, 0, -c, -s), {0, -1, 1}};
    EXPECT_NEAR(cameraUpAngleDeg(over_floor, y), 90.0 - pitch, 1e-9) << pitch;
    EXPECT_NEAR(cameraUpAngleDeg(over_floor, cv::Vec3d(0, 0, 1)), pitch, 1e-9) << pitch;
  }
}

}  // namespace
}  // namespace mono_plane_detection
