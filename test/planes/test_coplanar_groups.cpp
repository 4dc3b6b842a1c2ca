#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "mono_plane_detection/planes/coplanar_groups.h"
#include "mono_plane_detection/planes/cross_ratio.h"
#include "mono_plane_detection/sim/synthetic_two_view.h"

using namespace mono_plane_detection;

TEST(CoplanarGroups, DistanceRowsAreEuclidean) {
  const std::vector<cv::Point2d> p{{0, 0}, {3, 4}, {6, 8}};
  const cv::Mat rows = distanceRows(p, {1, 0});
  ASSERT_EQ(rows.rows, 2);
  ASSERT_EQ(rows.cols, 3);
  EXPECT_DOUBLE_EQ(rows.at<double>(0, 0), 5.0);
  EXPECT_DOUBLE_EQ(rows.at<double>(0, 1), 0.0);
  EXPECT_DOUBLE_EQ(rows.at<double>(1, 2), 10.0);
}

TEST(CoplanarGroups, GroupsAreNearWellSpreadDistinctAndDeterministic) {
  TwoViewSceneParams sp;
  sp.outlier_fraction = 0;
  const auto scene = makeTwoViewScene(sp);
  GroupParams params;
  const auto groups = buildGroups(scene.view2, params, 200);
  ASSERT_EQ(groups.size(), 200u);
  for (const auto& g : groups) {
    EXPECT_EQ(std::set<int>(g.begin(), g.end()).size(), 5u);
    std::array<cv::Point2d, 5> pts;
    for (int k = 0; k < 5; ++k) pts[k] = scene.view2[g[k]];
    EXPECT_TRUE(wellSpread(pts, params.min_shape));
    // Every member is among the seed's 10 nearest points at 30 px or more.
    std::vector<double> d;
    for (const auto& q : scene.view2) {
      const double r = cv::norm(q - pts[0]);
      if (r >= params.min_neighbour_distance_px) d.push_back(r);
    }
    std::nth_element(d.begin(), d.begin() + 9, d.end());
    for (int k = 1; k < 5; ++k) {
      EXPECT_GE(cv::norm(pts[k] - pts[0]), params.min_neighbour_distance_px);
      EXPECT_LE(cv::norm(pts[k] - pts[0]), d[9] + 1e-9);
    }
  }
  EXPECT_EQ(buildGroups(scene.view2, params, 200), groups);
  params.seed = 2;
  EXPECT_NE(buildGroups(scene.view2, params, 200), groups);
}

TEST(CoplanarGroups, TightClustersFallBackToTheNearestPoints) {
  // All points within 20 px: none is 30 px from a seed, the nearest are used instead.
  const std::vector<cv::Point2d> tight{{0, 0}, {10, 1}, {9, 12}, {-1, 8}, {2, 19}, {15, 15}};
  const auto groups = buildGroups(tight, GroupParams(), 5);
  EXPECT_EQ(groups.size(), 5u);
}

TEST(CoplanarGroups, FewerThanFivePointsGiveNoGroup) {
  EXPECT_TRUE(buildGroups({{0, 0}, {1, 0}, {0, 1}, {1, 1}}, GroupParams(), 10).empty());
  const std::vector<cv::Point2d> five{{0, 0}, {100, 10}, {90, 120}, {-10, 80}, {20, 115}};
  EXPECT_FALSE(buildGroups(five, GroupParams(), 3).empty());
}

TEST(CoplanarGroups, InvariantTestSeparatesPlaneFromMixedGroups) {
  TwoViewSceneParams sp;
  sp.planes = 2;
  sp.outlier_fraction = 0;
  sp.noise_px = 0.0;
  const auto scene = makeTwoViewScene(sp);
  GroupParams params;
  int same_ok = 0, same = 0, mixed_ok = 0, mixed = 0;
  for (const auto& g : buildGroups(scene.view2, params, 2000)) {
    std::array<cv::Point2d, 5> in_view1;
    for (int k = 0; k < 5; ++k) in_view1[k] = scene.view1[g[k]];
    if (!wellSpread(in_view1, params.min_shape)) {  // degenerate there: always rejected
      EXPECT_FALSE(isCoplanarGroup(g, scene.view1, scene.view2, params));
      continue;
    }
    std::set<int> labels;
    for (int i : g) labels.insert(scene.labels[i]);
    const bool ok = isCoplanarGroup(g, scene.view1, scene.view2, params);
    if (labels.size() == 1) {
      ++same;
      same_ok += ok;
    } else {
      ++mixed;
      mixed_ok += ok;
    }
  }
  ASSERT_GT(same, 100);
  ASSERT_GT(mixed, 20);
  EXPECT_EQ(same_ok, same);  // exact data: every single-plane group passes
  EXPECT_LT(static_cast<double>(mixed_ok) / mixed, 0.2);
}

