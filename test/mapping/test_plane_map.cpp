// The map of planes: association, stable ids, merging, fading, bounds.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "mono_plane_detection/geometry/plane_fit.h"
#include "mono_plane_detection/mapping/plane_map.h"

using namespace mono_plane_detection;

namespace {

// An observation of plane n . x = d: `count` points with ids from first_id, noise 1 cm,
// from a viewpoint 2 m in front of it that moves 0.2 m with each seed (observations
// count only from distinct viewpoints).
PlaneObservation observe(const cv::Vec3d& n, double d, std::uint64_t first_id, int count,
                         unsigned seed, double extent = 1.0) {
  cv::Vec3d u, v;
  planeAxes(n, u, v);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> spread(-extent, extent);
  std::normal_distribution<double> noise(0, 0.01);
  PlaneObservation obs;
  obs.viewpoint = (d + 2) * n + 0.2 * seed * u;  // on the normal's side
  for (int i = 0; i < count; ++i) {
    obs.ids.push_back(first_id + i);
    obs.points.push_back(d * n + spread(rng) * u + spread(rng) * v + noise(rng) * n);
  }
  return obs;
}

const cv::Vec3d kFloor(0, 1, 0), kWall(0, 0, 1);

// `count` points alternately on two vertical strips 8 cm wide, 1.5 m high (along z): a
// shelf front at x = shelf_x, 0.7-0.78 m along y, and the wall at x = wall_x, 0-0.08 m.
PlaneObservation twoStrips(double shelf_x, double wall_x, int count, std::uint64_t first_id,
                           std::mt19937& rng) {
  std::uniform_real_distribution<double> across(0, 0.08), up(0, 1.5);
  PlaneObservation obs;
  for (int i = 0; i < count; ++i) {
    const bool shelf = i % 2 == 0;
    obs.ids.push_back(first_id + i);
    obs.points.push_back({shelf ? shelf_x : wall_x, (shelf ? 0.7 : 0.0) + across(rng), up(rng)});
  }
  return obs;
}

}  // namespace

TEST(PlaneMap, TwoPlanesKeepTheirIdsOverTime) {
  PlaneMap map;
  for (int k = 0; k < 10; ++k) {
    const auto ids = map.update(
        {observe(kWall, 0.0, 100 + k * 3, 20, k), observe(kFloor, -0.8, 500 + k * 3, 15, 50 + k)},
        1000 + 0.1 * k);
    ASSERT_EQ(ids.size(), 2u);
    EXPECT_EQ(ids[0], 1);
    EXPECT_EQ(ids[1], 2);
  }
  ASSERT_EQ(map.planes().size(), 2u);
  const MapPlane& wall = map.planes()[0];
  EXPECT_LT(normalAngleDeg(wall.normal, kWall), 1.0);
  EXPECT_NEAR(wall.distance, 0.0, 0.01);
  EXPECT_EQ(wall.observations, 10);
  EXPECT_TRUE(wall.confirmed(map.params()));
  EXPECT_GE(wall.polygon.size(), 3u);
  EXPECT_NEAR(map.planes()[1].distance, -0.8, 0.01);
}

TEST(PlaneMap, ObservationsOfTheSamePlaneWithNewTracksAssociateByGeometry) {
  PlaneMap map;
  map.update({observe(kWall, 0.0, 100, 20, 1)}, 1000);
  const auto ids = map.update({observe(kWall, 0.03, 900, 20, 2)}, 1000.1);  // 3 cm off, new ids
  EXPECT_EQ(ids[0], 1);
  EXPECT_EQ(map.planes().size(), 1u);
  // 0.5 m away it is another (parallel) plane.
  const auto other = map.update({observe(kWall, 0.5, 2000, 20, 3)}, 1000.2);
  EXPECT_EQ(other[0], 2);
}

// Where the map's origin lies must not matter: with an odometry frame the robot may be
// 30 m from it. A second look at a wall, tilted 3 deg (within max_angle_deg) about the
// middle of the patch, with new tracks, is the same wall at either origin.
TEST(PlaneMap, AssociationDoesNotDependOnWhereTheOriginIs) {
  for (double along_wall_m : {0.0, 30.0}) {
    cv::Vec3d u, v;
    planeAxes(kWall, u, v);
    const cv::Vec3d centre = 2.0 * kWall + along_wall_m * u;
    auto patch = [&](const cv::Vec3d& n, std::uint64_t first_id, unsigned seed) {
      cv::Vec3d a, b;
      planeAxes(n, a, b);
      std::mt19937 rng(seed);
      std::uniform_real_distribution<double> spread(-1.0, 1.0);
      std::normal_distribution<double> noise(0, 0.01);
      PlaneObservation obs;
      obs.viewpoint = centre + 2.0 * kWall + 0.2 * seed * u;
      for (int i = 0; i < 20; ++i) {
        obs.ids.push_back(first_id + i);
        obs.points.push_back(centre + spread(rng) * a + spread(rng) * b + noise(rng) * n);
      }
      return obs;
    };
    const double tilt = 3.0 * CV_PI / 180;
    const cv::Vec3d tilted = std::cos(tilt) * kWall + std::sin(tilt) * u;
    PlaneMap map;
    map.update({patch(kWall, 100, 1)}, 1000);
    const auto ids = map.update({patch(tilted, 900, 2)}, 1000.1);
    ASSERT_EQ(ids.size(), 1u);
    EXPECT_EQ(ids[0], 1) << "origin " << along_wall_m << " m along the wall";
    EXPECT_EQ(map.planes().size(), 1u) << "origin " << along_wall_m << " m along the wall";
  }
}

TEST(PlaneMap, TooFewOrScatteredPointsAreRejected) {
  PlaneMap map;
  EXPECT_EQ(map.update({observe(kWall, 0.0, 100, 4, 1)}, 1000)[0], -1);
  PlaneObservation cloud;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 30; ++i) {
    cloud.ids.push_back(i);
    cloud.points.push_back({u(rng), u(rng), u(rng)});
  }
  EXPECT_EQ(map.update({cloud}, 1000.1)[0], -1);
  EXPECT_TRUE(map.planes().empty());
}

