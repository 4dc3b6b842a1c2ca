#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <tuple>

#include "mono_plane_detection/eval/segmentation_error.h"
#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/planes/correspondence_io.h"
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
  auto counts = [&] {  // each homography's points on this round's active set
    std::vector<size_t> c;
    for (const auto& H : hs) c.push_back(inliersOf(H, scene.view1, scene.view2, active, 2.0).size());
    return c;
  };
  std::vector<size_t> previous_counts;
  int skipped = 0;  // bounds a round left as they were though the homography lost points
  for (int round = 0; round < 3; ++round) {
    const std::vector<int> before = bounds;
    const std::vector<size_t> now = counts();
    const Vote plain = voteDominant(hs, scene.view1, scene.view2, active, 2.0);
    const Vote bounded = voteDominant(hs, scene.view1, scene.view2, active, 2.0, &bounds);
    EXPECT_EQ(bounded.winner, plain.winner);
    EXPECT_EQ(bounded.votes, plain.votes);
    EXPECT_EQ(bounded.voters, plain.voters);
    for (size_t h = 0; h < hs.size(); ++h) {
      if (round == 0) EXPECT_LT(bounds[h], std::numeric_limits<int>::max()) << h;  // all counted
      if (round > 0 && now[h] < previous_counts[h] && bounds[h] == before[h]) ++skipped;
    }
    previous_counts = now;
    for (int i : plain.voters) active[i] = false;  // as segmentPlanes does
  }
  // Homographies of planes already removed were skipped: their points left, their bound
  // stayed.
  EXPECT_GT(skipped, 0);
}

