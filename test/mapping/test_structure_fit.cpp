// A plane held at right angles to / parallel to better-known planes while its points allow.
#include <gtest/gtest.h>

#include <random>

#include "mono_plane_detection/geometry/plane_fit.h"
#include "mono_plane_detection/mapping/structure_fit.h"

using namespace mono_plane_detection;

namespace {

const double kDeg = CV_PI / 180;

// Points on the plane with normal n through the origin: a strip `length` x `width` m, its
// long axis along `along` (projected into the plane), noise `noise` m across it.
std::vector<cv::Vec3d> stripAlong(const cv::Vec3d& n, const cv::Vec3d& along, double length,
                                  double width, int count, double noise, unsigned seed) {
  const cv::Vec3d u = cv::normalize(along - along.dot(n) * n), v = n.cross(u);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> a(-length / 2, length / 2), b(-width / 2, width / 2);
  std::normal_distribution<double> off(0, noise);
  std::vector<cv::Vec3d> points;
  for (int i = 0; i < count; ++i) points.push_back(a(rng) * u + b(rng) * v + off(rng) * n);
  return points;
}

// The same along the first in-plane axis of planeAxes(n).
std::vector<cv::Vec3d> strip(const cv::Vec3d& n, double length, double width, int count,
                             double noise, unsigned seed) {
  cv::Vec3d u, v;
  planeAxes(n, u, v);
  return stripAlong(n, u, length, width, count, noise, seed);
}

// (fitPlane refuses strips narrower than its spread check: the eigenvector here.)
cv::Vec3d leastSquaresNormal(const std::vector<cv::Vec3d>& points, const cv::Vec3d& side) {
  cv::Vec3d centroid(0, 0, 0);
  for (const auto& p : points) centroid += p;
  centroid *= 1.0 / static_cast<double>(points.size());
  cv::Matx33d scatter = cv::Matx33d::zeros();
  for (const auto& p : points) scatter += (p - centroid) * (p - centroid).t();
  cv::Mat values, vectors;
  cv::eigen(cv::Mat(scatter), values, vectors);
  const cv::Vec3d n(vectors.at<double>(2, 0), vectors.at<double>(2, 1), vectors.at<double>(2, 2));
  return n.dot(side) < 0 ? -n : n;
}

cv::Vec3d turned(const cv::Vec3d& n, const cv::Vec3d& axis, double deg) {
  cv::Matx33d r;
  cv::Rodrigues(cv::Vec3d(cv::normalize(axis) * (deg * kDeg)), r);
  return r * n;
}

const cv::Vec3d kUp(0, 0, 1), kFront(1, 0, 0), kLeft(0, 1, 0);

}  // namespace

// A floor seen as a narrow strip along a wall (2 m x 0.2 m, 1 cm noise): its points leave
// it free to roll about the strip by degrees; held at right angles to two well-known
// walls it is as good as they are. Over 20 draws.
TEST(StructureFit, AStripOfFloorIsHeldAtRightAnglesToTheWalls) {
  double free_sum = 0, held_sum = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const auto points = strip(kUp, 2.0, 0.2, 30, 0.01, seed);
    const cv::Vec3d free = leastSquaresNormal(points, kUp);
    const std::vector<ReferencePlane> walls = {{turned(kFront, kLeft, 0.1), 0.1},
                                               {turned(kLeft, kFront, -0.1), 0.1}};
    const StructuredPlane held = structuredPlane(points, free, walls, 3.0, 0.005);
    EXPECT_EQ(held.perpendicular, 2) << seed;
    EXPECT_EQ(held.parallel, 0);
    EXPECT_LT(normalAngleDeg(held.normal, kUp), 0.2) << seed;
    EXPECT_NEAR(held.distance, 0.0, 0.01);
    free_sum += normalAngleDeg(free, kUp);
    held_sum += normalAngleDeg(held.normal, kUp);
  }
  EXPECT_GT(free_sum / 20, 0.5);  // the strip alone: this test asks something
  EXPECT_LT(held_sum / 20, 0.2);
}

// One wall known, a floor strip along it: the strip keeps the tilt its length fixes and
// is turned across it to the right angle.
TEST(StructureFit, OneRightAngleLeavesTheOtherTiltToThePoints) {
  const cv::Vec3d truth = turned(kUp, kLeft, 1.0);  // pitched 1 deg along the strip (x)
  const auto points = stripAlong(truth, kFront, 2.0, 0.2, 30, 0.01, 3);
  const cv::Vec3d free = leastSquaresNormal(points, kUp);
  const StructuredPlane held = structuredPlane(points, free, {{kLeft, 0.05}}, 3.0, 0.005);
  EXPECT_EQ(held.perpendicular, 1);
  EXPECT_LT(std::abs(held.normal.dot(kLeft)), 0.2 * std::abs(free.dot(kLeft)));
  EXPECT_GT(normalAngleDeg(free, truth), 0.5);  // the strip alone rolls
  EXPECT_LT(normalAngleDeg(held.normal, truth), 0.3);
  EXPECT_GT(normalAngleDeg(held.normal, kUp), 0.7);  // the 1 deg pitch is its own
}