TEST(PlaneMap, DuplicatesMergeIntoTheOlderId) {
  MapParams params;
  params.min_shared_ids = 2.0;  // never associate by shared tracks here
  params.max_offset_m = 0.05;   // the two start apart (8 cm)
  PlaneMap map(params);
  map.update({observe(kWall, 0.0, 100, 20, 1)}, 1000);
  map.update({observe(kWall, 0.08, 300, 20, 2)}, 1000);
  ASSERT_EQ(map.planes().size(), 2u);
  // Later points show both are one plane at 4 cm: the refit lands between, they merge.
  for (int k = 0; k < 4; ++k) map.update({observe(kWall, 0.04, 100, 20, 10 + k)}, 1000.1 * k);
  map.update({observe(kWall, 0.04, 300, 20, 20)}, 1001);
  ASSERT_EQ(map.planes().size(), 1u);
  EXPECT_EQ(map.planes()[0].id, 1);
}

TEST(PlaneMap, UnconfirmedPlanesVanishConfirmedOnesFade) {
  PlaneMap map;
  for (int k = 0; k < 3; ++k) map.update({observe(kWall, 0.0, 100, 20, k)}, 1000 + 0.1 * k);
  map.update({observe(kFloor, -0.8, 500, 20, 9)}, 1000.3);  // seen once
  ASSERT_EQ(map.planes().size(), 2u);
  const double fresh = map.planes()[0].confidence;
  map.update({}, 1003.0);  // 2.7 s later: the floor was never confirmed
  ASSERT_EQ(map.planes().size(), 1u);
  EXPECT_EQ(map.planes()[0].id, 1);
  map.update({}, 1000.2 + map.params().fade_time_s);
  EXPECT_NEAR(map.planes()[0].confidence, fresh * std::exp(-1.0), 0.02);
}

TEST(PlaneMap, MemoryIsBounded) {
  MapParams params;
  params.max_planes = 3;
  params.max_points_per_plane = 50;
  params.confirm_observations = 1;
  PlaneMap map(params);
  for (int k = 0; k < 8; ++k)  // 8 parallel planes 1 m apart
    map.update({observe(kWall, double(k), 1000 * (k + 1), 20, k)}, 1000 + k);
  EXPECT_EQ(map.planes().size(), 3u);
  for (int k = 0; k < 10; ++k)
    map.update({observe(kFloor, -0.8, 50000 + 30 * k, 30, 100 + k)}, 1010);
  for (const MapPlane& p : map.planes()) EXPECT_LE(p.points.size(), 50u);
  int last_id = 0;
  for (const MapPlane& p : map.planes()) last_id = std::max(last_id, p.id);
  ASSERT_GT(last_id, 0);
  map.reset();
  EXPECT_TRUE(map.planes().empty());
  // Ids are never reused, not even after a reset (a bag loop): the next one goes on.
  EXPECT_GT(map.update({observe(kWall, 0, 1, 20, 1)}, 2000)[0], last_id);
}

// Issue 18: images from one spot repeat the same evidence; a plane is confirmed only
// once it has been observed from viewpoints apart (view_spacing x its distance).
TEST(PlaneMap, ConfirmationNeedsViewsApart) {
  PlaneMap map;
  PlaneObservation obs = observe(kWall, 0.0, 100, 20, 1);
  for (int k = 0; k < 10; ++k) map.update({obs}, 1000 + 0.1 * k);  // one spot, 10 images
  ASSERT_EQ(map.planes().size(), 1u);
  EXPECT_EQ(map.planes()[0].observations, 1);
  EXPECT_FALSE(map.planes()[0].confirmed(map.params()));
  // 2 cm further: still within 3 % of the 2 m to the plane.
  obs.viewpoint += cv::Vec3d(0.02, 0, 0);
  map.update({obs}, 1001.1);
  EXPECT_EQ(map.planes()[0].observations, 1);
  for (int k = 1; k <= 2; ++k) {
    obs.viewpoint += cv::Vec3d(0.1, 0, 0);
    map.update({obs}, 1001.1 + 0.1 * k);
  }
  EXPECT_EQ(map.planes()[0].observations, 3);
  EXPECT_TRUE(map.planes()[0].confirmed(map.params()));
}

// Issue 18: an image plane holding two surfaces (points well triangulated, 4 cm apart)
// is split at the points' own uncertainty; poorly triangulated points (3 cm along the
// ray) cannot tell them apart and stay one plane, as without uncertainties.
TEST(PlaneMap, MixturesAreSplitAtTheLandmarksUncertainty) {
  MapParams params;
  params.max_offset_m = 0.02;  // keep the two surfaces apart in association and merging
  for (const double sigma : {0.002, 0.03}) {
    PlaneMap map(params);
    PlaneObservation a = observe(kWall, 0.0, 100, 30, 1, 1.0);
    const PlaneObservation b = observe(kWall, 0.04, 200, 30, 2, 1.0);
    // Noise-free positions so that the uncertainty given is the real one.
    for (size_t i = 0; i < a.points.size(); ++i) a.points[i][2] = 0.0;
    for (size_t i = 0; i < b.points.size(); ++i) {
      a.ids.push_back(b.ids[i]);
      a.points.push_back(cv::Vec3d(b.points[i][0], b.points[i][1], 0.04));
    }
    a.sigma_m.assign(a.points.size(), sigma);
    a.viewpoint = {0, 0, 2};
    map.update({a}, 1000);
    if (sigma < 0.01) {
      ASSERT_EQ(map.planes().size(), 2u) << "sigma " << sigma;
      for (const MapPlane& p : map.planes()) {
        EXPECT_LT(p.rms_m, 0.005);
        EXPECT_EQ(p.points.size(), 30u);
      }
    } else {
      EXPECT_EQ(map.planes().size(), 1u) << "sigma " << sigma;
    }
  }
}

