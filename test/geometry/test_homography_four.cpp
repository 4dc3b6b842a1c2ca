#include <gtest/gtest.h>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/geometry/homography_four.h"

using namespace mono_plane_detection;

namespace {
cv::Point2d apply(const cv::Matx33d& H, const cv::Point2d& p) {
  const cv::Vec3d q = H * cv::Vec3d(p.x, p.y, 1.0);
  return {q[0] / q[2], q[1] / q[2]};
}
}  // namespace

TEST(HomographyFromFour, RecoversAKnownHomography) {
  const cv::Matx33d truth(1.1, 0.05, 30, -0.08, 0.95, -12, 2e-4, -1e-4, 1);
  const cv::Point2d from[4] = {{10, 20}, {600, 40}, {580, 450}, {30, 400}};
  cv::Point2d to[4];
  for (int k = 0; k < 4; ++k) to[k] = apply(truth, from[k]);
  const auto H = homographyFromFour(from, to);
  ASSERT_TRUE(H);
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(H->val[k], truth.val[k], 1e-9 * (1 + std::abs(truth.val[k])));
  // Any other point of the plane transfers exactly too.
  EXPECT_LT(transferError(*H, {320, 240}, apply(truth, {320, 240})), 1e-9);
  // Same answer as the normalised DLT on the four.
  const auto dlt = fitHomography({from, from + 4}, {to, to + 4});
  ASSERT_TRUE(dlt);
  EXPECT_LT(cv::norm(apply(*H, {100, 300}) - apply(*dlt, {100, 300})), 1e-6);
}

TEST(HomographyFromFour, CollinearPointsGiveNothing) {
  const cv::Point2d line[4] = {{0, 0}, {1, 1}, {2, 2}, {5, 1}};
  const cv::Point2d good[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_FALSE(homographyFromFour(line, good));
  EXPECT_FALSE(homographyFromFour(good, line));
  const cv::Point2d fourth_on_edge[4] = {{0, 0}, {1, 0}, {1, 1}, {0.5, 0}};
  EXPECT_FALSE(homographyFromFour(fourth_on_edge, good));
  EXPECT_TRUE(homographyFromFour(good, good));
}