TEST(CoplanarGroups, FindStopsAtTheCapAndCountsTries) {
  TwoViewSceneParams sp;
  sp.outlier_fraction = 0.5;
  const auto scene = makeTwoViewScene(sp);
  GroupParams params;
  params.max_groups = 40;
  const auto found = findCoplanarGroups(scene.view1, scene.view2, params);
  EXPECT_EQ(found.groups.size(), 40u);
  EXPECT_GE(found.tried, 40);
  EXPECT_LE(found.tried, params.max_tries);
  for (const auto& g : found.groups)
    EXPECT_TRUE(isCoplanarGroup(g, scene.view1, scene.view2, params));
}

// Tries follow the number of points between the floor and the cap.
TEST(CoplanarGroups, TriesFollowThePointsBetweenFloorAndCap) {
  GroupParams params;
  params.tries_per_point = 15;
  params.min_tries = 2000;
  params.max_tries = 6000;
  EXPECT_EQ(triesFor(params, 0), 2000);
  EXPECT_EQ(triesFor(params, 100), 2000);   // 1500 under the floor
  EXPECT_EQ(triesFor(params, 200), 3000);
  EXPECT_EQ(triesFor(params, 400), 6000);
  EXPECT_EQ(triesFor(params, 100000), 6000);  // capped
}

// The transfer test: the fifth point's error under the other four's homography is 0 on a
// plane and grows with the point's distance from it; in noise units it accepts coplanar
// groups and refuses off-plane ones.
TEST(CoplanarGroups, FifthPointErrorAndTheTransferTest) {
  const cv::Matx33d H(1.05, 0.02, 12, -0.03, 0.98, -7, 1e-4, 5e-5, 1);
  auto apply = [&](const cv::Point2d& p) {
    const cv::Vec3d q = H * cv::Vec3d(p.x, p.y, 1);
    return cv::Point2d(q[0] / q[2], q[1] / q[2]);
  };
  std::vector<cv::Point2d> v1{{100, 100}, {300, 120}, {280, 320}, {90, 300}, {200, 210}};
  std::vector<cv::Point2d> v2;
  for (const auto& p : v1) v2.push_back(apply(p));
  const PointGroup g{0, 1, 2, 3, 4};
  EXPECT_LT(fifthPointError(g, v1, v2), 1e-9);
  v2[4].x += 3.0;  // the fifth point 3 px off the plane
  EXPECT_NEAR(fifthPointError(g, v1, v2), 3.0, 1e-9);
  GroupParams params;  // transfer, 10 noise scales
  EXPECT_TRUE(isCoplanarGroup(g, v1, v2, params, 0.5));    // 3 px < 5 px
  EXPECT_FALSE(isCoplanarGroup(g, v1, v2, params, 0.25));  // 3 px > 2.5 px
  // Without a noise scale the paper's cross-ratio test decides.
  params.coplanarity_test = "cross_ratio";
  EXPECT_EQ(isCoplanarGroup(g, v1, v2, params, 0.5), isCoplanarGroup(g, v1, v2, params, 0.0));
  // Degenerate four: infinite error.
  std::vector<cv::Point2d> line{{0, 0}, {1, 1}, {2, 2}, {3, 3}, {5, 1}};
  EXPECT_TRUE(std::isinf(fifthPointError(g, line, line)));
  EXPECT_TRUE(knownCoplanarityTest("transfer"));
  EXPECT_TRUE(knownCoplanarityTest("cross_ratio"));
  EXPECT_FALSE(knownCoplanarityTest("Transfer"));
}

// On a synthetic pair both tests accept mostly groups of one plane.
TEST(CoplanarGroups, BothTestsKeepMostlySinglePlaneGroups) {
  TwoViewSceneParams sp;
  sp.planes = 3;
  sp.outlier_fraction = 0.3;
  sp.noise_px = 0.5;
  const auto scene = makeTwoViewScene(sp);
  for (const char* test : {"transfer", "cross_ratio"}) {
    GroupParams params;
    params.coplanarity_test = test;
    const CoplanarGroups found =
        findCoplanarGroups(scene.view1, scene.view2, params, std::sqrt(2.0) * sp.noise_px);
    ASSERT_GT(found.groups.size(), 50u) << test;
    int pure = 0;
    for (const PointGroup& g : found.groups) {
      const int l = scene.labels[g[0]];
      bool same = l > 0;
      for (int i : g) same = same && scene.labels[i] == l;
      pure += same;
    }
    EXPECT_GT(static_cast<double>(pure) / found.groups.size(), 0.8) << test;
  }
}

