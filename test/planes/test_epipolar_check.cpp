#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <random>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/planes/epipolar_check.h"

using namespace mono_plane_detection;

namespace {

// Two cameras K[I|0], K[R|t] looking at two planes: the plane-induced homographies
// K (R - t n^T / d) K^-1 and F = K^-T [t]x R K^-1.
struct Rig {
  cv::Matx33d K{500, 0, 320, 0, 500, 240, 0, 0, 1};
  cv::Matx33d R;
  cv::Vec3d t{0.3, 0.05, 0.02};
  Rig() { cv::Rodrigues(cv::Vec3d(0.02, -0.1, 0.03), R); }
  cv::Matx33d H(const cv::Vec3d& n, double d) const {
    return K * (R - t * n.t() * (1.0 / d)) * K.inv();
  }
  cv::Matx33d F() const {
    const cv::Matx33d tx(0, -t[2], t[1], t[2], 0, -t[0], -t[1], t[0], 0);
    return K.inv().t() * tx * R * K.inv();
  }
  // Points on the plane n.X = d seen in both views, with pixel noise.
  void points(const cv::Vec3d& n, double d, int count, std::mt19937& rng,
              std::vector<cv::Point2d>& a, std::vector<cv::Point2d>& b) const {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::normal_distribution<double> g(0.0, 0.3);
    for (int i = 0; i < count; ++i) {
      cv::Vec3d ray(u(rng) * 0.6, u(rng) * 0.45, 1.0);
      const cv::Vec3d X = ray * (d / n.dot(ray));
      const cv::Vec3d x1 = K * X, x2 = K * (R * X + t);
      a.emplace_back(x1[0] / x1[2] + g(rng), x1[1] / x1[2] + g(rng));
      b.emplace_back(x2[0] / x2[2] + g(rng), x2[1] / x2[2] + g(rng));
    }
  }
};

}  // namespace

TEST(EpipolarCheck, PlaneInducedHomographiesAgreeWithF) {
  Rig rig;
  const cv::Vec3d floor(0, -1, 0), wall(0.2, 0, -1);
  const cv::Matx33d Hf = rig.H(floor, -1.2), Hw = rig.H(cv::normalize(wall), -3.0);
  EXPECT_LT(skewSymmetryError(Hf, rig.F()), 1e-9);
  EXPECT_LT(skewSymmetryError(Hw, rig.F()), 1e-9);
  const std::vector<cv::Point2d> probe{{100, 100}, {500, 80}, {320, 240}, {600, 400}, {50, 420}};
  EXPECT_LT(epipolarTransferError(Hf, rig.F(), probe), 1e-6);
  // A homography that is not plane-induced (an affine blend of the two): off the lines.
  const cv::Matx33d blend = 0.5 * (Hf + Hw) + cv::Matx33d(0, 0, 15, 0, 0, -20, 0, 0, 0);
  EXPECT_GT(skewSymmetryError(blend, rig.F()), 1e-3);
  EXPECT_GT(epipolarTransferError(blend, rig.F(), probe), 3.0);
  EXPECT_TRUE(std::isinf(epipolarTransferError(Hf, rig.F(), {})));
}

TEST(EpipolarCheck, EstimatesFFromTwoPlanes) {
  Rig rig;
  std::mt19937 rng(4);
  std::vector<cv::Point2d> a, b;
  rig.points({0, -1, 0}, -1.2, 80, rng, a, b);
  rig.points(cv::normalize(cv::Vec3d(0.2, 0, -1)), -3.0, 80, rng, a, b);
  const auto F = estimateFundamental(a, b, 1.0);
  ASSERT_TRUE(F);
  // The true plane homography is compatible with the estimate within about a pixel.
  const std::vector<cv::Point2d> probe(a.begin(), a.begin() + 40);
  EXPECT_LT(epipolarTransferError(rig.H({0, -1, 0}, -1.2), *F, probe), 1.5);
  // Too few points: nothing.
  EXPECT_FALSE(estimateFundamental({a.begin(), a.begin() + 10}, {b.begin(), b.begin() + 10}, 1.0));
}

namespace {
// The homography of the plane n.X = d (the convention of Rig::points):
// R X + t = (R + t n^T / d) X on it.
cv::Matx33d inducedBy(const Rig& rig, const cv::Vec3d& n, double d) {
  return rig.K * (rig.R + rig.t * n.t() * (1.0 / d)) * rig.K.inv();
}
cv::Point2d apply(const cv::Matx33d& H, const cv::Point2d& p) {
  const cv::Vec3d y = H * cv::Vec3d(p.x, p.y, 1);
  return {y[0] / y[2], y[1] / y[2]};
}
// Two walls in front of both cameras.
const cv::Vec3d kFront(0, 0, 1), kSide = cv::normalize(cv::Vec3d(0.5, 0, 1));
}  // namespace