// Issue 18: a shelf front and the wall beside it, each seen as a narrow vertical strip,
// lie on one tilted plane through both (two parallel lines always do). That plane
// is not taken; without it (the old rule) a plane tilted by tens of degrees was mapped.
TEST(PlaneMap, TwoStripsOnParallelSurfacesAreNotOneTiltedPlane) {
  std::mt19937 rng(3);
  PlaneObservation obs = twoStrips(0.35, 0.0, 40, 100, rng);
  obs.viewpoint = {2.0, 0.3, 1.0};
  PlaneMap old_rule;
  ASSERT_GE(old_rule.update({obs}, 1000)[0], 0);  // no uncertainties: one plane
  const double tilt = normalAngleDeg(old_rule.planes()[0].normal, cv::Vec3d(1, 0, 0));
  EXPECT_GT(tilt, 20.0);
  obs.sigma_m.assign(obs.points.size(), 0.003);
  PlaneMap map;
  // Refused (two surfaces): no plane at all, rather than one tilted through both.
  EXPECT_EQ(map.update({obs}, 1000)[0], -1);
  EXPECT_TRUE(map.planes().empty());
  for (const MapPlane& p : map.planes())
    EXPECT_LT(normalAngleDeg(p.normal, cv::Vec3d(1, 0, 0)), 10.0) << "plane " << p.id;
}

// Issue 18 (furnished room, humanoid path, search_spread_images 5, noise seed 1): a wall
// and the shelf front 0.35 m before it were both mapped and confirmed when one image's
// vote put a strip of each together; the tilted plane through the two strips (two
// parallel strips always lie on one plane) was mapped beside them, 18 deg off. Its points
// are all on the two larger planes: it adds no surface and goes.
TEST(PlaneMap, APlaneOfPointsThatLargerPlanesExplainIsDropped) {
  const cv::Vec3d across(1, 0, 0);
  PlaneMap map;
  for (unsigned k = 0; k < 5; ++k)
    map.update({observe(across, 3.0, 100 + 100 * k, 40, k),
                observe(across, 2.65, 1100 + 100 * k, 40, 20 + k)},
               1000 + 0.1 * k);
  ASSERT_EQ(map.planes().size(), 2u);
  for (const MapPlane& p : map.planes()) ASSERT_TRUE(p.confirmed(map.params()));
  // A strip of each (no uncertainties given: one plane fits them, as in
  // TwoStripsOnParallelSurfacesAreNotOneTiltedPlane's old rule).
  std::mt19937 rng(5);
  PlaneObservation mixture = twoStrips(2.65, 3.0, 14, 5000, rng);
  mixture.viewpoint = {1.0, 0.3, 1.0};
  const double stamp = 1001;
  const PlaneMap walls = map;
  const std::vector<int> ids = map.update({mixture}, stamp);
  EXPECT_EQ(ids[0], -1);
  EXPECT_EQ(map.planes().size(), 2u);
  for (const MapPlane& p : map.planes())
    EXPECT_LT(normalAngleDeg(p.normal, across), 2.0) << "plane " << p.id;
  // Not mixtures, and kept: the two strips with 6 points of their own between the two
  // surfaces (a panel from the shelf to the wall), and the wall's strip alone with 4.
  const auto onTheTiltedPlane = [&](int id) {
    const double y = std::uniform_real_distribution<double>(0.2, 0.5)(rng);
    const double z = std::uniform_real_distribution<double>(0, 1.5)(rng);
    return std::make_pair(std::uint64_t(id), cv::Vec3d(3.0 - 0.35 * (y - 0.04) / 0.7, y, z));
  };
  PlaneObservation panel = mixture, leaning;
  leaning.viewpoint = mixture.viewpoint;
  for (size_t i = 1; i < mixture.points.size(); i += 2) {
    leaning.ids.push_back(mixture.ids[i]);
    leaning.points.push_back(mixture.points[i]);
  }
  for (int i = 0; i < 6; ++i) {
    const auto [id, x] = onTheTiltedPlane(6000 + i);
    panel.ids.push_back(id);
    panel.points.push_back(x);
    if (i >= 4) continue;
    leaning.ids.push_back(id);
    leaning.points.push_back(x);
  }
  for (const PlaneObservation& surface : {panel, leaning}) {
    PlaneMap with = walls;
    EXPECT_GE(with.update({surface}, stamp)[0], 0) << surface.points.size() << " points";
    EXPECT_EQ(with.planes().size(), 3u) << surface.points.size() << " points";
  }
  // The mixture alone (no planes to explain it) is a plane, tilted: what was mapped. Confirmed from 3 views before the wall and shelf were mapped (as in the run),
  // it goes once they are confirmed.
  PlaneMap first;
  for (unsigned k = 0; k < 3; ++k) {
    mixture.viewpoint = {1.0, 0.3 + 0.2 * k, 1.0};
    ASSERT_GE(first.update({mixture}, stamp + k)[0], 0);
  }
  ASSERT_EQ(first.planes().size(), 1u);
  ASSERT_TRUE(first.planes()[0].confirmed(first.params()));
  EXPECT_GT(normalAngleDeg(first.planes()[0].normal, across), 10.0);
  const int mixture_id = first.planes()[0].id;
  for (unsigned k = 0; k < 5; ++k)
    first.update({observe(across, 3.0, 100 + 100 * k, 40, k),
                  observe(across, 2.65, 1100 + 100 * k, 40, 20 + k)},
                 stamp + 3 + 0.1 * k);
  EXPECT_EQ(first.planes().size(), 2u);
  for (const MapPlane& p : first.planes()) {
    EXPECT_NE(p.id, mixture_id);
    EXPECT_LT(normalAngleDeg(p.normal, across), 2.0) << "plane " << p.id;
  }
}

