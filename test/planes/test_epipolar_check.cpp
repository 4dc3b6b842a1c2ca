#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <random>

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
