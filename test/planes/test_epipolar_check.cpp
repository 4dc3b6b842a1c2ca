#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/version.hpp>
#include <random>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/geometry/opencv_usac.h"
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
  // `each` points on the floor 1.2 m below, then as many on a wall 3 m ahead.
  void floorAndWall(int each, std::mt19937& rng, std::vector<cv::Point2d>& a,
                    std::vector<cv::Point2d>& b) const {
    points({0, -1, 0}, -1.2, each, rng, a, b);
    points(cv::normalize(cv::Vec3d(0.2, 0, -1)), -3.0, each, rng, a, b);
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
  rig.floorAndWall(80, rng, a, b);
  const auto F = estimateFundamental(a, b, 1.0);
  ASSERT_TRUE(F);
  // The true plane homography is compatible with the estimate within about a pixel.
  const std::vector<cv::Point2d> probe(a.begin(), a.begin() + 40);
  EXPECT_LT(epipolarTransferError(rig.H({0, -1, 0}, -1.2), *F, probe), 1.5);
  // Too few points: nothing.
  EXPECT_FALSE(estimateFundamental({a.begin(), a.begin() + 10}, {b.begin(), b.begin() + 10}, 1.0));
}

// Many points, given plane after plane as the segmentation does: F comes from a stride
// through the list (each plane keeps its share), the inlier share from every point.
TEST(EpipolarCheck, EstimatesFFromManyPointsPlaneAfterPlane) {
  Rig rig;
  std::mt19937 rng(11);
  const cv::Vec3d floor(0, -1, 0), wall = cv::normalize(cv::Vec3d(0.2, 0, -1));
  std::vector<cv::Point2d> a, b;
  rig.points(floor, -1.2, 700, rng, a, b);  // first, 70 % of the list
  rig.points(wall, -3.0, 300, rng, a, b);
  const auto F = estimateFundamental(a, b, 1.2);
  ASSERT_TRUE(F);
  // The wall (last 30 %) fixes F too: a sample of the list's head would leave a family of
  // F through the floor's points, off the wall's homography by pixels.
  const std::vector<cv::Point2d> probe{{100, 100}, {500, 80}, {320, 240}, {600, 400}, {50, 420}};
  const double wall_px = epipolarTransferError(rig.H(wall, -3.0), *F, probe);
  const double floor_px = epipolarTransferError(rig.H(floor, -1.2), *F, probe);
  int near = 0;
  for (size_t i = 0; i < a.size(); ++i) near += epipolarLineDistance(*F, a[i], b[i]) < 1.2;
  EXPECT_LT(wall_px, 2.0);
  EXPECT_LT(floor_px, 2.0);
  EXPECT_GT(near, 700);
  // F polished on its inliers (USAC does; the fallback for OpenCV < 4.5 by
  // refineFundamental: its RANSAC's 7-point F alone was 1.4-1.6 px off, 767 points near
  // their lines here). Both paths: build with -DMPD_FORCE_PLAIN_RANSAC for the fallback.
  EXPECT_LT(wall_px, 0.5);
  EXPECT_LT(floor_px, 0.5);
  EXPECT_GT(near, 950);
}

TEST(EpipolarCheck, InlierShareCountedOverEveryPoint) {
  Rig rig;
  std::mt19937 rng(12);
  std::vector<cv::Point2d> a, b;
  rig.floorAndWall(500, rng, a, b);
  // Every point but the stride's 256 made a gross mismatch (anywhere in the image): the
  // stride alone would see only inliers.
  std::vector<char> kept(a.size(), 0);
  for (size_t k = 0; k < 256; ++k) kept[k * a.size() / 256] = 1;
  std::uniform_real_distribution<double> x(0.0, 640.0), y(0.0, 480.0);
  for (size_t i = 0; i < a.size(); ++i)
    if (!kept[i]) b[i] = {x(rng), y(rng)};
  // A quarter of the points on their lines: below a share of 0.3, nothing.
  EXPECT_FALSE(estimateFundamental(a, b, 1.0, 0.3));
#if MPD_HAVE_USAC
  // (USAC on the stride; the fallback's RANSAC on all points would need more than its
  // 1000 iterations at 74 % outliers.)
  EXPECT_TRUE(estimateFundamental(a, b, 1.0, 0.2));
#endif
}