// The 320x240 furnished run's false plane: landmarks of a strip of the shelf front
// (their depth errors shared: the shelf plane's own tracks) and a few of the wall below,
// fitted 17 deg off the shelf, beside the shelf's own plane. Most of its points are that
// larger plane's tracks, on it: its points seen leaning, and it goes, once that plane is
// confirmed. Not when the points are not that plane's tracks, even where they bunch
// within its tolerance (a door ajar 20 deg with 10 of its 16 landmarks within 7 cm of
// the hinge: texture is at hinges and frames), not at exactly half, and not when the
// larger plane is across (a floor strip along a wall's foot, of the wall's tracks).
TEST(PlaneMap, ALeaningCopyOfALargerPlanesTracksGoes) {
  const cv::Vec3d across(1, 0, 0);
  PlaneMap two_views;
  for (unsigned k = 0; k < 2; ++k)
    two_views.update({observe(across, 2.65, 100 + 100 * k, 40, k)}, 1000 + 0.1 * k);
  PlaneMap shelf = two_views;
  for (unsigned k = 2; k < 5; ++k)
    shelf.update({observe(across, 2.65, 100 + 100 * k, 40, k)}, 1000 + 0.1 * k);
  ASSERT_EQ(shelf.planes().size(), 1u);
  ASSERT_TRUE(shelf.planes()[0].confirmed(shelf.params()));
  ASSERT_FALSE(two_views.planes()[0].confirmed(two_views.params()));
  // Turned about the vertical line x = 2.65, y = 0.63; points evenly spread (no gap for
  // the observation's own two-surface test), noise 5 mm. ids: the shelf's tracks 100-139
  // first (`shelf_tracks` of them), then new ones.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.005);
  const auto turned = [&](double deg, const std::vector<double>& ys, size_t shelf_tracks,
                          const cv::Vec3d& viewpoint) {
    PlaneObservation obs;
    obs.viewpoint = viewpoint;
    for (size_t i = 0; i < ys.size(); ++i) {
      obs.ids.push_back(i < shelf_tracks ? 100 + i : 5000 + i);
      const double x = 2.65 + std::tan(deg * CV_PI / 180) * (0.63 - ys[i]) + noise(rng);
      obs.points.push_back({x, ys[i], 0.075 * static_cast<double>((i * 7) % 20)});
    }
    return obs;
  };
  const auto fourViews = [&](PlaneMap map, double deg, const std::vector<double>& ys,
                             size_t shelf_tracks) {
    for (unsigned k = 0; k < 4; ++k)
      map.update({turned(deg, ys, shelf_tracks, {1.0, 0.3 + 0.2 * k, 1.0})}, 1001 + 0.1 * k);
    return map;
  };
  const auto turnedPlanes = [&](const PlaneMap& map) {
    int n = 0;
    for (const MapPlane& p : map.planes()) n += normalAngleDeg(p.normal, across) > 1.0 &&
                                              normalAngleDeg(p.normal, across) < 179.0;
    return n;
  };
  std::vector<double> leaning, door;
  for (int i = 0; i < 12; ++i) leaning.push_back(0.58 + 0.1 * i / 11);  // on the shelf
  for (int i = 0; i < 8; ++i) leaning.push_back(0.5 - 0.2 * i);         // down to the wall
  for (int i = 0; i < 10; ++i) door.push_back(0.63 - 0.07 * i / 9);     // at the hinge
  for (int i = 0; i < 6; ++i) door.push_back(0.5 - 0.15 * i);          // across the door
  EXPECT_EQ(turnedPlanes(fourViews(shelf, 17, leaning, 12)), 0);   // 12 of 20: goes
  EXPECT_EQ(turnedPlanes(fourViews(shelf, 17, leaning, 10)), 1);   // exactly half: stays
  EXPECT_EQ(turnedPlanes(fourViews(two_views, 17, leaning, 12)), 1);  // not confirmed: stays
  const PlaneMap door_map = fourViews(shelf, 20, door, 0);
  ASSERT_EQ(turnedPlanes(door_map), 1);
  for (const MapPlane& p : door_map.planes()) EXPECT_TRUE(p.confirmed(door_map.params()));
  // A floor strip along the shelf's foot (y = -0.8), 7 of its 10 points the shelf's
  // tracks within its tolerance, 3 of its own across the floor: across, so it stays.
  PlaneObservation strip;
  strip.viewpoint = {1.0, 0.5, 1.0};
  for (int i = 0; i < 10; ++i) {
    strip.ids.push_back(i < 7 ? 100 + i : 6000 + i);
    const double x = i < 7 ? 2.65 + noise(rng) : 2.6 - 0.25 * (i - 6);
    strip.points.push_back({x, -0.8 + noise(rng), 0.2 * (i % 7) - 0.6});
  }
  PlaneMap with_strip = shelf;
  EXPECT_GE(with_strip.update({strip}, 1002)[0], 0);
  EXPECT_EQ(with_strip.planes().size(), 2u);
}