// The vote stops counting a homography once it cannot win: the winner and its count are
// still those of counting every point for every homography.
TEST(VoteDominant, SameWinnerAsCountingEverything) {
  TwoViewSceneParams sp;
  sp.planes = 3;
  sp.outlier_fraction = 0.3;
  const auto scene = makeTwoViewScene(sp);
  std::vector<cv::Matx33d> hs;
  for (int k = 0; k < 60; ++k) hs.push_back(scene.homographies[k % 3] * shift(0.05 * (k % 17)));
  std::vector<bool> active(scene.view1.size(), true);
  for (int round = 0; round < 3; ++round) {
    int best = -1, best_votes = 0;
    for (size_t h = 0; h < hs.size(); ++h) {
      int votes = 0;
      for (size_t i = 0; i < active.size(); ++i)
        votes += active[i] && transferError(hs[h], scene.view1[i], scene.view2[i]) < 2.0;
      if (votes > best_votes) {
        best_votes = votes;
        best = static_cast<int>(h);
      }
    }
    const Vote vote = voteDominant(hs, scene.view1, scene.view2, active, 2.0);
    EXPECT_EQ(vote.winner, best);
    EXPECT_EQ(vote.votes, best_votes);
    EXPECT_EQ(static_cast<int>(vote.voters.size()), best_votes);
    for (int i : vote.voters) active[i] = false;
  }
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
    if (k > 0) {
      EXPECT_GE(r.planes[k - 1].inliers.size(), r.planes[k].inliers.size());
    }
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

TEST(SegmentPlanes, ThresholdsFixedOrEstimated) {
  PlaneParams params;
  EXPECT_EQ(fixedThresholds(params).sigma_px, 0.0);  // default: estimated
  params.vote_threshold_px = 2.0;
  EXPECT_DOUBLE_EQ(fixedThresholds(params).inlier_px, 2.0);
  EXPECT_DOUBLE_EQ(fixedThresholds(params).sigma_px, 2.0 / params.vote_threshold_sigma);
  EXPECT_TRUE(checkPlaneParams(params).empty());
  params.groups.coplanarity_test = "cross-ratio";
  EXPECT_FALSE(checkPlaneParams(params).empty());
  const auto r = segmentPlanes({{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 3}}, {{0, 0}, {1, 0}, {0, 1}, {1, 1}, {2, 3}}, params);
  EXPECT_NE(r.error.find("coplanarity_test"), std::string::npos);
  EXPECT_EQ(r.labels, std::vector<int>(5, 0));
}

// The estimated noise scale follows the data: synthetic pairs at 0.3 and 1 px noise per
// view give transfer scales near sqrt(2) x that, and the planes are recovered.
TEST(SegmentPlanes, EstimatesTheNoiseScaleOfThePair) {
  for (double noise : {0.3, 1.0}) {
    TwoViewSceneParams sp;
    sp.planes = 2;
    sp.noise_px = noise;
    sp.outlier_fraction = 0.3;
    const auto scene = makeTwoViewScene(sp);
    const auto r = segmentPlanes(scene.view1, scene.view2);
    EXPECT_NEAR(r.noise_px, std::sqrt(2.0) * noise, 0.4 * noise) << noise;
    EXPECT_EQ(r.planes.size(), 2u) << noise;
    EXPECT_LT(misclassificationError(scene.labels, r.labels), 0.08) << noise;
    for (const HomographyPlane& p : r.planes) EXPECT_GE(p.noise_px, r.noise_px);
  }
}

// A repeated correspondence counts once and gets its first copy's label.
TEST(SegmentPlanes, DuplicatesCountOnce) {
  TwoViewSceneParams sp;
  sp.planes = 2;
  const auto scene = makeTwoViewScene(sp);
  auto v1 = scene.view1, v2 = scene.view2;
  const auto once = segmentPlanes(v1, v2);
  const size_t n = v1.size();
  for (size_t k = 0; k < 40; ++k) {  // three points repeated 40 times would weigh 14 times
    v1.push_back(v1[n - 1 - k % 3]);
    v2.push_back(v2[n - 1 - k % 3]);
  }
  const auto twice = segmentPlanes(v1, v2);
  EXPECT_EQ(twice.duplicates, 40);
  ASSERT_EQ(twice.labels.size(), v1.size());
  EXPECT_EQ(std::vector<int>(twice.labels.begin(), twice.labels.begin() + once.labels.size()),
            once.labels);
  for (size_t k = 0; k < 40; ++k) EXPECT_EQ(twice.labels[n + k], twice.labels[n - 1 - k % 3]);
  for (const HomographyPlane& p : twice.planes)
    for (int i : p.inliers) EXPECT_EQ(twice.labels[i], &p - &twice.planes[0] + 1);
}

// The first copy is the earliest wherever the repeats are; -0 and +0 are the same
// coordinate (the deduplication sorts indices for finite input, a map otherwise).
TEST(SegmentPlanes, DuplicatesAnywhereAndSignedZeros) {
  TwoViewSceneParams sp;
  sp.planes = 2;
  const auto scene = makeTwoViewScene(sp);
  auto v1 = scene.view1, v2 = scene.view2;
  v1[3] = {0.0, 120.0};
  v2[3] = {0.0, 118.0};
  v1.insert(v1.begin(), v1[10]);  // a repeat of (now) index 11, before it
  v2.insert(v2.begin(), v2[10]);
  v1.push_back({-0.0, 120.0});  // a repeat of (now) index 4, signed zero
  v2.push_back({-0.0, 118.0});
  const auto r = segmentPlanes(v1, v2);
  EXPECT_EQ(r.duplicates, 2);
  ASSERT_EQ(r.labels.size(), v1.size());
  EXPECT_EQ(r.labels[0], r.labels[11]);
  EXPECT_EQ(r.labels.back(), r.labels[4]);
  // Non-finite input takes the other path and counts the same repeats.
  v1.push_back({std::nan(""), 1.0});
  v2.push_back({1.0, 1.0});
  const auto n = segmentPlanes(v1, v2);
  EXPECT_EQ(n.duplicates, 2);
  EXPECT_EQ(n.labels[0], n.labels[11]);
}

// Repeated texture matched one period off: points that follow a homography (a true
// plane's, shifted in view 2) but not the epipolar geometry of the scene. With the
// epipolar check (default) that "plane" is dropped and its points are outliers; without
// it the core finds it. The true planes are kept either way.
TEST(SegmentPlanes, EpipolarCheckDropsPlanesOffTheEpipolarGeometry) {
  int fake_found_on = 0, fake_found_off = 0, true_kept = 0, runs = 0;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    TwoViewSceneParams sp;
    sp.planes = 3;
    sp.outlier_fraction = 0.2;
    sp.noise_px = 0.5;
    sp.seed = seed;
    TwoViewScene scene = makeTwoViewScene(sp);
    const size_t first_fake = scene.view1.size();
    const cv::Matx33d fake = cv::Matx33d(1, 0, 18, 0, 1, 24, 0, 0, 1) * scene.homographies[1];
    cv::RNG rng(seed);
    for (size_t i = 0; i < scene.labels.size() && scene.view1.size() < first_fake + 45; ++i) {
      if (scene.labels[i] != 2) continue;
      const cv::Point2d a = scene.view1[i] + cv::Point2d(rng.gaussian(6.0), rng.gaussian(6.0));
      const cv::Vec3d y = fake * cv::Vec3d(a.x, a.y, 1.0);
      scene.view1.push_back(a);
      scene.view2.emplace_back(y[0] / y[2] + rng.gaussian(0.5), y[1] / y[2] + rng.gaussian(0.5));
      scene.labels.push_back(4);
    }
    for (bool check : {false, true}) {
      PlaneParams params;
      params.epipolar_check = check;
      const PlaneSegmentation r = segmentPlanes(scene.view1, scene.view2, params);
      // The fake points: does one plane hold most of them?
      std::vector<int> count(r.planes.size() + 1, 0);
      for (size_t i = first_fake; i < scene.view1.size(); ++i) ++count[r.labels[i]];
      const bool found = *std::max_element(count.begin() + 1, count.end()) > 30;
      (check ? fake_found_on : fake_found_off) += found;
      if (check) {
        EXPECT_TRUE(r.epipolar_checked) << "seed " << seed;
        std::vector<int> truth(scene.labels.begin(), scene.labels.begin() + first_fake),
            found_labels(r.labels.begin(), r.labels.begin() + first_fake);
        true_kept += misclassificationError(truth, found_labels) < 0.05;
      }
    }
    ++runs;
  }
  std::printf("fake plane found: %d of %d scenes without the check, %d with it\n", fake_found_off,
              runs, fake_found_on);
  EXPECT_GE(fake_found_off, 3);  // the test scene is a real challenge
  EXPECT_EQ(fake_found_on, 0);
  EXPECT_EQ(true_kept, runs);
}