// A genuine plane's distances to its epipolar lines are |N(0, s)|: its score stays within
// chance (one in a thousand beyond 3.09); a cluster matched 2.5 scales off its lines (a
// period of repeated texture) scores far beyond, the fewer its points the less.
TEST(EpipolarCheck, OffsetScoreInStandardErrorsOfTheMedian) {
  std::mt19937 rng(21);
  const double s = 0.2;
  std::normal_distribution<double> g(0.0, s);
  auto distances = [&](int n, double offset) {
    std::vector<double> d;
    for (int i = 0; i < n; ++i) d.push_back(std::abs(offset + g(rng)));
    return d;
  };
  int beyond = 0;
  for (int k = 0; k < 1000; ++k)
    beyond += epipolarOffsetScore(distances(20 + k % 200, 0.0), s) > 3.09;
  EXPECT_LE(beyond, 5);  // the normal's median error is wider than a half-normal's: fewer
  // Heavier tails than the normal model's (Laplace distances, their scale s from their
  // median as epipolarScale takes it): still within chance, one in a thousand at most
  // (measured 0 of 2000). With the normal model's own error of the median (0.79 s /
  // sqrt(n) instead of the widened 1.25) about 0.6 % would be beyond: this fails then.
  std::exponential_distribution<double> laplace(1.0);
  const double laplace_s = std::log(2.0) / 0.6745;  // |Laplace(0, 1)|'s median / 0.6745
  std::mt19937 laplace_rng(22);
  int laplace_beyond = 0;
  for (int k = 0; k < 2000; ++k) {
    std::vector<double> d;
    for (int i = 0; i < 20 + k % 200; ++i) d.push_back(laplace(laplace_rng));
    laplace_beyond += epipolarOffsetScore(d, laplace_s) > 3.09;
  }
  EXPECT_LE(laplace_beyond, 2);
  for (int k = 0; k < 20; ++k) {
    EXPECT_GT(epipolarOffsetScore(distances(17, 2.5 * s), s), 4.0);
    EXPECT_GT(epipolarOffsetScore(distances(100, 2.5 * s), s), 10.0);
  }
  // The formula: median 0.6745 s scores 0; one standard error above, 1.
  EXPECT_NEAR(epipolarOffsetScore(std::vector<double>(25, 0.6745 * s), s), 0.0, 1e-9);
  EXPECT_NEAR(epipolarOffsetScore(std::vector<double>(25, (0.6745 + 1.2533 / 5) * s), s), 1.0,
              1e-3);
  EXPECT_TRUE(std::isinf(epipolarOffsetScore({}, s)));
  EXPECT_TRUE(std::isinf(epipolarOffsetScore({1.0, 2.0}, 0.0)));
  // The scale back from the distances' median.
  EXPECT_NEAR(epipolarScale(distances(4000, 0.0)), s, 0.02 * s);
  EXPECT_EQ(epipolarScale({}), 0.0);
}

TEST(EpipolarCheck, OffsetThresholdForSeveralPlanes) {
  EXPECT_NEAR(epipolarOffsetThreshold(1), 3.090, 0.002);
  EXPECT_NEAR(epipolarOffsetThreshold(2), 3.291, 0.002);
  EXPECT_NEAR(epipolarOffsetThreshold(3), 3.403, 0.002);
  EXPECT_NEAR(epipolarOffsetThreshold(0), 3.090, 0.002);
  EXPECT_GT(epipolarOffsetThreshold(10), epipolarOffsetThreshold(5));
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

namespace {
// Points of the plane n.X = d seen at view-1 pixels drawn in a rectangle, both views with
// pixel noise; `bend` adds a smooth error to view 2 (a lens model's residual: no
// homography F induces follows it).
void piece(const Rig& rig, const cv::Vec3d& n, double d, const cv::Rect2d& where, int count,
           double noise_px, double bend_px, std::mt19937& rng, std::vector<cv::Point2d>& a,
           std::vector<cv::Point2d>& b) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, noise_px);
  for (int i = 0; i < count; ++i) {
    const double s = u(rng);
    const cv::Point2d x1(where.x + s * where.width, where.y + u(rng) * where.height);
    const cv::Vec3d ray = rig.K.inv() * cv::Vec3d(x1.x, x1.y, 1.0);
    const cv::Vec3d X = ray * (d / n.dot(ray));
    const cv::Vec3d x2 = rig.K * (rig.R * X + rig.t);
    a.emplace_back(x1.x + g(rng), x1.y + g(rng));
    b.emplace_back(x2[0] / x2[2] + g(rng), x2[1] / x2[2] + bend_px * std::sin(CV_PI * s) + g(rng));
  }
}