// True surfaces next to confirmed walls stay: a floor seen as a strip along the front
// wall's foot (7 of its 10 points on the wall's plane), a floor into the corner of two
// walls (4 points along each wall's foot, 4 of its own), and a table top in that corner
// (3 points on each wall, 6 of its own): the walls their edges touch are across them, not
// surfaces nearly parallel to them that they would mix.
TEST(PlaneMap, TrueSurfacesBesideConfirmedWallsStay) {
  const cv::Vec3d side(1, 0, 0);
  const auto withWalls = [&] {
    PlaneMap map;
    for (unsigned k = 0; k < 5; ++k)
      map.update({observe(kWall, 0.0, 100 + 100 * k, 40, k, 2.0),
                  observe(side, 0.0, 1100 + 100 * k, 40, 20 + k, 2.0)},
                 1000 + 0.1 * k);
    EXPECT_EQ(map.planes().size(), 2u);
    for (const MapPlane& p : map.planes()) EXPECT_TRUE(p.confirmed(map.params()));
    return map;
  };
  // A horizontal surface at `height`: points along the front wall's line, along the side
  // wall's, and its own inside the corner.
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> edge(0.2, 0.8), foot(0.0, 0.02), inside(0.2, 0.6);
  const auto horizontal = [&](double height, int on_front, int on_side, int own) {
    PlaneObservation obs;
    obs.viewpoint = {1.0, height + 1.3, 2.0};
    for (int i = 0; i < on_front + on_side + own; ++i) {
      obs.ids.push_back(7000 + i);
      obs.points.push_back(i < on_front             ? cv::Vec3d(edge(rng), height, foot(rng))
                           : i < on_front + on_side ? cv::Vec3d(foot(rng), height, edge(rng))
                                                    : cv::Vec3d(inside(rng), height, inside(rng)));
    }
    return obs;
  };
  for (const PlaneObservation& surface :
       {horizontal(-0.8, 7, 0, 3), horizontal(-0.8, 4, 4, 4), horizontal(0.8, 3, 3, 6)}) {
    PlaneMap map = withWalls();
    EXPECT_GE(map.update({surface}, 1001)[0], 0);
    ASSERT_EQ(map.planes().size(), 3u);
    EXPECT_LT(normalAngleDeg(map.planes()[2].normal, kFloor), 2.0);
  }
}

// Sparse landmarks of one wall in two bands (0.35 m high, 0.4 m apart, 15 points each,
// 5 mm noise): each band alone fixes its normal to 0.7 deg, so the gap between them is
// no sign of two surfaces. A fixed width (bands under 20 cm were strips) refused this
// wall: the furnished room's left wall at 1280x960.
TEST(PlaneMap, TwoBandsOfOneWallThatFixTheirNormalsAreOnePlane) {
  PlaneObservation obs;
  obs.viewpoint = {0.5, 0.6, 2.5};
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> along(0, 1.5), up(0, 0.35);
  std::normal_distribution<double> noise(0, 0.005);
  for (int i = 0; i < 30; ++i) {
    obs.ids.push_back(100 + i);
    obs.points.push_back({along(rng), (i % 2 ? 0.75 : 0.0) + up(rng), noise(rng)});
  }
  obs.sigma_m.assign(obs.points.size(), 0.005);
  PlaneMap map;
  ASSERT_GE(map.update({obs}, 1000)[0], 0);
  ASSERT_EQ(map.planes().size(), 1u);
  EXPECT_LT(normalAngleDeg(map.planes()[0].normal, kWall), 1.0);
  EXPECT_EQ(map.planes()[0].points.size(), 30u);
}

// Issue 18: a plane is confirmed only once its points fix its normal; a strip of points
// (0.2 m wide, 1.5 m long, 1 cm noise) leaves it free to turn about the strip, however
// often seen.
TEST(PlaneMap, AStripOfPointsIsNeverConfirmed) {
  PlaneMap map;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> across(0, 0.2), along(0, 1.5);
  std::normal_distribution<double> noise(0, 0.01);
  for (int k = 0; k < 6; ++k) {
    PlaneObservation obs;
    obs.viewpoint = {0.3 * k, -2.0, 1.0};
    for (int i = 0; i < 20; ++i) {
      obs.ids.push_back(100 + i);
      obs.points.push_back({across(rng), noise(rng), along(rng)});
    }
    map.update({obs}, 1000 + 0.1 * k);
  }
  ASSERT_EQ(map.planes().size(), 1u);
  for (const MapPlane& p : map.planes()) {
    EXPECT_GE(p.observations, 3);
    EXPECT_GT(p.normal_sigma_deg, map.params().max_normal_sigma_deg);
    EXPECT_FALSE(p.confirmed(map.params()));
  }
  // The same points spread 1 m across: confirmed.
  PlaneMap wide;
  std::uniform_real_distribution<double> wide_across(0, 1.0);
  for (int k = 0; k < 6; ++k) {
    PlaneObservation obs;
    obs.viewpoint = {0.3 * k, -2.0, 1.0};
    for (int i = 0; i < 20; ++i) {
      obs.ids.push_back(100 + i);
      obs.points.push_back({wide_across(rng), noise(rng), along(rng)});
    }
    wide.update({obs}, 1000 + 0.1 * k);
  }
  ASSERT_EQ(wide.planes().size(), 1u);
  EXPECT_TRUE(wide.planes()[0].confirmed(wide.params()));
}

// camera_height: the floor landmarks the start's check fitted the map to (a strip along a
// wall, 0.5 m wide, seen in two stretches 0.3 m apart) are one plane by that check: taken
// whole, not split as an image plane's mixture; the image planes of the floor (a few of
// its landmarks each) join it.
TEST(PlaneMap, AKnownPlaneIsTakenWholeAndTheImagesJoinIt) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> across(-3.0, -2.5), near(-1.6, -0.3), far(0.0, 1.3);
  std::normal_distribution<double> noise(0, 0.01);
  PlaneObservation floor;
  floor.viewpoint = cv::Vec3d(-1.3, 1.2, -0.7);
  for (int i = 0; i < 32; ++i) {
    floor.ids.push_back(100 + i);
    floor.points.emplace_back(across(rng), noise(rng), i < 16 ? near(rng) : far(rng));
  }
  PlaneMap map;
  const int id = map.addKnownPlane(floor, 1000);
  ASSERT_GE(id, 0);
  ASSERT_EQ(map.planes().size(), 1u);
  const MapPlane& plane = map.planes()[0];
  EXPECT_EQ(plane.points.size(), floor.points.size());
  EXPECT_LT(normalAngleDeg(plane.normal, kFloor), 1.0);
  EXPECT_NEAR(plane.distance, 0.0, 0.01);
  EXPECT_EQ(plane.observations, 1);
  EXPECT_FALSE(plane.confirmed(map.params()));
  // Two images see 8 of its landmarks and 4 new ones each, from viewpoints 0.5 m apart.
  for (int k = 1; k <= 2; ++k) {
    PlaneObservation image;
    image.viewpoint = floor.viewpoint + cv::Vec3d(0, 0, 0.5 * k);
    for (int i = 0; i < 8; ++i) {
      image.ids.push_back(floor.ids[8 * k + i]);
      image.points.push_back(floor.points[8 * k + i] + cv::Vec3d(0, noise(rng), 0));
    }
    for (int i = 0; i < 4; ++i) {
      image.ids.push_back(200 + 10 * k + i);
      image.points.emplace_back(across(rng), noise(rng), far(rng));
    }
    EXPECT_EQ(map.update({image}, 1000 + 0.1 * k)[0], id);
  }
  ASSERT_EQ(map.planes().size(), 1u);
  EXPECT_EQ(map.planes()[0].points.size(), floor.points.size() + 8);
  EXPECT_TRUE(map.planes()[0].confirmed(map.params()));
  EXPECT_LT(normalAngleDeg(map.planes()[0].normal, kFloor), 1.0);
}