// The pull follows the reference's sigma: a wall tilted 1 deg and known to 0.05 deg turns
// a floor strip along it by nearly that; the same wall known to 3 deg (worse than the
// strip) hardly.
TEST(StructureFit, AReferenceIsTrustedAsFarAsItsSigma) {
  const auto points = stripAlong(kUp, kFront, 2.0, 0.2, 30, 0.004, 9);
  const cv::Vec3d free = leastSquaresNormal(points, kUp);
  const cv::Vec3d wall = turned(kLeft, kFront, 1.0);  // leaning 1 deg across the strip
  const StructuredPlane sure = structuredPlane(points, free, {{wall, 0.05}}, 3.0, 0.001);
  const StructuredPlane loose = structuredPlane(points, free, {{wall, 3.0}}, 3.0, 0.001);
  ASSERT_EQ(sure.perpendicular, 1);
  ASSERT_EQ(loose.perpendicular, 1);
  EXPECT_GT(normalAngleDeg(sure.normal, free), 0.7);
  EXPECT_LT(normalAngleDeg(loose.normal, free), 0.1);
}

// A ramp 8 deg from level, its points spread 1 m x 1 m: their residuals deny the right
// angle to a wall, and the plane keeps its own normal.
TEST(StructureFit, ARampsPointsDenyTheRightAngle) {
  const cv::Vec3d ramp = turned(kUp, kLeft, 8.0);
  const auto points = strip(ramp, 1.0, 1.0, 60, 0.01, 5);
  const cv::Vec3d free = leastSquaresNormal(points, kUp);
  const StructuredPlane held = structuredPlane(points, free, {{kFront, 0.1}}, 3.0, 0.005);
  EXPECT_EQ(held.perpendicular, 0);
  EXPECT_EQ(held.parallel, 0);
  EXPECT_LT(normalAngleDeg(held.normal, free), 1e-9);
}

// The same ramp's points spread and nearly exact (its normal known to about 0.03 deg)
// against a loose reference (0.5 deg) 10 deg from its right angle: the points' residuals
// hardly notice the fused normal, so the relation passes, and moves the plane only by the
// reference's share, 10 deg x 0.03^2 / (0.03^2 + 0.5^2), about 0.04 deg.
TEST(StructureFit, ALooseReferenceMovesAWellKnownPlaneByItsShareOnly) {
  const cv::Vec3d ramp = turned(kUp, kLeft, 10.0);
  const auto points = strip(ramp, 1.0, 1.0, 60, 0.001, 14);
  const cv::Vec3d free = leastSquaresNormal(points, kUp);
  const StructuredPlane held = structuredPlane(points, free, {{kFront, 0.5}}, 3.0, 0.0005);
  EXPECT_LT(normalAngleDeg(held.normal, free), 0.1);
  EXPECT_LT(normalAngleDeg(held.normal, ramp), 0.1);
}

// A ramp 4 deg from level seen as a strip up its slope, between a front wall it rises
// towards and a side wall along it: its 2 m length fixes the slope, so its points deny
// the right angle to the front wall (a turn about the axis they fix), but its 0.2 m width
// leaves the roll to the side wall's right angle, which is taken without the other.
TEST(StructureFit, ARelationThePointsDenyIsLeftOutWithoutTheOthers) {
  const cv::Vec3d ramp = turned(kUp, kLeft, 4.0);  // rising along x
  const auto points = stripAlong(ramp, kFront, 2.0, 0.2, 30, 0.01, 4);
  const cv::Vec3d free = leastSquaresNormal(points, kUp);
  const StructuredPlane alone = structuredPlane(points, free, {{kFront, 0.05}}, 3.0, 0.005);
  EXPECT_EQ(alone.perpendicular, 0);
  EXPECT_LT(normalAngleDeg(alone.normal, free), 1e-9);
  const StructuredPlane held =
      structuredPlane(points, free, {{kFront, 0.05}, {kLeft, 0.05}}, 3.0, 0.005);
  EXPECT_EQ(held.perpendicular, 1);  // the side wall's
  EXPECT_NEAR(held.normal.dot(kFront), std::sin(4.0 * kDeg), 0.005);  // its slope kept
  EXPECT_LT(std::abs(held.normal.dot(kLeft)), 0.2 * std::abs(free.dot(kLeft)));
}

// Of a reference's two relations the nearer is asked: a loose strip (1 m x 0.3 m, 5 cm
// noise: free to turn about its long axis by about 6 deg) 15 deg from a wall's parallel is
// held parallel to it, not at right angles (75 deg away).
TEST(StructureFit, TheNearerRelationIsAsked) {
  const cv::Vec3d tilted = turned(kFront, kUp, 15.0);
  const auto points = stripAlong(tilted, kUp, 1.0, 0.3, 30, 0.05, 11);
  const cv::Vec3d free = leastSquaresNormal(points, tilted);
  const StructuredPlane held = structuredPlane(points, free, {{kFront, 0.05}}, 3.0, 0.005);
  EXPECT_EQ(held.perpendicular, 0);
  EXPECT_EQ(held.parallel, 1);
  EXPECT_LT(normalAngleDeg(held.normal, kFront), 0.5);
}