TEST(EpipolarCheck, LineDistance) {
  Rig rig;
  const cv::Matx33d F = rig.F();
  // x2 on the epipolar line of x1 (the image of a point at any depth): 0; moved across
  // the line by 3 px: 3 px.
  const cv::Point2d x1(200, 150);
  const cv::Vec3d X = rig.K.inv() * cv::Vec3d(x1.x, x1.y, 1) * 4.0;
  const cv::Vec3d y = rig.K * (rig.R * X + rig.t);
  const cv::Point2d x2(y[0] / y[2], y[1] / y[2]);
  EXPECT_LT(epipolarLineDistance(F, x1, x2), 1e-6);
  const cv::Vec3d l = F * cv::Vec3d(x1.x, x1.y, 1);
  const cv::Point2d n = cv::Point2d(l[0], l[1]) * (1.0 / std::hypot(l[0], l[1]));
  EXPECT_NEAR(epipolarLineDistance(F, x1, x2 + 3.0 * n), 3.0, 1e-6);
  EXPECT_TRUE(std::isinf(epipolarLineDistance(cv::Matx33d::zeros(), x1, x2)));
}

TEST(EpipolarCheck, RefinesFFromTwoPlanes) {
  Rig rig;
  std::mt19937 rng(7);
  std::vector<cv::Point2d> a, b;
  rig.points(kFront, 3.0, 60, rng, a, b);
  rig.points(kSide, 2.5, 60, rng, a, b);
  const auto F = refineFundamental(a, b, 0.3);
  ASSERT_TRUE(F);
  // Every point within the noise of its epipolar line, and the true plane homographies
  // compatible with it.
  double worst = 0.0;
  for (size_t i = 0; i < a.size(); ++i)
    worst = std::max(worst, epipolarLineDistance(*F, a[i], b[i]));
  EXPECT_LT(worst, 1.5);
  const std::vector<cv::Point2d> probe{{100, 100}, {320, 240}, {600, 400}};
  EXPECT_LT(epipolarTransferError(inducedBy(rig, kFront, 3.0), *F, probe), 0.5);
  EXPECT_LT(epipolarTransferError(inducedBy(rig, kSide, 2.5), *F, probe), 0.5);
  // A gross outlier is down-weighted.
  a.emplace_back(300, 200);
  b.emplace_back(50, 400);
  const auto Fo = refineFundamental(a, b, 0.3);
  ASSERT_TRUE(Fo);
  EXPECT_LT(epipolarTransferError(inducedBy(rig, kFront, 3.0), *Fo, probe), 0.5);
  EXPECT_FALSE(refineFundamental({a.begin(), a.begin() + 7}, {b.begin(), b.begin() + 7}, 0.3));
}

TEST(EpipolarCheck, InducedHomographyThroughPoints) {
  Rig rig;
  std::mt19937 rng(6);
  std::vector<cv::Point2d> a, b;
    rig.points(kSide, 2.5, 30, rng, a, b);
  const cv::Vec3d e2 = rig.K * rig.t;
  const auto H = fitInducedHomography(inducedBy(rig, kFront, 3.0), e2, a, b);
  ASSERT_TRUE(H);
  // It is the wall's homography (within the 0.3 px noise) and plane-induced.
  const cv::Matx33d truth = inducedBy(rig, kSide, 2.5);
  for (const cv::Point2d& p : std::vector<cv::Point2d>{{100, 100}, {320, 240}, {600, 400}})
    EXPECT_LT(transferError(*H, p, apply(truth, p)), 0.5);
  EXPECT_LT(skewSymmetryError(*H, rig.F()), 1e-9);
  // Weights are used (a zero weight ignores a gross outlier).
  a.emplace_back(300, 200);
  b.emplace_back(10, 10);
  std::vector<double> w(a.size(), 1.0);
  w.back() = 0.0;
  const auto Hw = fitInducedHomography(inducedBy(rig, kFront, 3.0), e2, a, b, w);
  ASSERT_TRUE(Hw);
  EXPECT_LT(transferError(*Hw, a[0], b[0]), 1.5);
  // Too few points, or collinear ones: nothing.
  EXPECT_FALSE(fitInducedHomography(inducedBy(rig, kFront, 3.0), e2, {a[0], a[1]}, {b[0], b[1]}));
  EXPECT_FALSE(fitInducedHomography(inducedBy(rig, kFront, 3.0), e2, {{0, 0}, {1, 1}, {2, 2}, {3, 3}},
                                    {{0, 0}, {1, 1}, {2, 2}, {3, 3}}));
}