// A plane from the tracks' motion (PipelineParams::motion_plane_images): its points lie on
// it by construction, so its fit's sigma says how well it is known, and the camera centres
// the fit took its tracks from count as views. A patch of 10 points (0.3 m wide) alone
// leaves the normal loose by the points' measure; with the fit's 0.8 deg and two earlier
// camera centres it is confirmed from one image.
TEST(PlaneMap, APlaneFromMotionCountsItsFitsViewsAndSigma) {
  PlaneObservation patch = observe(kWall, 0.0, 100, 10, 1, 0.15);
  for (cv::Vec3d& p : patch.points) p[2] = 0;  // exactly on the plane, as constructed
  {
    PlaneMap map;
    map.update({patch}, 1000);
    ASSERT_EQ(map.planes().size(), 1u);
    EXPECT_EQ(map.planes()[0].observations, 1);
    EXPECT_GT(map.planes()[0].normal_sigma_deg, 1.0);
    EXPECT_FALSE(map.planes()[0].confirmed(map.params()));
  }
  PlaneMap map;
  patch.measured_from = {patch.viewpoint + cv::Vec3d(0.2, 0, 0),
                         patch.viewpoint + cv::Vec3d(0.4, 0, 0)};
  patch.normal_sigma_deg = 0.8;
  map.update({patch}, 1000);
  ASSERT_EQ(map.planes().size(), 1u);
  EXPECT_EQ(map.planes()[0].observations, 3);
  EXPECT_NEAR(map.planes()[0].normal_sigma_deg, 0.8, 1e-9);
  EXPECT_TRUE(map.planes()[0].confirmed(map.params()));
  // Later points of its own (landmarks) do not loosen it.
  map.update({observe(kWall, 0.0, 200, 10, 2, 0.15)}, 1000.1);
  EXPECT_LE(map.planes()[0].normal_sigma_deg, 0.8);
}

namespace {

// The humanoid's floor as it sees it at image k: `count` points of a strip along the left
// wall (x in [x0, x1], z 0.5-3 m, y = -0.8 m with `noise`), new ids per image.
PlaneObservation floorStrip(std::mt19937& rng, int k, int count, double x0, double x1,
                            double noise) {
  std::uniform_real_distribution<double> across(x0, x1), along(0.5, 3.0);
  std::normal_distribution<double> off(0, noise);
  PlaneObservation floor;
  floor.viewpoint = {-1.5, 0.8 + 0.01 * k, 0.5 + 0.3 * k};
  for (int i = 0; i < count; ++i) {
    floor.ids.push_back(5000 + count * k + i);
    floor.points.push_back({across(rng), -0.8 + off(rng), along(rng)});
  }
  return floor;
}

}  // namespace

// Indoor structure (map/structure_sigmas): a floor seen as a strip 0.3 m wide along a wall
// (as the humanoid sees it) turns about the strip by its points' noise (0.6 cm: its
// normal known to under 1 deg, max_normal_sigma_deg); once two walls are
// confirmed it is held at right angles to them. Its confirmation and the views it counts
// stay its own points' (own_normal: the fit without the walls). With structure_sigmas 0 it
// keeps its own tilt.
TEST(PlaneMap, AStripOfFloorIsHeldAtRightAnglesToTheConfirmedWalls) {
  const cv::Vec3d left(1, 0, 0);
  double held_sum = 0, free_sum = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    MapParams off;
    off.structure_sigmas = 0;
    PlaneMap held, alone(off);
    std::mt19937 rng(seed);
    for (int k = 0; k < 8; ++k) {
      const PlaneObservation floor = floorStrip(rng, k, 20, -2.95, -2.65, 0.006);
      const auto walls = {observe(kWall, 0.0, 100 + 30 * k, 30, seed * 10 + k, 1.5),
                          observe(left, -3.0, 1000 + 30 * k, 30, seed * 20 + k, 1.5)};
      std::vector<PlaneObservation> image(walls);
      if (k >= 4) image.push_back(floor);  // the floor after the walls are confirmed
      held.update(image, 1000 + 0.1 * k);
      alone.update(image, 1000 + 0.1 * k);
    }
    auto floorOf = [&](const PlaneMap& map) -> const MapPlane* {
      for (const MapPlane& p : map.planes())
        if (normalAngleDeg(p.normal, kFloor) < 10) return &p;
      return nullptr;
    };
    const MapPlane* with = floorOf(held);
    const MapPlane* without = floorOf(alone);
    ASSERT_TRUE(with && without) << seed;
    ASSERT_LE(without->normal_sigma_deg, held.params().max_normal_sigma_deg) << seed;
    // Never worse than alone; better on average (below).
    EXPECT_LE(normalAngleDeg(with->normal, kFloor), normalAngleDeg(without->normal, kFloor) + 0.05)
        << seed;
    EXPECT_EQ(with->normal_sigma_deg, without->normal_sigma_deg);
    EXPECT_EQ(with->confirmed(held.params()), without->confirmed(alone.params()));
    // Its own plane is the fit without the walls, what the map without structure has.
    EXPECT_LT(normalAngleDeg(with->own_normal, without->normal), 1e-9) << seed;
    EXPECT_NEAR(with->own_distance, without->distance, 1e-12);
    EXPECT_GT(normalAngleDeg(with->own_normal, with->normal), 0.0);  // held in every draw
    held_sum += normalAngleDeg(with->normal, kFloor);
    free_sum += normalAngleDeg(without->normal, kFloor);
  }
  std::printf("floor strip: alone %.2f deg, held %.2f deg (mean of 10 draws)\n", free_sum / 10,
              held_sum / 10);
  EXPECT_GT(free_sum / 10, 2 * held_sum / 10);  // the strip alone is worse: a real test
}

