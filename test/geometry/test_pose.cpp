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

}  // namespace
}  // namespace mono_plane_detection