namespace {

struct RealScene {
  std::vector<cv::Point2d> view1, view2;
  std::vector<int> labels;
};

RealScene readScene(const std::string& name) {
  RealScene s;
  std::ifstream txt(std::string(TEST_DATA_DIR) + "/" + name + ".txt");
  const Correspondences c = readCorrespondences(txt);
  s.view1 = c.view1;
  s.view2 = c.view2;
  std::ifstream labels(std::string(TEST_DATA_DIR) + "/" + name + ".labels");
  std::string line;
  while (std::getline(labels, line)) {
    line = line.substr(0, line.find('#'));
    if (line.find_first_not_of(" \t\r") != std::string::npos) s.labels.push_back(std::stoi(line));
  }
  return s;
}

}  // namespace

// Real images, default settings, five seeds: AdelaideRMF sene (2 planes, 47 % outliers)
// and elderhallb (3 planes, 48 % outliers). Measured: sene 3.0 % mean, worst 3.6 % (the
// paper's fixed 2 px: 6.4 %), elderhallb 4.1 % mean over seeds 1-5, worst 6.7 % (5.9 %
// over 20 seeds, worst 17 %: two of its planes meet at a shallow angle; fixed 2 px:
// 8.2 %, worst 12.6 %).
TEST(SegmentPlanes, RealScenesBelowAMisclassificationBound) {
  for (const auto& [name, mean_bound, worst_bound] :
       {std::make_tuple("adelaidermf_sene", 0.04, 0.05),
        std::make_tuple("adelaidermf_elderhallb", 0.075, 0.11)}) {
    const RealScene s = readScene(name);
    ASSERT_EQ(s.labels.size(), s.view1.size()) << name;
    ASSERT_GT(s.view1.size(), 200u) << name;
    double sum = 0, worst = 0;
    for (unsigned seed = 1; seed <= 5; ++seed) {
      PlaneParams params;
      params.groups.seed = seed;
      const double e = misclassificationError(s.labels, segmentPlanes(s.view1, s.view2, params).labels);
      sum += e / 5;
      worst = std::max(worst, e);
    }
    std::printf("%s: mean %.2f %%, worst %.2f %% over 5 seeds\n", name, 100 * sum, 100 * worst);
    EXPECT_LT(sum, mean_bound) << name;
    EXPECT_LT(worst, worst_bound) << name;
  }
  // The paper's fixed 2 px on sene, for comparison: worse than the estimate.
  const RealScene s = readScene("adelaidermf_sene");
  PlaneParams fixed;
  fixed.vote_threshold_px = 2.0;
  EXPECT_GT(misclassificationError(s.labels, segmentPlanes(s.view1, s.view2, fixed).labels), 0.04);
}