// A shelf front (a strip 0.15 m high) parallel to the wall behind it takes the wall's
// normal; its distance stays its own.
TEST(StructureFit, AParallelStripTakesTheBetterKnownNormal) {
  double free_sum = 0, held_sum = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    auto points = strip(kFront, 1.5, 0.15, 25, 0.01, 100 + seed);
    for (auto& p : points) p += 0.3 * kFront;  // 0.3 m in front of the wall
    const cv::Vec3d free = leastSquaresNormal(points, kFront);
    const StructuredPlane held = structuredPlane(points, free, {{kFront, 0.05}}, 3.0, 0.005);
    EXPECT_EQ(held.parallel, 1) << seed;
    EXPECT_LT(normalAngleDeg(held.normal, kFront), 0.1) << seed;
    EXPECT_NEAR(held.distance, 0.3, 0.01);
    free_sum += normalAngleDeg(free, kFront);
    held_sum += normalAngleDeg(held.normal, kFront);
  }
  EXPECT_GT(free_sum / 20, 1.0);
  EXPECT_LT(held_sum / 20, 0.05);
}

// Two walls at right angles to the plane that are (nearly) parallel to each other are both
// taken: each adds its information across the same axis, the normal stays well defined.
TEST(StructureFit, NearlyParallelReferencesAreFusedNotDegenerate) {
  const auto points = strip(kUp, 2.0, 0.2, 30, 0.01, 7);
  const cv::Vec3d free = leastSquaresNormal(points, kUp);
  const StructuredPlane held = structuredPlane(
      points, free, {{kFront, 0.05}, {turned(kFront, kUp, 2.0), 0.1}}, 3.0, 0.005);
  EXPECT_EQ(held.perpendicular, 2);
  EXPECT_NEAR(cv::norm(held.normal), 1.0, 1e-12);
  EXPECT_LT(std::abs(held.normal.dot(kFront)), 0.2 * std::abs(free.dot(kFront)));
}

// Defensive: a reference normal not of unit length counts as its direction; one of zero
// length or a NaN sigma is skipped; exact points without a floor give no NaN.
TEST(StructureFit, OddReferencesAreHandled) {
  const auto points = strip(kUp, 2.0, 0.2, 30, 0.01, 12);
  const cv::Vec3d free = leastSquaresNormal(points, kUp);
  const StructuredPlane unit = structuredPlane(points, free, {{kFront, 0.1}}, 3.0, 0.005);
  const StructuredPlane scaled = structuredPlane(points, free, {{5.0 * kFront, 0.1}}, 3.0, 0.005);
  EXPECT_EQ(unit.perpendicular, 1);
  EXPECT_LT(normalAngleDeg(unit.normal, scaled.normal), 1e-9);
  const StructuredPlane skipped = structuredPlane(
      points, free, {{cv::Vec3d(0, 0, 0), 0.1}, {kLeft, std::nan("")}}, 3.0, 0.005);
  EXPECT_EQ(skipped.perpendicular + skipped.parallel, 0);
  EXPECT_LT(normalAngleDeg(skipped.normal, free), 1e-9);
  const auto exact = strip(kUp, 2.0, 0.2, 30, 0.0, 13);
  const StructuredPlane held = structuredPlane(exact, kUp, {{kFront, 0.1}}, 3.0, 0.0);
  EXPECT_TRUE(std::isfinite(held.normal[0]) && std::isfinite(held.distance));
}

// Off (sigmas 0), no reference, or too few points: the free plane as given.
TEST(StructureFit, OffOrNothingToHoldToGivesTheFreePlane) {
  const auto points = strip(kUp, 2.0, 0.2, 30, 0.01, 8);
  const cv::Vec3d free = leastSquaresNormal(points, kUp);
  for (const auto& [sigmas, refs] :
       {std::pair<double, std::vector<ReferencePlane>>{0.0, {{kFront, 0.05}}},
        {3.0, std::vector<ReferencePlane>{}}}) {
    const StructuredPlane held = structuredPlane(points, free, refs, sigmas, 0.005);
    EXPECT_EQ(held.normal, free);
    EXPECT_EQ(held.perpendicular + held.parallel, 0);
  }
  const std::vector<cv::Vec3d> three(points.begin(), points.begin() + 3);
  EXPECT_EQ(structuredPlane(three, free, {{kFront, 0.05}}, 3.0, 0.005).normal, free);
  EXPECT_EQ(structuredPlane({}, free, {{kFront, 0.05}}, 3.0, 0.005).normal, free);
}