// The map's up (map/up_sigma_deg): the same strip of floor with no wall in the map is held
// level once the map is told the room's vertical (PlaneMap::setVertical: the target's or
// the odometry's up), and keeps its own tilt when it is not (camera_height, or not told) or
// when up_sigma_deg is 0. Its confirmation stays its own points'.
TEST(PlaneMap, AStripOfFloorIsHeldLevelByTheMapsUp) {
  double held_sum = 0, free_sum = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    MapParams no_up;
    no_up.up_sigma_deg = 0;
    PlaneMap held, untold, off(no_up);
    held.setVertical(kFloor);
    off.setVertical(kFloor);
    std::mt19937 rng(seed);
    for (int k = 0; k < 8; ++k) {
      const std::vector<PlaneObservation> image = {floorStrip(rng, k, 20, -2.95, -2.65, 0.006)};
      held.update(image, 1000 + 0.1 * k);
      untold.update(image, 1000 + 0.1 * k);
      off.update(image, 1000 + 0.1 * k);
    }
    ASSERT_EQ(held.planes().size(), 1u) << seed;
    ASSERT_EQ(untold.planes().size(), 1u) << seed;
    ASSERT_EQ(off.planes().size(), 1u) << seed;
    const MapPlane& with = held.planes()[0];
    const MapPlane& without = untold.planes()[0];
    ASSERT_LE(without.normal_sigma_deg, held.params().max_normal_sigma_deg) << seed;
    // Not told, or told with up_sigma_deg 0: the points' own plane.
    EXPECT_LT(normalAngleDeg(without.normal, without.own_normal), 1e-12) << seed;
    EXPECT_LT(normalAngleDeg(off.planes()[0].normal, without.normal), 1e-12) << seed;
    EXPECT_LT(normalAngleDeg(with.own_normal, without.normal), 1e-9) << seed;
    EXPECT_EQ(with.normal_sigma_deg, without.normal_sigma_deg);
    EXPECT_EQ(with.confirmed(held.params()), without.confirmed(untold.params()));
    EXPECT_LT(normalAngleDeg(with.normal, kFloor), normalAngleDeg(without.normal, kFloor)) << seed;
    held_sum += normalAngleDeg(with.normal, kFloor);
    free_sum += normalAngleDeg(without.normal, kFloor);
  }
  std::printf("floor strip: alone %.2f deg, held by the map's up %.2f deg (mean of 10 draws)\n",
              free_sum / 10, held_sum / 10);
  EXPECT_GT(free_sum / 10, 2 * held_sum / 10);
  // A reset map waits to be told again.
  PlaneMap map;
  map.setVertical(kFloor);
  ASSERT_TRUE(map.vertical());
  map.reset();
  EXPECT_FALSE(map.vertical());
  std::mt19937 rng(3);
  for (int k = 0; k < 8; ++k)
    map.update({floorStrip(rng, k, 20, -2.95, -2.65, 0.006)}, 1000 + 0.1 * k);
  ASSERT_EQ(map.planes().size(), 1u);
  EXPECT_LT(normalAngleDeg(map.planes()[0].normal, map.planes()[0].own_normal), 1e-12);
}

// The map's up holds a plane only where refit can use it: offered to planes known worse
// than up_sigma_deg, held only if known to max_normal_sigma_deg, by structure_sigmas.
TEST(PlaneMap, TheUpCanHoldOnlyBelowTheHoldingBound) {
  MapParams p;
  EXPECT_TRUE(p.upCanHold());  // 0.2 < 1 deg, structure on
  MapParams off = p;
  off.up_sigma_deg = 0;
  EXPECT_FALSE(off.upCanHold());
  MapParams no_structure = p;
  no_structure.structure_sigmas = 0;
  EXPECT_FALSE(no_structure.upCanHold());
  MapParams by_eye = p;
  by_eye.up_sigma_deg = by_eye.max_normal_sigma_deg;  // no plane both worse and held
  EXPECT_FALSE(by_eye.upCanHold());
  by_eye.up_sigma_deg = 0.5;
  EXPECT_TRUE(by_eye.upCanHold());
}

// A ramp is not a floor: 2 m x 2 m of it, tilted 5 deg about x, points 1 cm off, fixes its
// normal to about a tenth of a degree, and the map's up does not pull it level: at 0.2 deg
// it is known worse than the ramp and not offered (as a plane is not); at 0.01 the points
// reject the relation (map/structure_sigmas).
TEST(PlaneMap, ARampKeepsItsSlopeUnderTheMapsUp) {
  const double tilt = 5 * CV_PI / 180;
  const cv::Vec3d ramp(0, std::cos(tilt), std::sin(tilt));
  for (double up_sigma : {0.2, 0.01}) {
    MapParams params;
    params.up_sigma_deg = up_sigma;
    PlaneMap map(params);
    map.setVertical(kFloor);
    for (int k = 0; k < 6; ++k) {
      map.update({observe(ramp, -0.5, 100 + 40 * k, 40, k + 1, 1.0)}, 1000 + 0.1 * k);
    }
    ASSERT_EQ(map.planes().size(), 1u) << up_sigma;
    const MapPlane& plane = map.planes()[0];
    ASSERT_TRUE(plane.confirmed(map.params())) << up_sigma;
    // Known better than 0.2 deg (not offered) and worse than 0.01 (offered, refused).
    ASSERT_LT(plane.normal_sigma_deg, 0.2);
    ASSERT_GT(plane.normal_sigma_deg, 0.01);
    EXPECT_NEAR(normalAngleDeg(plane.normal, kFloor), 5.0, 0.3) << up_sigma;
    EXPECT_LT(normalAngleDeg(plane.normal, plane.own_normal), 1e-9) << up_sigma;
  }
}