namespace {

// The plane n.X = d (left camera) that makes H (undistorted left -> right pixels) closest
// to plane-induced under the known pose, by least squares on H's entries (as
// scripts/eval_euroc): m = n / d with lambda K1^-1 H K0 - t m^T = R.
cv::Matx33d inducedByPose(const cv::Matx33d& H, const cv::Matx33d& K0, const cv::Matx33d& K1,
                          const cv::Matx33d& R, const cv::Vec3d& t) {
  const cv::Matx33d Hn = K1.inv() * H * K0;
  cv::Mat A = cv::Mat::zeros(9, 4, CV_64F), b(9, 1, CV_64F);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      A.at<double>(3 * i + j, 0) = Hn(i, j);
      A.at<double>(3 * i + j, 1 + j) = -t[i];
      b.at<double>(3 * i + j) = R(i, j);
    }
  }
  cv::Mat x;
  cv::solve(A, b, x, cv::DECOMP_SVD);
  const cv::Vec3d m(x.at<double>(1), x.at<double>(2), x.at<double>(3));
  return K1 * (R + cv::Matx33d(t[0] * m[0], t[0] * m[1], t[0] * m[2], t[1] * m[0], t[1] * m[1],
                               t[1] * m[2], t[2] * m[0], t[2] * m[1], t[2] * m[2])) *
         K0.inv();
}

cv::Point2d apply(const cv::Matx33d& H, const cv::Point2d& p) {
  const cv::Vec3d y = H * cv::Vec3d(p.x, p.y, 1.0);
  return {y[0] / y[2], y[1] / y[2]};
}

}  // namespace