// The neighbour lists come from a grid search; every group must still be its seed and 4
// of the seed's 10 nearest at 30 px or more by (distance, index), as a scan of the seed's
// row of the distance matrix gives them: a dense cluster among sparse points (crowded
// cells), integer coordinates with many equal distances, and a cluster all within 30 px.
TEST(CoplanarGroups, NeighbourListsAreTheNearestOfTheDistanceRow) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> wide(0, 2000), dense(900, 960);
  std::vector<cv::Point2d> points;
  for (int i = 0; i < 150; ++i) points.emplace_back(wide(rng), wide(rng));
  for (int i = 0; i < 300; ++i) points.emplace_back(dense(rng), dense(rng));
  for (int i = 0; i < 12; ++i) points.emplace_back(3000 + (i % 4) * 5, 3000 + (i / 4) * 5);
  GroupParams params;
  const auto groups = buildGroups(points, params, 3000);
  ASSERT_GT(groups.size(), 1000u);
  const double floor2 = params.min_neighbour_distance_px * params.min_neighbour_distance_px;
  for (const auto& g : groups) {
    auto key = [&](int j) {
      const cv::Point2d d = points[j] - points[g[0]];
      return std::make_pair(d.x * d.x + d.y * d.y, j);
    };
    std::vector<std::pair<double, int>> far, all;
    for (int j = 0; j < static_cast<int>(points.size()); ++j) {
      if (j == g[0]) continue;
      all.push_back(key(j));
      if (key(j).first >= floor2) far.push_back(key(j));
    }
    std::vector<std::pair<double, int>>& row = far.size() >= 4 ? far : all;
    std::sort(row.begin(), row.end());
    const auto tenth = row[std::min<size_t>(9, row.size() - 1)];
    for (int k = 1; k < 5; ++k) {
      EXPECT_LE(key(g[k]), tenth) << "seed " << g[0] << " member " << g[k];
      if (&row == &far) {
        EXPECT_GE(key(g[k]).first, floor2);
      }
    }
  }
}

TEST(CoplanarGroups, FifthPointsShareTheirFour) {
  // fifth_points > 1: runs of groups with the same seed and 3 neighbours, each completed
  // by a different other neighbour, every group still well spread; 1: one group per four.
  TwoViewSceneParams sp;
  sp.outlier_fraction = 0;
  const auto scene = makeTwoViewScene(sp);
  GroupParams params;
  params.fifth_points = 7;
  const auto groups = buildGroups(scene.view2, params, 700);
  ASSERT_EQ(groups.size(), 700u);
  size_t runs = 0, longest = 0;
  for (size_t i = 0; i < groups.size();) {
    size_t j = i;
    std::set<int> fifths;
    while (j < groups.size() &&
           std::equal(groups[i].begin(), groups[i].begin() + 4, groups[j].begin())) {
      std::array<cv::Point2d, 5> pts;
      for (int k = 0; k < 5; ++k) pts[k] = scene.view2[groups[j][k]];
      EXPECT_TRUE(wellSpread(pts, params.min_shape));
      EXPECT_EQ(std::set<int>(groups[j].begin(), groups[j].end()).size(), 5u);
      EXPECT_TRUE(fifths.insert(groups[j][4]).second) << "a fifth point twice for one four";
      ++j;
    }
    EXPECT_LE(j - i, static_cast<size_t>(params.fifth_points));
    longest = std::max(longest, j - i);
    ++runs;
    i = j;
  }
  EXPECT_EQ(longest, 7u);     // the seed's other 7 neighbours (10 - 3)
  EXPECT_LT(runs, 700u / 3);  // most fours give several groups
  EXPECT_EQ(buildGroups(scene.view2, params, 700), groups);
  params.fifth_points = 1;
  const auto single = buildGroups(scene.view2, params, 200);
  size_t shared = 0;
  for (size_t i = 1; i < single.size(); ++i)
    shared += std::equal(single[i].begin(), single[i].begin() + 4, single[i - 1].begin());
  EXPECT_EQ(shared, 0u);
}

TEST(CoplanarGroups, SamplerDrawsOnDemandAndStopsOnDegeneratePoints) {
  // GroupSampler itself: its first groups are buildGroups' (which only collects them),
  // it goes on drawing past any count, and it gives up on points that allow no group.
  TwoViewSceneParams sp;
  sp.outlier_fraction = 0;
  const auto scene = makeTwoViewScene(sp);
  const GroupParams params;
  GroupSampler sampler(scene.view2, params);
  std::vector<PointGroup> drawn(300);
  for (PointGroup& g : drawn) ASSERT_TRUE(sampler.next(g));
  EXPECT_EQ(std::vector<PointGroup>(drawn.begin(), drawn.begin() + 50),
            buildGroups(scene.view2, params, 50));
  // More groups than seeds: the seeds are visited round after round.
  ASSERT_GT(drawn.size(), scene.view2.size());
  std::set<int> seeds;
  for (const PointGroup& g : drawn) seeds.insert(g[0]);
  EXPECT_LT(seeds.size(), drawn.size());  // some seed drawn again

  // Points on one line: every draw is degenerate; next() returns false, it does not spin.
  std::vector<cv::Point2d> line;
  for (int i = 0; i < 40; ++i) line.emplace_back(10.0 * i, 5.0 * i);
  GroupSampler on_line(line, params);
  PointGroup g;
  EXPECT_FALSE(on_line.next(g));
  EXPECT_FALSE(on_line.next(g));
  GroupSampler four({{0, 0}, {100, 0}, {0, 100}, {100, 100}}, params);
  EXPECT_FALSE(four.next(g));
}
