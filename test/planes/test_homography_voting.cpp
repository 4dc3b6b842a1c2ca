#include <gtest/gtest.h>

#include <limits>

#include "mono_plane_detection/planes/homography_voting.h"
#include "mono_plane_detection/sim/synthetic_two_view.h"
#include "mono_plane_detection/sim/synthetic_views.h"

using namespace mono_plane_detection;

namespace {

cv::Matx33d shift(double dx) { return cv::Matx33d(1, 0, dx, 0, 1, 0, 0, 0, 1); }

// view2 = view1 shifted by 10 px for points 0-4, by 20 px for points 5-9.
struct HandMade {
  std::vector<cv::Point2d> view1, view2;
  HandMade() {
    for (int i = 0; i < 10; ++i) {
      view1.emplace_back(10.0 * i, 3.0 * i * i);
      view2.push_back(view1.back() + cv::Point2d(i < 5 ? 10 : 20, 0));
    }
  }
};

}  // namespace

TEST(VoteDominant, MostVotesWinsFirstOnTies) {
  HandMade s;
  // shift(10) and shift(20) both get 5 votes: the first listed wins.
  Vote v = voteDominant({shift(0), shift(10), shift(20)}, s.view1, s.view2, {}, 2.0);
  EXPECT_EQ(v.winner, 1);
  EXPECT_EQ(v.votes, 5);
  EXPECT_EQ(v.voters, (std::vector<int>{0, 1, 2, 3, 4}));
  v = voteDominant({shift(0), shift(20), shift(10)}, s.view1, s.view2, {}, 2.0);
  EXPECT_EQ(v.winner, 1);
  // Transfer error 1.5 px votes under 2 px, not under 1 px.
  EXPECT_EQ(voteDominant({shift(11.5)}, s.view1, s.view2, {}, 2.0).votes, 5);
  EXPECT_EQ(voteDominant({shift(11.5)}, s.view1, s.view2, {}, 1.0).votes, 0);
}

TEST(VoteDominant, OnlyActivePointsVote) {
  HandMade s;
  std::vector<bool> active(10, true);
  active[0] = active[1] = false;  // shift(10) now has 3 votes, shift(20) 5
  const Vote v = voteDominant({shift(10), shift(20)}, s.view1, s.view2, active, 2.0);
  EXPECT_EQ(v.winner, 1);
  EXPECT_EQ(v.votes, 5);
  EXPECT_EQ(inliersOf(shift(10), s.view1, s.view2, active, 2.0), (std::vector<int>{2, 3, 4}));
  EXPECT_EQ(voteDominant({}, s.view1, s.view2, {}, 2.0).winner, -1);
}

TEST(VoteDominant, BoundsGiveTheSameWinnerWithLessWork) {
  TwoViewSceneParams sp;
  sp.planes = 3;
  const auto scene = makeTwoViewScene(sp);
  std::vector<cv::Matx33d> hs = scene.homographies;
  for (int k = 0; k < 20; ++k) hs.push_back(scene.homographies[k % 3] * shift(0.1 * k));
  std::vector<bool> active(scene.view1.size(), true);
  std::vector<int> bounds(hs.size(), std::numeric_limits<int>::max());
  for (int round = 0; round < 3; ++round) {
    const Vote plain = voteDominant(hs, scene.view1, scene.view2, active, 2.0);
    const Vote bounded = voteDominant(hs, scene.view1, scene.view2, active, 2.0, &bounds);
    EXPECT_EQ(bounded.winner, plain.winner);
    EXPECT_EQ(bounded.votes, plain.votes);
    EXPECT_EQ(bounded.voters, plain.voters);
    for (int i : plain.voters) active[i] = false;  // as segmentPlanes does
  }
  // Homographies of planes already removed were skipped, so their bound stayed high.
  int stale = 0;
  for (int b : bounds) stale += b > 0;
  EXPECT_GT(stale, 0);
}

TEST(RefitPlane, RecoversTheHomographyFromARoughStart) {
  TwoViewSceneParams sp;
  sp.planes = 1;
  sp.noise_px = 0.5;
  sp.outlier_fraction = 0.3;
  const auto scene = makeTwoViewScene(sp);
  PlaneParams params;
  params.vote_threshold_px = 2.0;  // refitPlane takes the threshold as given
  cv::Matx33d H = scene.homographies[0] * shift(1.2);  // off by 1.2 px
  std::vector<int> inliers = inliersOf(H, scene.view1, scene.view2, {}, params.vote_threshold_px);
  ASSERT_TRUE(refitPlane(H, inliers, scene.view1, scene.view2, {}, params));
  int truth = 0, wrong = 0;
  for (size_t i = 0; i < scene.labels.size(); ++i) truth += scene.labels[i] == 1;
  for (int i : inliers) wrong += scene.labels[i] != 1;
  EXPECT_GE(static_cast<double>(inliers.size() - wrong) / truth, 0.95);
  EXPECT_LE(wrong, 1);
  const cv::Point2d centre(320, 240);
  EXPECT_LT(cv::norm(transfer(H, centre) - transfer(scene.homographies[0], centre)), 0.3);
}

