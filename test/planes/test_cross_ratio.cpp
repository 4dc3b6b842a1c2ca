// Five-point invariants: unchanged by any homography, changed off the plane.
#include <gtest/gtest.h>

#include <random>

#include "mono_plane_detection/planes/cross_ratio.h"
#include "mono_plane_detection/sim/synthetic_views.h"

using namespace mono_plane_detection;

namespace {

const std::array<cv::Point2d, 5> kFive{{{0, 0}, {100, 10}, {90, 120}, {-10, 80}, {20, 115}}};

std::array<cv::Point2d, 5> mapped(const cv::Matx33d& H, const std::array<cv::Point2d, 5>& p) {
  std::array<cv::Point2d, 5> out;
  for (int i = 0; i < 5; ++i) out[i] = transfer(H, p[i]);
  return out;
}

}  // namespace

TEST(CrossRatio, InvariantUnderRandomHomographies) {
  const auto base = fivePointInvariants(kFive);
  ASSERT_TRUE(base);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const cv::Matx33d H(1 + 0.3 * u(rng), 0.3 * u(rng), 200 * u(rng), 0.3 * u(rng),
                        1 + 0.3 * u(rng), 200 * u(rng), 1e-3 * u(rng), 1e-3 * u(rng), 1.0);
    const auto other = fivePointInvariants(mapped(H, kFive), 1e-3);
    if (!other) continue;  // a homography can squash a triple nearly flat
    ++checked;
    EXPECT_NEAR(other->i1, base->i1, 1e-6 * std::abs(base->i1));
    EXPECT_NEAR(other->i2, base->i2, 1e-6 * std::abs(base->i2));
    EXPECT_LT(invariantDistance(*base, *other), 1e-6);
  }
  EXPECT_GT(checked, 150);  // a few squashed triples, not all
}

TEST(CrossRatio, PointMovedOffThePlaneChangesThem) {
  const auto base = fivePointInvariants(kFive);
  auto moved = kFive;
  moved[4] += cv::Point2d(12, -7);  // parallax of a point off the plane
  const auto other = fivePointInvariants(moved);
  ASSERT_TRUE(base && other);
  EXPECT_GT(invariantDistance(*base, *other), 0.1);
}

TEST(CrossRatio, DegenerateGroupsRejected) {
  auto collinear = kFive;
  collinear[2] = {50, 5};  // on the line through points 0 and 1
  EXPECT_FALSE(fivePointInvariants(collinear));
  auto repeated = kFive;
  repeated[3] = repeated[0];
  EXPECT_FALSE(fivePointInvariants(repeated));
  auto infinite = kFive;
  infinite[1].x = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(fivePointInvariants(infinite));
  auto nan = kFive;
  nan[4].y = std::nan("");
  EXPECT_FALSE(fivePointInvariants(nan));
  auto tiny = kFive;  // scale does not matter: a tiny well-shaped group is fine
  for (auto& p : tiny) p *= 1e-3;
  EXPECT_TRUE(fivePointInvariants(tiny));
}

TEST(CrossRatio, TriangleShapeIsScaleFreeAndZeroWhenFlat) {
  EXPECT_NEAR(triangleShape({0, 0}, {1, 0}, {0.5, std::sqrt(3.0) / 2}), std::sqrt(3.0) / 2, 1e-12);
  EXPECT_NEAR(triangleShape({0, 0}, {1000, 0}, {500, 500 * std::sqrt(3.0)}), std::sqrt(3.0) / 2,
              1e-12);
  EXPECT_EQ(triangleShape({0, 0}, {1, 1}, {2, 2}), 0.0);
  EXPECT_EQ(triangleShape({3, 3}, {3, 3}, {3, 3}), 0.0);
  EXPECT_TRUE(wellSpread(kFive, 0.05));
  EXPECT_FALSE(wellSpread(kFive, 0.9));
}

TEST(CrossRatio, DistanceIsRelativeAndBounded) {
  EXPECT_NEAR(invariantDistance({1000, 2}, {1010, 2}), 10.0 / 1010, 1e-12);
  EXPECT_NEAR(invariantDistance({1, 2}, {1, 2.2}), 0.2 / 2.2, 1e-12);
  EXPECT_NEAR(invariantDistance({1, 2}, {-1, 2}), 2.0, 1e-12);  // opposite signs
  EXPECT_EQ(invariantDistance({0, 0}, {0, 0}), 0.0);
}

// One triple of wellSpread's test from its squared sides: the same verdict as
// triangleShape >= min_shape, and as wellSpread for five points.
TEST(CrossRatio, SpreadTripleIsTriangleShapeFromItsSides) {
  auto sides = [](const cv::Point2d& a, const cv::Point2d& b, const cv::Point2d& c,
                  double min_shape) {
    return spreadTriple(a, b, c, (a - b).dot(a - b), (b - c).dot(b - c), (a - c).dot(a - c),
                        min_shape);
  };
  const cv::Point2d a(0, 0), b(10, 0), c(5, 8), flat(5, 0.2);
  EXPECT_TRUE(sides(a, b, c, 0.05));
  EXPECT_FALSE(sides(a, b, flat, 0.05));  // shape 0.02
  EXPECT_TRUE(sides(a, b, flat, 0.01));
  for (double m : {0.01, 0.019, 0.021, 0.05}) EXPECT_EQ(sides(a, b, flat, m), triangleShape(a, b, flat) >= m);
  EXPECT_FALSE(sides(a, a, a, 0.05));  // repeated points
  EXPECT_TRUE(wellSpread({a, b, c, cv::Point2d(-3, 9), cv::Point2d(13, 10)}, 0.05));
  EXPECT_FALSE(wellSpread({a, b, c, cv::Point2d(-3, 9), flat}, 0.05));
}