// The segmentation's criterion in miniature (planes/homography_voting.cpp): a Gaussian
// cost in the plane's own scale (median-based, between 1 and 4 pair scales), truncated at
// 8 scales; a label cost of 24 ln N; points to their cheapest plane.
struct MiniCriterion {
  const std::vector<cv::Point2d>& a;
  const std::vector<cv::Point2d>& b;
  double sigma;
  double cost(const HomographyPlane& p, int i) const {
    const double r = transferError(p.H, a[i], b[i]);
    if (!(r < p.threshold_px)) return 64.0;
    const double u = r / p.noise_px;
    return std::min(u * u + 4.0 * std::log(p.noise_px / sigma), 64.0);
  }
  PlaneCriterion make() const {
    PlaneCriterion c;
    c.outlier_cost = 64.0;
    c.label_cost = 24.0 * std::log(static_cast<double>(a.size()));
    c.costs = [this](const HomographyPlane& p, const std::vector<int>& idx) {
      std::vector<double> out;
      for (int i : idx) out.push_back(cost(p, i));
      return out;
    };
    c.measure = [this](HomographyPlane& p, const std::vector<int>& idx) {
      std::vector<double> r;
      for (int i : idx) r.push_back(transferError(p.H, a[i], b[i]));
      std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
      p.noise_px = std::clamp(r[r.size() / 2] / 1.1774, sigma, 4.0 * sigma);  // Rayleigh median
      p.threshold_px = 8.0 * p.noise_px;
    };
    c.assign = [this](std::vector<HomographyPlane>& planes) {
      for (HomographyPlane& p : planes) p.inliers.clear();
      for (size_t i = 0; i < a.size(); ++i) {
        double best = 64.0;
        HomographyPlane* to = nullptr;
        for (HomographyPlane& p : planes) {
          const double e = cost(p, static_cast<int>(i));
          if (e < best) {
            best = e;
            to = &p;
          }
        }
        if (to) to->inliers.push_back(static_cast<int>(i));
      }
    };
    return c;
  }
};

// The free homography through points [begin, end), with its scale.
HomographyPlane freePlane(const std::vector<cv::Point2d>& a, const std::vector<cv::Point2d>& b,
                          int begin, int end, const PlaneCriterion& c) {
  HomographyPlane p;
  for (int i = begin; i < end; ++i) p.inliers.push_back(i);
  p.H = *fitHomography({a.begin() + begin, a.begin() + end}, {b.begin() + begin, b.begin() + end});
  c.measure(p, p.inliers);
  return p;
}

// F's epipole in view 2 and [e2]x F.
void inducedBasis(const Rig& rig, cv::Matx33d& H1, cv::Vec3d& e2) {
  e2 = rig.K * rig.t;
  const cv::Matx33d ex(0, -e2[2], e2[1], e2[2], 0, -e2[0], -e2[1], e2[0], 0);
  H1 = ex * rig.F();
}
}  // namespace