// Multi-plane recovery over a grid of synthetic scenes: 2-4 planes, 0.5-1 px noise,
// 0-60 % outliers, three scenes each, each run with five group seeds: the method is
// randomized, and a bound on one draw would test luck. Judged against the oracle that
// knows the true homographies (bestPossibleLabels: 0.7-5.4 % here, the error noise makes
// unavoidable). The vote threshold follows the noise (4 sigma, at least the paper's
// 2 px): with sigma = 1 px only 64 % of true inliers are within 2 px.
// Measured over 30 group seeds: 3.7 points above the oracle on average (one seed's
// average: 2.6-5.2); on 2-3 planes with <= 30 % outliers 5 % of runs are more than 7
// points above it (a homography bridging two adjacent planes) and 1 % miss or split a
// plane. The bounds sit about three standard deviations beyond those rates.
TEST(SegmentPlanes, RecoversEveryPlaneOfSyntheticScenes) {
  double excess_sum = 0;
  int runs = 0, easy_runs = 0, easy_far_off = 0, easy_wrong_count = 0;
  for (unsigned group_seed = 1; group_seed <= 5; ++group_seed) {
    for (int planes = 2; planes <= 4; ++planes) {
      for (double outliers : {0.0, 0.3, 0.6}) {
        for (unsigned seed = 1; seed <= 3; ++seed) {
          TwoViewSceneParams sp;
          sp.planes = planes;
          sp.outlier_fraction = outliers;
          sp.noise_px = 0.5 + 0.25 * (seed - 1);
          sp.seed = seed * 17 + planes;
          const auto scene = makeTwoViewScene(sp);
          PlaneParams params;
          params.vote_threshold_px = std::max(2.0, 4.0 * sp.noise_px);
          params.groups.seed = group_seed;
          const auto result = segmentPlanes(scene.view1, scene.view2, params);
          const double excess =
              misclassificationError(scene.labels, result.labels) -
              misclassificationError(scene.labels,
                                     bestPossibleLabels(scene, params.vote_threshold_px));
          if (planes <= 3 && outliers <= 0.3) {
            ++easy_runs;
            easy_far_off += excess > 0.07;
            easy_wrong_count += static_cast<int>(result.planes.size()) != planes;
          }
          excess_sum += excess;
          ++runs;
        }
      }
    }
  }
  std::printf(
      "synthetic multi-plane: %.2f points above the oracle on average over %d runs; of %d "
      "runs with 2-3 planes and <= 30 %% outliers %d more than 7 points above, %d with a "
      "wrong plane count\n",
      100 * excess_sum / runs, runs, easy_runs, easy_far_off, easy_wrong_count);
  EXPECT_LT(excess_sum / runs, 0.05);
  EXPECT_LE(easy_far_off, 8);
  EXPECT_LE(easy_wrong_count, 3);
}

TEST(SegmentPlanes, PlanesAreSortedAndConsistentWithLabels) {
  TwoViewSceneParams sp;
  sp.planes = 3;
  sp.points_per_plane = 40;
  const auto scene = makeTwoViewScene(sp);
  const auto r = segmentPlanes(scene.view1, scene.view2);
  ASSERT_FALSE(r.planes.empty());
  for (size_t k = 0; k < r.planes.size(); ++k) {
    if (k > 0) EXPECT_GE(r.planes[k - 1].inliers.size(), r.planes[k].inliers.size());
    for (int i : r.planes[k].inliers) EXPECT_EQ(r.labels[i], static_cast<int>(k) + 1);
    EXPECT_LT(r.planes[k].rms_error_px, 2.0);
    EXPECT_NEAR(r.planes[k].score, double(r.planes[k].inliers.size()) / scene.view1.size(), 1e-12);
  }
  EXPECT_GT(r.groups_coplanar, 0);
  EXPECT_GE(r.groups_built, r.groups_coplanar);
  // Deterministic given the seed.
  EXPECT_EQ(segmentPlanes(scene.view1, scene.view2).labels, r.labels);
}

TEST(SegmentPlanes, DegenerateInputs) {
  auto r = segmentPlanes({{0, 0}, {1, 1}}, {{0, 0}, {1, 1}});
  EXPECT_EQ(r.labels, (std::vector<int>{0, 0}));
  EXPECT_TRUE(r.planes.empty());
  r = segmentPlanes({{0, 0}}, {});
  EXPECT_FALSE(r.error.empty());
  EXPECT_TRUE(segmentPlanes({}, {}).labels.empty());

  TwoViewSceneParams sp;
  sp.planes = 1;
  auto scene = makeTwoViewScene(sp);
  scene.view1[3].x = std::nan("");
  scene.view2[5].y = std::numeric_limits<double>::infinity();
  r = segmentPlanes(scene.view1, scene.view2);
  EXPECT_EQ(r.labels[3], 0);
  EXPECT_EQ(r.labels[5], 0);
  EXPECT_EQ(r.planes.size(), 1u);
}
