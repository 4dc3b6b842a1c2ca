// Robust metric plane fits against known planes.
#include <gtest/gtest.h>

#include <random>

#include "mono_plane_detection/geometry/plane_fit.h"

using namespace mono_plane_detection;

namespace {

// Points on n . x = d (n unit) with noise, plus outliers off the plane.
std::vector<cv::Vec3d> planePoints(const cv::Vec3d& n, double d, int count, double noise,
                                   int outliers, unsigned seed = 3) {
  cv::Vec3d u, v;
  planeAxes(n, u, v);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> spread(-1.5, 1.5), off(0.3, 1.0);
  std::normal_distribution<double> gauss(0, noise);
  std::vector<cv::Vec3d> pts;
  for (int i = 0; i < count; ++i)
    pts.push_back(d * n + spread(rng) * u + spread(rng) * v + gauss(rng) * n);
  for (int i = 0; i < outliers; ++i)
    pts.push_back(d * n + spread(rng) * u + spread(rng) * v + off(rng) * n);
  return pts;
}

}  // namespace

TEST(PlaneFit, RecoversANoisyPlaneDespiteOutliers) {
  cv::Vec3d n(0.2, -0.9, 0.3);
  n /= cv::norm(n);
  const auto pts = planePoints(n, 1.7, 80, 0.01, 25);
  const PlaneFit fit = fitPlane(pts, 0.05);
  ASSERT_TRUE(fit.ok);
  const double sign = fit.normal.dot(n) > 0 ? 1 : -1;
  EXPECT_LT(normalAngleDeg(sign * fit.normal, n), 1.0);
  EXPECT_NEAR(sign * fit.distance, 1.7, 0.01);
  EXPECT_EQ(fit.inliers.size(), 80u);  // none of the outliers (>= 0.3 m off)
  EXPECT_NEAR(fit.rms_m, 0.01, 0.004);
}

TEST(PlaneFit, RefusesTooFewOrCollinearPoints) {
  EXPECT_FALSE(fitPlane({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, 0.05).ok);  // below min_points
  std::vector<cv::Vec3d> line;
  for (int i = 0; i < 20; ++i) line.push_back({0.1 * i, 0.2 * i, 1.0});
  EXPECT_FALSE(fitPlane(line, 0.05).ok);
}

TEST(PlaneFit, OrientTowardsFlipsToTheViewpointSide) {
  PlaneFit p;
  p.ok = true;
  p.normal = {0, 0, 1};
  p.distance = 2;  // z = 2
  orientTowards(p, {0, 0, 0});
  EXPECT_EQ(p.normal, cv::Vec3d(0, 0, -1));
  EXPECT_EQ(p.distance, -2);
  orientTowards(p, {0, 0, 1});  // already facing it
  EXPECT_EQ(p.normal, cv::Vec3d(0, 0, -1));
}

TEST(PlaneFit, AxesAreOrthonormalAndRightHanded) {
  for (const cv::Vec3d& n : {cv::Vec3d(0, 0, 1), cv::Vec3d(1, 0, 0), cv::Vec3d(0.6, 0.8, 0)}) {
    cv::Vec3d u, v;
    planeAxes(n, u, v);
    EXPECT_NEAR(cv::norm(u), 1, 1e-12);
    EXPECT_NEAR(cv::norm(v), 1, 1e-12);
    EXPECT_NEAR(u.dot(n), 0, 1e-12);
    EXPECT_LT(cv::norm(u.cross(v) - n), 1e-12);
  }
}

TEST(PlaneFit, PolygonIsTheHullOnThePlane) {
  // A grid on z = 1 (normal +z): the hull is its 4 corners, counter-clockwise from +z.
  std::vector<cv::Vec3d> pts;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j) pts.push_back({0.25 * i, 0.5 * j, 1.0});
  const auto polygon = planePolygon({0, 0, 1}, 1.0, pts);
  ASSERT_EQ(polygon.size(), 4u);
  double area = 0;  // shoelace in (x, y): positive = counter-clockwise
  for (size_t k = 0; k < polygon.size(); ++k) {
    const auto& a = polygon[k];
    const auto& b = polygon[(k + 1) % polygon.size()];
    area += a[0] * b[1] - b[0] * a[1];
    EXPECT_NEAR(a[2], 1.0, 1e-9);
  }
  EXPECT_NEAR(area / 2, 2.0, 1e-6);
  EXPECT_TRUE(planePolygon({0, 0, 1}, 1.0, {{0, 0, 1}, {1, 0, 1}}).empty());
}

TEST(PlaneFit, NormalAngle) {
  EXPECT_NEAR(normalAngleDeg({1, 0, 0}, {0, 1, 0}), 90, 1e-9);
  EXPECT_NEAR(normalAngleDeg({1, 0, 0}, {-2, 0, 0}), 180, 1e-9);
  EXPECT_NEAR(normalAngleDeg({1, 1, 0}, {1, 0, 0}), 45, 1e-9);
}
