#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <set>

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
  // A camera 0.8 m above the floor is 0.8 m from it, on either side of it.
  const ScenePlane* floor = nullptr;
  for (const auto& p : scene.planes)
    if (p.name == "floor") floor = &p;
  ASSERT_TRUE(floor);
  EXPECT_NEAR(floor->distanceFrom(start), 0.8, 1e-12);
  EXPECT_NEAR(floor->distanceFrom({1, 2, -0.8}), 0.8, 1e-12);
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

TEST(IndoorScene, APlaneContainsItsRectangleButNotItsHoles) {
  ScenePlane wall;
  wall.width_m = 4;
  wall.height_m = 2.5;
  wall.holes.push_back(cv::Rect2d(1.0, 0.0, 0.9, 2.0));  // a door
  EXPECT_TRUE(wall.contains(0.5, 1.0));
  EXPECT_TRUE(wall.contains(1.5, 2.2));   // above the door
  EXPECT_FALSE(wall.contains(1.5, 1.0));  // in the door
  EXPECT_FALSE(wall.contains(-0.1, 1.0));
  EXPECT_FALSE(wall.contains(2.0, 2.6));
}

TEST(IndoorScene, PoseAlgebra) {
  Pose a{cv::Matx33d(0, -1, 0, 1, 0, 0, 0, 0, 1), {1, 2, 3}};
  const cv::Vec3d x(0.5, -2, 7);
  EXPECT_LT(cv::norm(a.inverse().apply(a.apply(x)) - x), 1e-12);
  EXPECT_LT(cv::norm((a * a.inverse()).apply(x) - x), 1e-12);
  EXPECT_LT(cv::norm(a.apply(x) - cv::Vec3d(3, 2.5, 10)), 1e-12);
}

// ---- The furnished room (issue 18) --------------------------------------------------

namespace {

const std::string kTextures = std::string(TEST_DATA_DIR) + "/textures";

const ScenePlane* planeNamed(const IndoorScene& scene, const std::string& name) {
  for (const auto& p : scene.planes)
    if (p.name == name) return &p;
  return nullptr;
}

// Mean absolute Sobel response: how much a corner detector has to hold on to.
double gradientEnergy(const cv::Mat& texture) {
  cv::Mat gx, gy;
  cv::Sobel(texture, gx, CV_32F, 1, 0);
  cv::Sobel(texture, gy, CV_32F, 0, 1);
  return cv::mean(cv::abs(gx))[0] + cv::mean(cv::abs(gy))[0];
}

}  // namespace

TEST(FurnishedRoom, FurnitureFacesAreBoundedPlanesFacingOutOfTheirBoxes) {
  RoomParams params;
  params.layout = "furnished";
  const IndoorScene scene = makeRoom(params);
  for (const std::string name :
       {"sideboard_-y", "sideboard_+z", "sideboard_-x", "shelf_+x", "shelf_+y", "shelf_-y",
        "table_+z", "table_-z", "door", "door_jamb_near", "door_jamb_far", "door_lintel"})
    ASSERT_NE(planeNamed(scene, name), nullptr) << name;
  // Unit normals, every corner on its plane, ids unique.
  std::set<int> ids;
  for (const auto& p : scene.planes) {
    EXPECT_NEAR(cv::norm(p.normal()), 1.0, 1e-12) << p.name;
    for (const auto& c : p.corners()) EXPECT_NEAR(p.normal().dot(c), p.distance(), 1e-12);
    EXPECT_TRUE(ids.insert(p.id).second) << p.name;
  }
  // Out of the box: the sideboard's front faces the start, its top faces up, the
  // shelf's front faces into the room (+x), the table's underside faces down.
  EXPECT_NEAR(planeNamed(scene, "sideboard_-y")->normal()[1], -1, 1e-12);
  EXPECT_NEAR(planeNamed(scene, "sideboard_+z")->normal()[2], 1, 1e-12);
  EXPECT_NEAR(planeNamed(scene, "shelf_+x")->normal()[0], 1, 1e-12);
  EXPECT_NEAR(planeNamed(scene, "table_-z")->normal()[2], -1, 1e-12);
  // From the start, straight ahead at 0.4 m height, 1 m to the right: the sideboard's
  // front, 0.45 m before the front wall.
  RayHit hit = castRay(scene, {1.0, 0, 0.4}, {0, 1, 0});
  ASSERT_GE(hit.plane, 0);
  EXPECT_EQ(scene.planes[hit.plane].name, "sideboard_-y");
  EXPECT_NEAR(hit.distance, params.front_m - 0.45, 1e-12);
  // Towards the left wall through the door opening: the door, recessed 0.12 m.
  hit = castRay(scene, {0, -2.1, 1.0}, {-1, 0, 0});
  ASSERT_GE(hit.plane, 0);
  EXPECT_EQ(scene.planes[hit.plane].name, "door");
  EXPECT_NEAR(hit.distance, params.width_m / 2 + 0.12, 1e-12);
  // Beside the door: the wall itself.
  hit = castRay(scene, {0, -1.0, 1.0}, {-1, 0, 0});
  EXPECT_EQ(scene.planes[hit.plane].name, "left_wall");
  // Table top from above, the floor under it seen from below the top.
  hit = castRay(scene, {-1.1, -1.8, 1.5}, {0, 0, -1});
  EXPECT_EQ(scene.planes[hit.plane].name, "table_+z");
  EXPECT_NEAR(hit.distance, 1.5 - 0.74, 1e-12);
  EXPECT_EQ(scene.planes[castRay(scene, {-1.1, -1.8, 0.5}, {0, 0, -1}).plane].name, "floor");
}