// A plane its own points leave loose (over max_normal_sigma_deg) is not held: it would
// swing to a reference by degrees.
TEST(PlaneMap, ALooseStripIsNotHeld) {
  const cv::Vec3d left(1, 0, 0);
  PlaneMap map;
  std::mt19937 rng(4);
  for (int k = 0; k < 8; ++k) {
    const PlaneObservation floor = floorStrip(rng, k, 12, -2.9, -2.7, 0.03);
    std::vector<PlaneObservation> image = {observe(kWall, 0.0, 100 + 30 * k, 30, 10 + k, 1.5),
                                           observe(left, -3.0, 1000 + 30 * k, 30, 20 + k, 1.5)};
    if (k >= 4) image.push_back(floor);
    map.update(image, 1000 + 0.1 * k);
  }
  const MapPlane* floor = nullptr;
  for (const MapPlane& p : map.planes())
    if (normalAngleDeg(p.normal, kFloor) < 30) floor = &p;
  ASSERT_TRUE(floor);
  EXPECT_GT(floor->normal_sigma_deg, map.params().max_normal_sigma_deg);
  EXPECT_LT(normalAngleDeg(floor->normal, floor->own_normal), 1e-12);
}

namespace {

// A confirmed floor (y = -0.8), then 6 images of a shelf front x = 2.7 (0.6 m wide along
// z, 12 points each with `noise` m across it) that each also hold the points `extra`
// (the same tracks in every image, ids from 9000, floor_noise across the floor). Returns
// the map and its shelf plane (nullptr when none within 20 deg of the front).
struct ShelfBesideFloor {
  PlaneMap map;
  const MapPlane* shelf = nullptr;
};

ShelfBesideFloor shelfBesideFloor(double noise_m, const std::vector<cv::Vec3d>& extra) {
  ShelfBesideFloor out;
  for (unsigned k = 0; k < 5; ++k)
    out.map.update({observe(kFloor, -0.8, 100 + 100 * k, 60, k, 3.0)}, 1000 + 0.1 * k);
  EXPECT_TRUE(out.map.planes().size() == 1 && out.map.planes()[0].confirmed(out.map.params()));
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> up(-0.8, 0.7), along(0.0, 0.6);
  std::normal_distribution<double> noise(0, noise_m), floor_noise(0, 0.003);
  for (unsigned k = 0; k < 6; ++k) {
    PlaneObservation shelf;
    shelf.viewpoint = {0.7, 0.5, 0.2 * k};
    for (int i = 0; i < 12; ++i) {
      shelf.ids.push_back(5000 + 100 * k + i);
      shelf.points.push_back({2.7 + noise(rng), up(rng), along(rng)});
    }
    for (size_t i = 0; i < extra.size(); ++i) {
      shelf.ids.push_back(9000 + i);
      shelf.points.push_back(extra[i] + cv::Vec3d(0, floor_noise(rng), 0));
    }
    out.map.update({shelf}, 1001 + 0.1 * k);
  }
  const cv::Vec3d front(1, 0, 0);
  for (const MapPlane& p : out.map.planes())
    if (std::min(normalAngleDeg(p.normal, front), normalAngleDeg(p.normal, -front)) < 20)
      out.shelf = &p;
  return out;
}

double angleToFront(const MapPlane& plane) {
  const cv::Vec3d front(1, 0, 0);
  return std::min(normalAngleDeg(plane.normal, front), normalAngleDeg(plane.normal, -front));
}

}  // namespace

// Issue 18 (the furnished room painted with TUM photographs, wheeled, noise seed 0): a
// shelf front came out 3.6 deg off with 4 floor points 0.7-1.2 m beyond the shelf's end
// among its own (11-14 cm before its plane, but within the refit's 5 cm of its tilted
// extension, holding most of the lever). Points on the confirmed floor, off the plane of
// the shelf's other points, that turn it are the floor's: the shelf's fit leaves them out.
// Points at the shelf's foot are on both and stay. (Without the rule: 3.0 deg.)
TEST(PlaneMap, ACrossingPlanesPointsBeyondTheJoinAreNotThisPlanes) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> beyond(1.26, 1.75), before(0.10, 0.13);
  std::vector<cv::Vec3d> extra;
  for (int i = 0; i < 4; ++i) extra.push_back({2.7 - before(rng), -0.8, beyond(rng)});
  for (int i = 0; i < 3; ++i) extra.push_back({2.7, -0.8, 0.2 * i});  // at its foot
  const ShelfBesideFloor room = shelfBesideFloor(0.015, extra);
  ASSERT_NE(room.shelf, nullptr);
  EXPECT_LT(angleToFront(*room.shelf), 1.5);
  for (std::uint64_t id = 9000; id < 9004; ++id) EXPECT_EQ(room.shelf->points.count(id), 0u) << id;
  for (std::uint64_t id = 9004; id < 9007; ++id) EXPECT_EQ(room.shelf->points.count(id), 1u) << id;
}

// A floor point 3 cm before a shelf front known to 5 mm, at its middle: on the floor and
// off the shelf's other points, but it turns nothing (a lever, not noise, must turn the
// plane beyond 3 sigma of its other points): it stays.
TEST(PlaneMap, ACrossingPlanesPointThatTurnsNothingStays) {
  const ShelfBesideFloor room = shelfBesideFloor(0.005, {{2.67, -0.8, 0.3}});
  ASSERT_NE(room.shelf, nullptr);
  EXPECT_LT(angleToFront(*room.shelf), 1.0);
  EXPECT_EQ(room.shelf->points.count(9000), 1u);
}