// Real stereo pair with a known pose (test/data/README.md: EuRoC V1_01_easy, one instant,
// SIFT matches undistorted by plane_pair --matches), seeds 1-20. A plane's homography is
// plane-induced when the median over its points of the distance between its transfer and
// the one the pose induces (n/d by least squares on H, as scripts/eval_euroc) is below
// 1.5 px. The floor must be found and induced in every seed, and so must every other
// plane: 0 of 45 not induced (before F by USAC and the drop of planes off their
// epipolar lines beyond chance, planes/epipolar_check.h: 4 of 47, clusters of 17-19
// mismatched points in the bottom left corner, where the lens model is poorest, and a
// strip of floor tape; before the merge of pieces of one 3D plane: 7 of 49; 8bea236: 11
// of 55; docs/plane_core.md, EuRoC). Those drops must not take the genuine planes: a
// second induced plane above the floor (40 points or more) in 19 of the 20 seeds (17
// before).
TEST(SegmentPlanes, RealStereoPairPlaneInducedHomographies) {
  std::ifstream txt(std::string(TEST_DATA_DIR) + "/euroc_1403715274212143104.txt");
  const Correspondences c = readCorrespondences(txt);
  ASSERT_TRUE(c.error.empty()) << c.error;
  ASSERT_GT(c.view1.size(), 400u);
  // Intrinsics and left -> right pose from the data set's sensor.yaml files
  // (inv(T_BS_cam1) * T_BS_cam0).
  const cv::Matx33d K0(458.654, 0, 367.215, 0, 457.296, 248.375, 0, 0, 1);
  const cv::Matx33d K1(457.587, 0, 379.999, 0, 456.134, 255.238, 0, 0, 1);
  const cv::Matx33d R(0.99999725648, 0.0023120671924, 0.00037600810242, -0.0023171357233,
                      0.99989804851, 0.014089835847, -0.00034339312052, -0.014090668453,
                      0.99990066264);
  const cv::Vec3d t(-0.1100738081, 0.0003991215, -0.0008537025);
  int not_induced = 0, with_second = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    PlaneParams params;
    params.groups.seed = seed;
    const PlaneSegmentation r = segmentPlanes(c.view1, c.view2, params);
    ASSERT_GE(r.planes.size(), 1u) << "seed " << seed;
    // (Seed 3 ends with the floor only: F from one plane is undetermined.)
    if (r.planes.size() > 1) {
      EXPECT_TRUE(r.epipolar_checked) << "seed " << seed;
    }
    size_t floor = 0;
    double floor_induced = 1e9;
    bool second = false;
    for (size_t k = 0; k < r.planes.size(); ++k) {
      const HomographyPlane& p = r.planes[k];
      const cv::Matx33d Hp = inducedByPose(p.H, K0, K1, R, t);
      std::vector<double> d;
      double mean_y = 0;
      for (int i : p.inliers) {
        const cv::Point2d a = apply(Hp, c.view1[i]) - apply(p.H, c.view1[i]);
        d.push_back(std::hypot(a.x, a.y));
        mean_y += c.view1[i].y / p.inliers.size();
      }
      std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
      const double induced = d[d.size() / 2];
      std::printf("seed %u plane %zu: %zu points, mean y %.0f, induced %.2f px\n", seed, k + 1,
                  p.inliers.size(), mean_y, induced);
      not_induced += induced >= 1.5;
      second = second || (induced < 1.5 && mean_y < 300.0 && p.inliers.size() >= 40);
      // The floor fills the image's lower part; nothing else there is as large.
      if (mean_y > 300.0 && p.inliers.size() > floor) {
        floor = p.inliers.size();
        floor_induced = induced;
      }
    }
    EXPECT_GE(floor, 150u) << "seed " << seed;  // 204-295
    EXPECT_LT(floor_induced, 1.5) << "seed " << seed;  // 0.07-0.13 px
    with_second += second;
  }
  std::printf("not induced: %d planes over 20 seeds; a second plane in %d\n", not_induced,
              with_second);
  EXPECT_EQ(not_induced, 0);  // 4 before the drop beyond chance
  EXPECT_GE(with_second, 18);  // measured 19 (17 before)
}

// max_planes caps the planes found, whichever move adds them (the vote, the split move):
// three-plane scenes give 3 planes uncapped, at most the cap otherwise.
TEST(SegmentPlanes, MaxPlanesCapsThePlanesFound) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    TwoViewSceneParams sp;
    sp.seed = seed;
    const auto scene = makeTwoViewScene(sp);
    PlaneParams params;
    params.groups.seed = seed;
    EXPECT_GE(segmentPlanes(scene.view1, scene.view2, params).planes.size(), 3u);
    for (int cap : {1, 2}) {
      params.max_planes = cap;
      const PlaneSegmentation seg = segmentPlanes(scene.view1, scene.view2, params);
      EXPECT_GE(seg.planes.size(), 1u);
      EXPECT_LE(seg.planes.size(), static_cast<size_t>(cap)) << "seed " << seed;
    }
  }
}
