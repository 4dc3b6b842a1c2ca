#include <gtest/gtest.h>

#include "mono_plane_detection/sim/indoor_scene.h"

using namespace mono_plane_detection;

TEST(IndoorScene, RoomPlanesFaceTheRobot) {
  const IndoorScene scene = makeRoom(RoomParams());
  ASSERT_EQ(scene.planes.size(), 6u);  // floor, 4 walls, ceiling
  const cv::Vec3d start(0, 0, 0.8);
  for (const auto& p : scene.planes) {
    EXPECT_NEAR(cv::norm(p.normal()), 1.0, 1e-12) << p.name;
    EXPECT_GT(p.normal().dot(start) - p.distance(), 0.5)
        << p.name << " normal points out of the room";
    for (const auto& c : p.corners()) EXPECT_NEAR(p.normal().dot(c), p.distance(), 1e-12);
  }
  RoomParams bare;
  bare.walls = 1;
  bare.ceiling = false;
  EXPECT_EQ(makeRoom(bare).planes.size(), 2u);
}

TEST(IndoorScene, RaysHitWhatTheGeometrySays) {
  RoomParams params;
  const IndoorScene scene = makeRoom(params);
  // Straight ahead from 0.8 m height: the front wall, front_m away.
  RayHit hit = castRay(scene, {0, 0, 0.8}, {0, 1, 0});
  ASSERT_GE(hit.plane, 0);
  EXPECT_EQ(scene.planes[hit.plane].name, "front_wall");
  EXPECT_NEAR(hit.distance, params.front_m, 1e-12);
  EXPECT_NEAR(hit.a, params.width_m / 2, 1e-12);
  EXPECT_NEAR(hit.b, 0.8, 1e-12);
  // 30 degrees down: the floor, 0.8 / sin(30) away.
  const double s = std::sin(CV_PI / 6), c = std::cos(CV_PI / 6);
  hit = castRay(scene, {0, 0, 0.8}, {0, c, -s});
  EXPECT_EQ(scene.planes[hit.plane].name, "floor");
  EXPECT_NEAR(hit.distance, 1.6, 1e-12);
  // Up: the ceiling; without one, and without walls, nothing.
  EXPECT_EQ(scene.planes[castRay(scene, {0, 0, 0.8}, {0, 0, 1}).plane].name, "ceiling");
  RoomParams open;
  open.walls = 0;
  open.ceiling = false;
  EXPECT_EQ(castRay(makeRoom(open), {0, 0, 0.8}, {0, 0, 1}).plane, -1);
}

TEST(IndoorScene, TargetIsPaintedWhereItsCornersSay) {
  for (const std::string where : {"wall", "floor"}) {
    RoomParams params;
    params.target_on = where;
    const IndoorScene scene = makeRoom(params);
    const StartTarget& t = scene.target;
    const ScenePlane& plane = scene.planes[t.plane_index];
    EXPECT_EQ(plane.name, where == "wall" ? "front_wall" : "floor");
    EXPECT_NEAR(cv::norm(t.corners[1] - t.corners[0]), 0.297, 1e-12);
    EXPECT_NEAR(cv::norm(t.corners[3] - t.corners[0]), 0.210, 1e-12);
    for (const auto& corner : t.corners)
      EXPECT_NEAR(plane.normal().dot(corner), plane.distance(), 1e-12);
    // The map frame: corners at (+-w/2, +-h/2, 0), z along the plane's normal.
    const Pose map_from_world = t.world_from_map.inverse();
    const cv::Vec3d c0 = map_from_world.apply(t.corners[0]),
                    c2 = map_from_world.apply(t.corners[2]);
    EXPECT_NEAR(c0[0], -0.1485, 1e-12);
    EXPECT_NEAR(c0[1], -0.105, 1e-12);
    EXPECT_NEAR(c2[0], 0.1485, 1e-12);
    EXPECT_NEAR(c2[2], 0.0, 1e-12);
    EXPECT_LT(cv::norm(t.world_from_map.R * cv::Vec3d(0, 0, 1) - plane.normal()), 1e-12);
    // White inside, black in the border, as texels.
    auto texel = [&](const cv::Vec3d& x) {
      const cv::Vec3d local = x - plane.origin;
      return plane.texture.at<uchar>(
          static_cast<int>(std::lround(local.dot(plane.v_axis) * plane.texels_per_m)),
          static_cast<int>(std::lround(local.dot(plane.u_axis) * plane.texels_per_m)));
    };
    EXPECT_EQ(texel(t.centre), 255);
    const cv::Vec3d outward = t.corners[0] - t.centre;
    EXPECT_EQ(texel(t.corners[0] + 0.1 * outward), 0);
  }
}

TEST(IndoorScene, PoseAlgebra) {
  Pose a{cv::Matx33d(0, -1, 0, 1, 0, 0, 0, 0, 1), {1, 2, 3}};
  const cv::Vec3d x(0.5, -2, 7);
  EXPECT_LT(cv::norm(a.inverse().apply(a.apply(x)) - x), 1e-12);
  EXPECT_LT(cv::norm((a * a.inverse()).apply(x) - x), 1e-12);
  EXPECT_LT(cv::norm(a.apply(x) - cv::Vec3d(3, 2.5, 10)), 1e-12);
}
