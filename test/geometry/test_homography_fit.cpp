#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
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
  EXPECT_TRUE(std::isinf(transferErrorSquared(H, {0, 5}, {0, 0})));
  EXPECT_NEAR(transferErrorSquared(cv::Matx33d::eye(), {3, 4}, {0, 0}), 25.0, 1e-12);
  // A homography with w != 1 (the projective case the division-free test must scale).
  const cv::Point2d a(30, 40), b = transfer(kH, a) + cv::Point2d(0, 1.5);
  EXPECT_NEAR(transferErrorSquared(kH, a, b), 2.25, 1e-9);
  EXPECT_TRUE(transfersWithin(2.0 * kH, a, b, 1.6));  // scale-free, as transferError
  EXPECT_FALSE(transfersWithin(-3.0 * kH, a, b, 1.4));
}

// The one-division form is the same error (to the last bits), scale-free in H, and
// infinite where H sends the point to infinity.
TEST(HomographyFit, OneDivisionErrorIsTheTransferError) {
  for (const cv::Point2d& a : {cv::Point2d(30, 40), cv::Point2d(-200, 310), cv::Point2d(0, 0)}) {
    for (const cv::Point2d& off : {cv::Point2d(0, 0), cv::Point2d(0, 1.5), cv::Point2d(-7, 3)}) {
      const cv::Point2d b = transfer(kH, a) + off;
      const double e2 = off.dot(off);
      EXPECT_NEAR(transferErrorSquaredOneDivision(kH, a, b), e2, 1e-9 * (1 + e2));
      EXPECT_NEAR(transferErrorSquaredOneDivision(-4.0 * kH, a, b), e2, 1e-9 * (1 + e2));
      EXPECT_NEAR(transferErrorSquaredOneDivision(kH, a, b), transferErrorSquared(kH, a, b),
                  1e-9 * (1 + e2));
    }
  }
  const cv::Matx33d at_infinity(1, 0, 0, 0, 1, 0, 1, 0, 0);
  EXPECT_TRUE(std::isinf(transferErrorSquaredOneDivision(at_infinity, {0, 5}, {0, 0})));
}

namespace {

// The textbook normalised DLT: 9x9 normal matrix from the two rows per point, smallest
// eigenvector by the full eigensolver (what fitHomography computes faster).
cv::Matx33d referenceDlt(const std::vector<cv::Point2d>& from, const std::vector<cv::Point2d>& to,
                         const std::vector<double>& w) {
  auto normaliser = [](const std::vector<cv::Point2d>& p) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& q : p) mean += Eigen::Vector2d(q.x, q.y);
    mean /= static_cast<double>(p.size());
    double spread = 0.0;
    for (const auto& q : p) spread += (Eigen::Vector2d(q.x, q.y) - mean).norm();
    const double s = std::sqrt(2.0) / (spread / static_cast<double>(p.size()));
    Eigen::Matrix3d T;
    T << s, 0, -s * mean.x(), 0, s, -s * mean.y(), 0, 0, 1;
    return T;
  };
  const Eigen::Matrix3d Tf = normaliser(from), Tt = normaliser(to);
  Eigen::Matrix<double, 9, 9> normal = Eigen::Matrix<double, 9, 9>::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    const Eigen::Vector3d a = Tf * Eigen::Vector3d(from[i].x, from[i].y, 1.0);
    const Eigen::Vector3d b = Tt * Eigen::Vector3d(to[i].x, to[i].y, 1.0);
    Eigen::Matrix<double, 2, 9> rows;
    rows << 0, 0, 0, -a.x(), -a.y(), -1, b.y() * a.x(), b.y() * a.y(), b.y(), a.x(), a.y(), 1, 0,
        0, 0, -b.x() * a.x(), -b.x() * a.y(), -b.x();
    normal += (w.empty() ? 1.0 : w[i]) * rows.transpose() * rows;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> solver(normal);
  const Eigen::Matrix<double, 9, 1> h = solver.eigenvectors().col(0);
  Eigen::Matrix3d Hn;
  Hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  Eigen::Matrix3d H = Tt.inverse() * Hn * Tf;
  H /= H(2, 2);
  cv::Matx33d out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out(r, c) = H(r, c);
  return out;
}

}  // namespace

// fitHomography takes the smallest eigenvector by inverse iteration and builds the normal
// matrix from 3x3 blocks: the same homography as the textbook DLT, on five-point groups,
// large noisy sets with outliers, and with weights.
TEST(HomographyFit, MatchesTheTextbookDlt) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0, 640), w01(0, 1);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (int n : {5, 5, 5, 6, 12, 80, 400}) {
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<cv::Point2d> a, b;
      std::vector<double> w;
      for (int i = 0; i < n; ++i) {
        a.emplace_back(u(rng), u(rng));
        b.push_back(transfer(kH, a.back()) + cv::Point2d(noise(rng), noise(rng)));
        if (i % 7 == 3) b.back() += cv::Point2d(u(rng) / 10, -u(rng) / 10);  // outliers
        w.push_back(w01(rng));
      }
      for (const std::vector<double>& weights : {std::vector<double>{}, w}) {
        const auto H = fitHomography(a, b, weights);
        ASSERT_TRUE(H);
        const cv::Matx33d R = referenceDlt(a, b, weights);
        for (const auto& p : a) {
          const cv::Point2d d = transfer(*H, p) - transfer(R, p);
          EXPECT_LT(std::hypot(d.x, d.y), 1e-6) << n << " points, trial " << trial;
        }
      }
    }
  }
}
