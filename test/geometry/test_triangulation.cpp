#include "mono_plane_detection/geometry/triangulation.h"

#include <gtest/gtest.h>

namespace mono_plane_detection {
namespace {

cv::Point2d projectNormalised(const cv::Matx34d& P, const cv::Vec3d& x) {
  const cv::Vec3d c = P * cv::Vec4d(x[0], x[1], x[2], 1.0);
  return {c[0] / c[2], c[1] / c[2]};
}

// The second camera 0.3 m to the right, turned 5 deg towards the point.
cv::Matx34d secondCamera() {
  const double a = 5 * CV_PI / 180;
  const cv::Matx33d R(std::cos(a), 0, -std::sin(a), 0, 1, 0, std::sin(a), 0, std::cos(a));
  return projectionMatrix(R, R * cv::Vec3d(-0.3, 0, 0));
}

TEST(Triangulation, ProjectionMatrixIsRAndT) {
  const cv::Matx33d R(0, -1, 0, 1, 0, 0, 0, 0, 1);
  const cv::Matx34d P = projectionMatrix(R, cv::Vec3d(1, 2, 3));
  const cv::Vec3d c = P * cv::Vec4d(1, 0, 0, 1);
  EXPECT_EQ(c, cv::Vec3d(1, 3, 3));
}

TEST(Triangulation, RecoversAPointSeenFromTwoViews) {
  const cv::Matx34d P1 = projectionMatrix(cv::Matx33d::eye(), cv::Vec3d(0, 0, 0));
  const cv::Matx34d P2 = secondCamera();
  const cv::Vec3d truth(0.2, -0.1, 2.5);
  const auto p = triangulate(P1, P2, projectNormalised(P1, truth), projectNormalised(P2, truth));
  ASSERT_TRUE(p);
  EXPECT_LT(cv::norm(p->x - truth), 1e-9);
  EXPECT_NEAR(p->depth1, 2.5, 1e-9);
  EXPECT_GT(p->depth2, 2.0);
  EXPECT_LT(p->error, 1e-12);
}

TEST(Triangulation, ReportsTheReprojectionErrorOfNoisyRays) {
  const cv::Matx34d P1 = projectionMatrix(cv::Matx33d::eye(), cv::Vec3d(0, 0, 0));
  const cv::Matx34d P2 = secondCamera();
  const cv::Vec3d truth(0.2, -0.1, 2.5);
  const cv::Point2d noise(0, 0.01);  // rays that do not meet
  const auto p = triangulate(P1, P2, projectNormalised(P1, truth) + noise, projectNormalised(P2, truth));
  ASSERT_TRUE(p);
  EXPECT_GT(p->error, 1e-3);
  EXPECT_LT(p->error, 0.01);
}

TEST(Triangulation, APointBehindACameraHasANegativeDepth) {
  const cv::Matx34d P1 = projectionMatrix(cv::Matx33d::eye(), cv::Vec3d(0, 0, 0));
  const cv::Matx34d P2 = projectionMatrix(cv::Matx33d::eye(), cv::Vec3d(-0.3, 0, 0));
  const cv::Vec3d behind(0.1, 0.1, -2.0);
  const auto p = triangulate(P1, P2, projectNormalised(P1, behind), projectNormalised(P2, behind));
  ASSERT_TRUE(p);
  EXPECT_LT(p->depth1, 0);
  EXPECT_LT(p->depth2, 0);
}

TEST(Triangulation, ParallelRaysGiveNothing) {
  // Two cameras side by side, the same direction in both: the rays meet at infinity.
  const cv::Matx34d P1 = projectionMatrix(cv::Matx33d::eye(), cv::Vec3d(0, 0, 0));
  const cv::Matx34d P2 = projectionMatrix(cv::Matx33d::eye(), cv::Vec3d(-0.3, 0, 0));
  EXPECT_FALSE(triangulate(P1, P2, {0.1, 0.2}, {0.1, 0.2}).has_value());
}


// Sampson distance: 0 for a pair that fits E, about the pixel offset for one moved
// across its epipolar line.
TEST(Triangulation, SampsonDistanceIsTheOffsetFromTheEpipolarGeometry) {
  const cv::Matx33d R = cv::Matx33d::eye();
  const cv::Vec3d t(1, 0, 0);  // sideways: epipolar lines are horizontal
  const cv::Matx33d tx(0, -t[2], t[1], t[2], 0, -t[0], -t[1], t[0], 0);
  const cv::Matx33d E = tx * R;
  const cv::Matx34d P1 = projectionMatrix(cv::Matx33d::eye(), {0, 0, 0}), P2 = projectionMatrix(R, t);
  const cv::Vec4d X(0.2, -0.1, 4.0, 1.0);
  const cv::Vec3d a = P1 * X, b = P2 * X;
  const cv::Point2d x1(a[0] / a[2], a[1] / a[2]), x2(b[0] / b[2], b[1] / b[2]);
  EXPECT_NEAR(sampsonDistance(E, x1, x2), 0.0, 1e-12);
  // Moved 0.01 across the (horizontal) line in the second view: the offset is shared
  // between the two views, so the distance is 0.01 / sqrt(2).
  EXPECT_NEAR(sampsonDistance(E, x1, x2 + cv::Point2d(0, 0.01)), 0.01 / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(sampsonDistance(E, x1, x2 + cv::Point2d(0.05, 0)), 0.0, 1e-12);  // along it
}

}  // namespace
}  // namespace mono_plane_detection