TEST(EpipolarCheck, RobustInducedFitThroughPiecesOfDifferentNoise) {
  Rig rig;
  std::mt19937 rng(11);
  const cv::Vec3d floor(0, -1, 0);
  std::vector<cv::Point2d> a, b;
  piece(rig, floor, -1.2, {100, 330, 440, 140}, 120, 0.2, 0.0, rng, a, b);
  piece(rig, floor, -1.2, {60, 300, 240, 12}, 40, 1.0, 0.0, rng, a, b);
  // A fifth of the second piece's matches gross outliers.
  for (int i = 120; i < 128; ++i) b[i] += cv::Point2d(9.0, -7.0);
  std::vector<double> scale(a.size(), 0.2), start(a.size(), 0.0);
  for (size_t i = 120; i < a.size(); ++i) scale[i] = 1.0;
  cv::Matx33d H1;
  cv::Vec3d e2;
  inducedBasis(rig, H1, e2);
  const auto H = fitInducedRobust(H1, e2, a, b, scale, start);
  ASSERT_TRUE(H);
  const cv::Matx33d truth = inducedBy(rig, floor, -1.2);
  for (const cv::Point2d& p : std::vector<cv::Point2d>{{60, 300}, {300, 400}, {540, 470}})
    EXPECT_LT(transferError(*H, p, apply(truth, p)), 0.3) << p;
  EXPECT_LT(skewSymmetryError(*H, rig.F()), 1e-9);
  // Sizes that do not match: nothing.
  EXPECT_FALSE(fitInducedRobust(H1, e2, a, b, {0.2}, start));
}

TEST(EpipolarCheck, MergesPiecesOfOnePlaneOnly) {
  Rig rig;
  const cv::Vec3d floor(0, -1, 0);
  cv::Matx33d H1;
  cv::Vec3d e2;
  inducedBasis(rig, H1, e2);
  // The floor, a strip of it at the image's edge where the lens model is poorer (its
  // matches bent by up to 1 px), and a wall. Then the same strip 15 % farther than the
  // floor (another plane): not merged.
  for (const double strip_d : {-1.2, -1.2 * 1.15}) {
    for (unsigned seed = 1; seed <= 10; ++seed) {
      std::mt19937 rng(seed);
      std::vector<cv::Point2d> a, b;
      piece(rig, floor, -1.2, {150, 330, 440, 140}, 150, 0.2, 0.0, rng, a, b);
      piece(rig, floor, strip_d, {20, 290, 240, 14}, 150, 0.15, 1.0, rng, a, b);
      piece(rig, kFront, 3.0, {100, 40, 440, 160}, 100, 0.2, 0.0, rng, a, b);
      const MiniCriterion mini{a, b, 0.2};
      const PlaneCriterion c = mini.make();
      std::vector<HomographyPlane> planes{freePlane(a, b, 0, 150, c), freePlane(a, b, 150, 300, c),
                                          freePlane(a, b, 300, 400, c)};
      const bool same_plane = strip_d == -1.2;
      const int merges = mergeInducedPieces(planes, H1, e2, a, b, c);
      EXPECT_EQ(merges, same_plane ? 1 : 0) << "seed " << seed << ", strip at " << strip_d;
      ASSERT_EQ(planes.size(), same_plane ? 2u : 3u);
      // The floor's plane holds its points (0-149) and the strip's (150-299, when on it),
      // its homography the one the floor induces; the wall (300-399) is left alone.
      const int floor_end = same_plane ? 300 : 150;
      size_t floor_points = 0, wall_points = 0;
      for (const HomographyPlane& p : planes) {
        size_t on_floor = 0, on_wall = 0;
        for (int i : p.inliers) {
          if (i < floor_end) ++on_floor;
          if (i >= 300) ++on_wall;
        }
        if (on_floor > on_wall) {
          if (on_floor > floor_points) floor_points = on_floor;
          if (same_plane) {
            EXPECT_LT(skewSymmetryError(p.H, rig.F()), 1e-9);
            EXPECT_LT(
                transferError(p.H, {100, 297}, apply(inducedBy(rig, floor, -1.2), {100, 297})),
                0.5);
          }
        } else {
          wall_points = std::max(wall_points, on_wall);
        }
      }
      EXPECT_GE(floor_points, same_plane ? 290u : 145u) << "seed " << seed;
      EXPECT_GE(wall_points, 97u) << "seed " << seed;
    }
  }
}
