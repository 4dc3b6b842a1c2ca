#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "mono_plane_detection/planes/noise_scale.h"
#include "mono_plane_detection/sim/synthetic_two_view.h"

using namespace mono_plane_detection;

namespace {

// Transfer residuals of true inliers (Rayleigh(sigma): 2-D Gaussian per coordinate) and
// of outliers (uniform over a disc of radius 300 px).
std::vector<double> residuals(int inliers, int outliers, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> r;
  for (int i = 0; i < inliers; ++i) r.push_back(std::hypot(g(rng), g(rng)));
  for (int i = 0; i < outliers; ++i) r.push_back(300.0 * std::sqrt(u(rng)));
  return r;
}

}  // namespace

TEST(MsseScale, FindsTheInlierScaleAmongOutliers) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const NoiseScale s = msseScale(residuals(100, 200, 0.8, seed), 10, 0);
    EXPECT_NEAR(s.sigma_px, 0.8, 0.2) << seed;
    EXPECT_GE(s.inliers, 80) << seed;
    EXPECT_LE(s.inliers, 110) << seed;
  }
  EXPECT_EQ(msseScale({1.0, 2.0}, 8).inliers, 0);  // too few
  EXPECT_EQ(msseScale({NAN, INFINITY, 1.0}, 1, 0).inliers, 1);
}

TEST(MedianScale, IsTheRayleighScaleAndIgnoresFarResiduals) {
  const std::vector<double> r = residuals(400, 300, 1.5, 3);
  // From a start off by a factor of two either way.
  for (double start : {0.75, 3.0}) {
    const NoiseScale s = medianScale(r, start, 5.0);
    EXPECT_NEAR(s.sigma_px, 1.5, 0.2) << start;
  }
  EXPECT_EQ(medianScale(r, 0.0, 5.0).inliers, 0);
  EXPECT_EQ(medianScale({100.0}, 1.0, 5.0).inliers, 0);  // nothing under the cut
}

TEST(MedianScaleSquared, GivesTheScaleOfTheResidualsFromTheirSquares) {
  const std::vector<double> r = residuals(400, 300, 1.5, 4);
  std::vector<double> r2;
  for (double x : r) r2.push_back(x * x);
  r2.push_back(INFINITY);  // ignored, as in medianScale
  const NoiseScale s = medianScaleSquared(r2, 3.0, 5.0);
  EXPECT_NEAR(s.sigma_px, 1.5, 0.2);
  const NoiseScale t = medianScale(r, 3.0, 5.0);
  EXPECT_NEAR(s.sigma_px, t.sigma_px, 1e-9);
  EXPECT_EQ(s.inliers, t.inliers);
  EXPECT_NEAR(s.tail_ratio, t.tail_ratio, 1e-9);
  // Rayleigh: the 90th over the 50th percentile is sqrt(ln 10 / ln 2) = 1.82.
  EXPECT_NEAR(s.tail_ratio, 1.82, 0.2);
}

TEST(EstimateNoiseScale, RecoversTheNoiseOfASyntheticPair) {
  for (double noise : {0.3, 1.0}) {
    TwoViewSceneParams sp;
    sp.planes = 2;
    sp.noise_px = noise;
    sp.outlier_fraction = 0.4;
    const auto scene = makeTwoViewScene(sp);
    // A near-true and a wrong candidate: the estimate comes from the true plane.
    const cv::Matx33d wrong = scene.homographies[0] * cv::Matx33d(1, 0, 25, 0, 1, -10, 0, 0, 1);
    const NoiseScale s =
        estimateNoiseScale({wrong, scene.homographies[1]}, scene.view1, scene.view2);
    // Noise of sigma in both views: the transfer residual's scale is about sqrt(2) sigma.
    EXPECT_NEAR(s.sigma_px, std::sqrt(2.0) * noise, 0.35 * noise) << noise;
    EXPECT_GT(s.inliers, 20);
  }
  EXPECT_EQ(estimateNoiseScale({}, {}, {}).inliers, 0);
}

TEST(TransferResiduals, AreThePixelDistances) {
  const cv::Matx33d shift(1, 0, 3, 0, 1, 4, 0, 0, 1);
  const auto r = transferResiduals(shift, {{0, 0}, {10, 10}}, {{0, 0}, {13, 14}});
  ASSERT_EQ(r.size(), 2u);
  EXPECT_NEAR(r[0], 5.0, 1e-12);
  EXPECT_NEAR(r[1], 0.0, 1e-12);
}

// The bucket sort and selection give std::sort's order and nth_element's value on squared
// residuals: many equal values, exact zeros, tiny and huge values (beyond the buckets'
// reach), +infinity, and sizes below and above the plain-sort cut-off.
TEST(SortNonNegative, GivesTheSortedOrderAndTheKthValue) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> size(1, 700);
  for (int run = 0; run < 200; ++run) {
    std::vector<double> v = residuals(size(rng), size(rng) / 2, 0.5, run + 1);
    for (double& r : v) r *= r;
    if (run % 3 == 0) v.insert(v.end(), {0.0, 0.0, 1e-30, 1e12, 2.25, 2.25, 2.25});
    if (run % 5 == 0) v.push_back(std::numeric_limits<double>::infinity());
    std::shuffle(v.begin(), v.end(), rng);
    std::vector<double> expected = v, sorted = v;
    std::sort(expected.begin(), expected.end());
    sortNonNegative(sorted);
    ASSERT_EQ(sorted, expected) << run;
    for (size_t k : {size_t{0}, v.size() / 10, v.size() / 2, v.size() - 1}) {
      std::vector<double> w = v;
      ASSERT_EQ(kthNonNegative(w, k), expected[k]) << run << " k " << k;
    }
    std::vector<double> w = v;  // beyond the last: no such value
    ASSERT_EQ(kthNonNegative(w, v.size()), std::numeric_limits<double>::infinity()) << run;
  }
}
