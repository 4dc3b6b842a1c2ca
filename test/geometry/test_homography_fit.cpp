#include <gtest/gtest.h>

#include <random>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/sim/synthetic_views.h"

using namespace mono_plane_detection;

namespace {
const cv::Matx33d kH(1.1, 0.05, 3, -0.02, 0.95, -4, 1e-4, 2e-4, 1);
}

TEST(HomographyFit, ExactFromFivePoints) {
  std::vector<cv::Point2d> a{{10, 10}, {300, 15}, {150, 290}, {320, 330}, {20, 340}}, b;
  for (const auto& p : a) b.push_back(transfer(kH, p));
  const auto H = fitHomography(a, b);
  ASSERT_TRUE(H);
  EXPECT_LT(cv::norm(*H - kH), 1e-9);
  for (size_t i = 0; i < a.size(); ++i) EXPECT_LT(transferError(*H, a[i], b[i]), 1e-8);
}

TEST(HomographyFit, WeightsSilenceAnOutlier) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(0, 400);
  std::vector<cv::Point2d> a, b;
  for (int i = 0; i < 30; ++i) {
    a.emplace_back(u(rng), u(rng));
    b.push_back(transfer(kH, a.back()));
  }
  b[7] += cv::Point2d(40, -25);
  std::vector<double> w(a.size(), 1.0);
  const auto plain = fitHomography(a, b);
  w[7] = 0.0;
  const auto weighted = fitHomography(a, b, w);
  ASSERT_TRUE(plain && weighted);
  EXPECT_GT(transferError(*plain, a[0], b[0]), 0.05);
  EXPECT_LT(transferError(*weighted, a[0], b[0]), 1e-8);
}

TEST(HomographyFit, DegenerateInputGivesNothing) {
  EXPECT_FALSE(fitHomography({{0, 0}, {1, 1}, {2, 0}}, {{0, 0}, {1, 1}, {2, 0}}));  // 3 points
  EXPECT_FALSE(fitHomography({{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}},
                             {{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}}));  // collinear
  EXPECT_FALSE(fitHomography({{1, 1}, {1, 1}, {1, 1}, {1, 1}}, {{0, 0}, {1, 0}, {0, 1}, {1, 1}}));
  EXPECT_FALSE(fitHomography({{0, 0}, {1, 0}, {0, 1}, {1, 1}}, {{0, 0}, {1, 0}, {0, 1}}));
  EXPECT_FALSE(
      fitHomography({{0, 0}, {1, 0}, {0, 1}, {1, 1}}, {{0, 0}, {1, 0}, {0, 1}, {1, 1}}, {1, 1}));
}

TEST(HomographyFit, TransfersWithinAgreesWithTransferError) {
  for (double dx : {0.0, 1.9, 2.1, 5.0}) {
    EXPECT_EQ(transfersWithin(kH, {30, 40}, transfer(kH, {30, 40}) + cv::Point2d(dx, 0), 2.0),
              dx < 2.0);
  }
  const cv::Matx33d at_infinity(1, 0, 0, 0, 1, 0, 1, 0, 0);
  EXPECT_FALSE(transfersWithin(at_infinity, {0, 5}, {0, 0}, 1e9));
}

TEST(HomographyFit, TransferErrorAtInfinity) {
  const cv::Matx33d H(1, 0, 0, 0, 1, 0, 1, 0, 0);  // sends x = 0 to infinity
  EXPECT_TRUE(std::isinf(transferError(H, {0, 5}, {0, 0})));
  EXPECT_NEAR(transferError(cv::Matx33d::eye(), {3, 4}, {0, 0}), 5.0, 1e-12);
}
