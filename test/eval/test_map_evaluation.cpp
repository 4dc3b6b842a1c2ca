// Judging maps against the truth: truth planes, image shares, matching.
#include <gtest/gtest.h>

#include <cmath>

#include "mono_plane_detection/eval/map_evaluation.h"
#include "mono_plane_detection/geometry/plane_fit.h"

using namespace mono_plane_detection;

TEST(MapEvaluation, TruthPlanesAreInTheTargetFrame) {
  const IndoorScene scene = makeRoom(RoomParams());
  const auto truth = truthPlanes(scene);
  ASSERT_EQ(truth.size(), scene.planes.size());
  int checked = 0;
  for (const TruthPlane& t : truth) {
    checked += t.name == "front_wall" || t.name == "floor";
    if (t.name == "front_wall") {  // the target's wall: map z, through the origin
      EXPECT_LT(normalAngleDeg(t.normal, {0, 0, 1}), 1e-6);
      EXPECT_NEAR(t.distance, 0, 1e-9);
    }
    if (t.name == "floor") {  // map y is up on a wall target: floor 0.8 m below its centre
      EXPECT_LT(normalAngleDeg(t.normal, {0, 1, 0}), 1e-6);
      EXPECT_NEAR(t.distance, -0.8, 1e-9);
    }
  }
  EXPECT_EQ(checked, 2);
}

TEST(MapEvaluation, ImageSharesAtTheStart) {
  const IndoorScene scene = makeRoom(RoomParams());
  TrajectoryParams tp;
  const auto shares = imageShares(scene, CameraModel(), trajectoryPose(tp, 0), 8);
  double sum = 0;
  for (double s : shares) sum += s;
  EXPECT_NEAR(sum, 1.0, 1e-9);            // a closed room: every ray hits a plane
  EXPECT_GT(shares[0] + shares[1], 0.9);  // floor + front wall fill the first view
  for (size_t i = 2; i < shares.size(); ++i) EXPECT_LT(shares[i], 0.1);
}

TEST(MapEvaluation, MatchesMissesAndSplits) {
  std::vector<TruthPlane> truth(3);
  truth[0] = {1, "floor", {0, 1, 0}, -0.8, 0.3};
  truth[1] = {2, "wall", {0, 0, 1}, 0.0, 0.9};
  truth[2] = {3, "far", {1, 0, 0}, -3.0, 0.05};  // never big enough to be required
  std::vector<MapPlane> planes(4);
  planes[0].id = 7;
  planes[0].normal = {0, std::cos(0.02), std::sin(0.02)};
  planes[0].distance = -0.78;
  planes[1].id = 8;
  planes[1].normal = {0, 1, 0};
  planes[1].distance = -0.85;
  planes[2].id = 9;
  planes[2].normal = {0, -1, 0};  // facing the wrong way: matches nothing
  planes[2].distance = 0.8;
  planes[3].id = 10;
  planes[3].normal = {0.7071, 0.7071, 0};
  planes[3].distance = 0;
  const MapEvaluation e = evaluateMap(planes, truth);
  ASSERT_EQ(e.matches.size(), 4u);
  EXPECT_EQ(e.matches[0].truth_id, 1);
  EXPECT_NEAR(e.matches[0].normal_error_deg, 0.02 * 180 / CV_PI, 1e-6);
  EXPECT_NEAR(e.matches[0].distance_error_m, 0.02, 1e-9);
  EXPECT_EQ(e.matches[1].truth_id, 1);
  EXPECT_EQ(e.matches[2].truth_id, -1);
  EXPECT_EQ(e.matches[3].truth_id, -1);
  EXPECT_EQ(e.split, std::vector<int>{1});
  EXPECT_EQ(e.missed, std::vector<int>{2});
  EXPECT_NEAR(e.worst_distance_error_m, 0.05, 1e-9);
}

// A wall and the door recessed 0.12 m in it have the same normal: a mapped plane goes to
// the one it is nearer to, not to whichever comes last.
TEST(MapEvaluation, ParallelSurfacesAreToldApartByOffset) {
  std::vector<TruthPlane> truth(2);
  truth[0] = {1, "left_wall", {1, 0, 0}, -3.0, 0.5};
  truth[1] = {2, "door", {1, 0, 0}, -3.12, 0.05};
  std::vector<MapPlane> planes(2);
  planes[0].id = 1;
  planes[0].normal = {1, 0, 0};
  planes[0].distance = -3.01;
  planes[1].id = 2;
  planes[1].normal = {1, 0, 0};
  planes[1].distance = -3.11;
  const MapEvaluation e = evaluateMap(planes, truth);
  EXPECT_EQ(e.matches[0].truth_id, 1);
  EXPECT_EQ(e.matches[1].truth_id, 2);
  EXPECT_TRUE(e.split.empty());
}

// Kabsch: the rotation and translation between two copies of a point set, not a
// reflection even when the points lie nearly in a plane.
TEST(MapEvaluation, RigidAlignRecoversAKnownMotion) {
  const Pose motion{cameraOrientation(0.7, 0.2, -0.1), {1.0, -2.0, 0.5}};
  std::vector<cv::Vec3d> from, to;
  for (int i = 0; i < 20; ++i) {
    from.emplace_back(0.3 * i, std::sin(i), 0.01 * (i % 3));  // nearly a plane
    to.push_back(motion.apply(from.back()));
  }
  const Pose found = rigidAlign(from, to);
  EXPECT_LT(cv::norm(found.t - motion.t), 1e-9);
  EXPECT_LT(cv::norm(cv::Mat(found.R - motion.R)), 1e-9);
  EXPECT_NEAR(cv::determinant(cv::Mat(found.R)), 1.0, 1e-9);
}