TEST(FurnishedRoom, PlainPaintNextToRichTextureAndPhotographs) {
  RoomParams params;
  params.layout = "furnished";
  const IndoorScene generated = makeRoom(params);
  // Weak: painted walls are smooth away from their posters; rich: the sideboard front.
  const ScenePlane& back = *planeNamed(generated, "back_wall");
  EXPECT_EQ(back.surface, "paint");
  const cv::Mat bare_paint = back.texture(cv::Rect(0, 0, 150, 150));  // floor level, no poster
  EXPECT_LT(gradientEnergy(bare_paint), 1.0);
  EXPECT_GT(gradientEnergy(planeNamed(generated, "sideboard_-y")->texture), 20.0);
  EXPECT_EQ(planeNamed(generated, "shelf_+x")->surface, "books");
  EXPECT_EQ(planeNamed(generated, "table_+z")->surface, "wood");
  // The posters: corners on a painted wall.
  EXPECT_GT(gradientEnergy(planeNamed(generated, "right_wall")->texture), 2 * gradientEnergy(bare_paint));

  params.photos = loadTexturePhotos(kTextures);
  ASSERT_EQ(params.photos.size(), 3u);  // test/data/textures/README.md
  const IndoorScene photographed = makeRoom(params);
  for (const std::string name : {"floor", "front_wall", "left_wall"}) {
    const ScenePlane& p = *planeNamed(photographed, name);
    EXPECT_EQ(p.surface, "photo") << name;
    EXPECT_GT(gradientEnergy(p.texture), 5.0) << name;
    // Not the generated texture: the photograph's pixels.
    EXPECT_GT(cv::norm(p.texture, planeNamed(generated, name)->texture, cv::NORM_L1) / p.texture.total(),
              10.0)
        << name;
  }
  // The bare room too (the photographs were left out there, silently: generalization sweep).
  RoomParams bare;
  const IndoorScene bare_generated = makeRoom(bare);
  bare.photos = params.photos;
  const IndoorScene bare_photographed = makeRoom(bare);
  for (const std::string name : {"floor", "front_wall", "left_wall"}) {
    const ScenePlane& p = *planeNamed(bare_photographed, name);
    EXPECT_EQ(p.surface, "photo") << name;
    EXPECT_GT(cv::norm(p.texture, planeNamed(bare_generated, name)->texture, cv::NORM_L1) /
                  p.texture.total(),
              10.0)
        << name;
  }
  EXPECT_NE(planeNamed(bare_photographed, "right_wall")->surface, "photo");
  EXPECT_THROW(loadTexturePhotos(std::string(TEST_DATA_DIR) + "/no_such_folder"),
               std::runtime_error);
  RoomParams bad;
  bad.layout = "castle";
  EXPECT_THROW(makeRoom(bad), std::invalid_argument);
}

TEST(StartTargets, NoneLeavesTheWallAsItIsAndKeepsTheMapFrame) {
  RoomParams with, without;
  without.target_type = "none";
  const IndoorScene a = makeRoom(with), b = makeRoom(without);
  EXPECT_EQ(b.target.type, "none");
  EXPECT_LT(cv::norm(a.target.centre - b.target.centre), 1e-12);
  const ScenePlane& wall = b.planes[b.target.plane_index];
  const cv::Vec3d local = b.target.centre - wall.origin;
  const int col = static_cast<int>(local.dot(wall.u_axis) * wall.texels_per_m),
            row = static_cast<int>(local.dot(wall.v_axis) * wall.texels_per_m);
  // The generated texture there: no white sheet, no black border.
  const cv::Mat around = wall.texture(cv::Rect(col - 40, row - 30, 80, 60));
  double lo, hi;
  cv::minMaxLoc(around, &lo, &hi);
  EXPECT_LT(hi, 255);
  EXPECT_EQ(cv::countNonZero(around < 3), 0);
}

TEST(StartTargets, SheetOnGreyWallOrWoodTable) {
  for (const std::string background : {"grey", "wood"}) {
    RoomParams params;
    params.layout = "furnished";
    params.target_background = background;
    if (background == "wood") params.target_on = "table";
    const IndoorScene scene = makeRoom(params);
    const StartTarget& t = scene.target;
    const ScenePlane& plane = scene.planes[t.plane_index];
    EXPECT_EQ(plane.name, background == "wood" ? "table_+z" : "front_wall");
    EXPECT_NEAR(cv::norm(t.corners[1] - t.corners[0]), 0.297, 1e-12);
    auto texel = [&](const cv::Vec3d& x) {
      const cv::Vec3d local = x - plane.origin;
      return static_cast<int>(plane.texture.at<uchar>(
          static_cast<int>(std::lround(local.dot(plane.v_axis) * plane.texels_per_m)),
          static_cast<int>(std::lround(local.dot(plane.u_axis) * plane.texels_per_m))));
    };
    EXPECT_EQ(texel(t.centre), 255);
    // Just outside the sheet: mid-grey, or wood (neither black nor white).
    const cv::Vec3d outside = t.corners[0] + 0.2 * (t.corners[0] - t.centre);
    if (background == "grey")
      EXPECT_EQ(texel(outside), 128);
    else
      EXPECT_TRUE(texel(outside) > 60 && texel(outside) < 180) << texel(outside);
  }
  RoomParams bare_table;
  bare_table.target_on = "table";
  EXPECT_THROW(makeRoom(bare_table), std::invalid_argument);
}
