// FeatureTracker against exact ground truth: views of a texture through known motions.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <map>
#include <opencv2/imgproc.hpp>
#include <set>

#include "support/tracker_ground_truth.h"

using namespace mono_plane_detection;

namespace {

const cv::Size kView(640, 480);
const cv::Point2d kCentred(-180, -160);  // view shows the middle of a 1000x800 texture

const cv::Mat& texture() {
  static const cv::Mat t = makeCornerTexture({1000, 800}, 42);
  return t;
}

}  // namespace

TEST(FeatureTracker, FirstImageSearchesUpToMaxFeatures) {
  FeatureTracker tracker;
  const auto& points = tracker.process(warpView(texture(), similarity(0, {}, kCentred), kView));
  EXPECT_EQ(points.size(), 50u);
  EXPECT_TRUE(tracker.lastStats().searched);
  std::set<std::uint64_t> ids;
  for (const auto& p : points) {
    EXPECT_TRUE(p.is_new);
    EXPECT_FALSE(p.is_tracked);
    EXPECT_EQ(p.prev_index, -1);
    EXPECT_EQ(p.age, 0);
    ids.insert(p.id);
  }
  EXPECT_EQ(ids.size(), points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    for (size_t j = i + 1; j < points.size(); ++j) {
      EXPECT_GE(cv::norm(points[i].uv - points[j].uv), 15.0 - 1.0);  // sub-pixel refinement
    }
  }
}

TEST(FeatureTracker, EasyMotionTrackedBelowFifthOfPixel) {
  FeatureTracker tracker;
  const auto run =
      runOnViews(tracker, texture(), translations(60, kCentred, {1.3, -0.7}, 0.002), kView);
  ASSERT_GT(run.score.errors().size(), 1000u);
  EXPECT_LT(run.score.meanError(), 0.2);
  // A few points on edges slide along them; the forward-backward check cannot see that.
  EXPECT_LT(percentile(run.score.errors(), 0.99), 1.0);
}

TEST(FeatureTracker, PrevIndexPointsToSamePointInPreviousState) {
  FeatureTracker tracker;
  const auto hs = translations(5, kCentred, {2.0, 1.0});
  for (const auto& H : hs) tracker.process(warpView(texture(), H, kView));
  int checked = 0;
  for (const auto& p : tracker.current()) {
    if (p.prev_index < 0) continue;
    ASSERT_LT(p.prev_index, static_cast<int>(tracker.previous().size()));
    EXPECT_EQ(tracker.previous()[p.prev_index].id, p.id);
    EXPECT_EQ(tracker.previous()[p.prev_index].age + 1, p.age);
    ++checked;
  }
  EXPECT_GT(checked, 40);
}

TEST(FeatureTracker, IdsStableOverHundredFrames) {
  FeatureTracker tracker;
  const auto run =
      runOnViews(tracker, texture(), translations(100, kCentred, {0.4, 0.3}, 0.0005), kView);
  std::set<std::uint64_t> first, last;
  for (const auto& p : run.states.front()) first.insert(p.id);
  for (const auto& p : run.states.back()) last.insert(p.id);
  int kept = 0;
  for (auto id : first) kept += last.count(id);
  EXPECT_GE(kept, 40);  // of 50
  // Every id still names its own physical point.
  EXPECT_LT(run.score.maxError(), 2.0);
}

TEST(FeatureTracker, IdsIncreaseAndAreNeverReused) {
  TrackerParams params;
  params.reidentify = false;
  FeatureTracker tracker(params);
  std::uint64_t highest = 0;
  std::set<std::uint64_t> seen;
  // Fast motion: points leave the view and new ones are found all the time.
  for (const auto& H : translations(40, kCentred, {9.0, 0.0})) {
    for (const auto& p : tracker.process(warpView(texture(), H, kView))) {
      if (p.is_new) {
        EXPECT_GT(p.id, highest);
        EXPECT_EQ(seen.count(p.id), 0u);
        highest = p.id;
      }
      seen.insert(p.id);
    }
  }
  EXPECT_GT(highest, 60u);
}

TEST(FeatureTracker, SearchesEveryTenFramesOnAStillScene) {
  FeatureTracker tracker;
  const cv::Mat view = warpView(texture(), similarity(0, {}, kCentred), kView);
  std::vector<int> searched_at;
  for (int k = 0; k < 35; ++k) {
    tracker.process(view);
    if (tracker.lastStats().searched) searched_at.push_back(k);
  }
  EXPECT_EQ(searched_at, (std::vector<int>{0, 10, 20, 30}));
}

TEST(FeatureTracker, SearchesWhenTwoThirdsAreLost) {
  FeatureTracker tracker;
  const cv::Mat view = warpView(texture(), similarity(0, {}, kCentred), kView);
  tracker.process(view);
  tracker.process(view);
  ASSERT_FALSE(tracker.lastStats().searched);
  const int before = static_cast<int>(tracker.current().size());

  // Hide a part of the image holding fewer than 2/3 of the points: no search.
  auto hide_left = [&](double share) {
    cv::Mat hidden = view.clone();
    hidden.colRange(0, static_cast<int>(share * view.cols)).setTo(0);
    return hidden;
  };
  int in_left_third = 0;
  for (const auto& p : tracker.current()) in_left_third += p.uv.x < 0.3 * view.cols - 20;
  ASSERT_GT(in_left_third, 0);
  tracker.process(hide_left(0.3));
  EXPECT_FALSE(tracker.lastStats().searched);
  EXPECT_GE(tracker.lastStats().lost, in_left_third);
  EXPECT_LT(tracker.lastStats().lost, 2 * before / 3);

  // Hide almost everything: at least 2/3 lost since the search, so search now.
  tracker.process(hide_left(0.9));
  EXPECT_TRUE(tracker.lastStats().searched);
}

TEST(FeatureTracker, PaperModeMatchesRedetectedCornersToLivePoints) {
  TrackerParams params;
  params.mask_existing = false;  // paper: a new search finds the same corners again
  params.reidentify = false;
  params.spread_grid_columns = 0;  // and takes the strongest (spread: 24 of 30 matched)
  FeatureTracker tracker(params);
  const auto hs = translations(11, kCentred, {0.5, 0.25});
  std::set<std::uint64_t> before;
  for (int k = 0; k < 10; ++k) tracker.process(warpView(texture(), hs[k], kView));
  for (const auto& p : tracker.current()) before.insert(p.id);
  tracker.process(warpView(texture(), hs[10], kView));
  ASSERT_TRUE(tracker.lastStats().searched);
  EXPECT_GE(tracker.lastStats().matched, 30);
  EXPECT_LE(tracker.lastStats().added, 20);
  int kept = 0;
  for (const auto& p : tracker.current()) kept += before.count(p.id);
  EXPECT_GE(kept, 40);
}

TEST(FeatureTracker, MaskKeepsNewCornersAwayFromLivePoints) {
  FeatureTracker tracker;
  int checked = 0;  // new corners measured against the live points of their image
  for (const auto& H : translations(30, kCentred, {6.0, 2.0})) {
    const auto& points = tracker.process(warpView(texture(), H, kView));
    if (!tracker.lastStats().searched) continue;
    for (const auto& fresh : points) {
      if (!fresh.is_new) continue;
      ++checked;
      for (const auto& other : points) {
        if (other.id == fresh.id) continue;
        EXPECT_GE(cv::norm(fresh.uv - other.uv), 15.0 - 1.0);
      }
    }
  }
  EXPECT_GT(checked, 0);
}

namespace {

// Slides right until points on the right edge leave, slides back, holds still long
// enough for a search. Returns how many points of the first image left the view and
// came back with their old id; fails the test on any id found on the wrong point.
int returnedWithOldId(bool reidentify) {
  TrackerParams params;
  params.max_features = 300;  // dense, so the returning corners are found again
  params.min_distance_px = 10;
  params.reidentify = reidentify;
  FeatureTracker tracker(params);
  std::vector<cv::Matx33d> hs;
  for (int k = 0; k <= 12; ++k) hs.push_back(similarity(0, {}, kCentred + cv::Point2d(8.0 * k, 0)));
  for (int k = 12; k >= 0; --k) hs.push_back(similarity(0, {}, kCentred + cv::Point2d(8.0 * k, 0)));
  for (int k = 0; k < 11; ++k) hs.push_back(hs.back());
  const auto run = runOnViews(tracker, texture(), hs, kView);

  std::set<std::uint64_t> at_far_end, at_end;
  for (const auto& p : run.states[12]) at_far_end.insert(p.id);
  for (const auto& p : run.states.back()) at_end.insert(p.id);
  int left = 0, back = 0;
  for (const auto& p : run.states.front()) {
    if (at_far_end.count(p.id)) continue;
    ++left;
    back += static_cast<int>(at_end.count(p.id));
  }
  EXPECT_GE(left, 40);
  // Every id, re-identified or not, is still on the texture pixel it was born on.
  for (const auto& p : run.states.back()) {
    const cv::Point2d truth = transfer(hs.back(), run.score.texturePixel(p.id));
    EXPECT_LT(cv::norm(truth - cv::Point2d(p.uv)), 2.0) << "id " << p.id << " on a wrong point";
  }
  return back;
}

}  // namespace

TEST(FeatureTracker, LostPointGetsItsIdBackWhenItReturns) {
  // Measured 15 of 55; corners re-entering at the image border, where ORB cannot
  // describe them, still get new ids.
  EXPECT_GE(returnedWithOldId(true), 10);
}

TEST(FeatureTracker, WithoutReidentificationReturningPointsGetNewIds) {
  EXPECT_EQ(returnedWithOldId(false), 0);
}

TEST(FeatureTracker, BlackImageGivesNoPointsAndNoCrash) {
  FeatureTracker tracker;
  const cv::Mat black(480, 640, CV_8UC1, cv::Scalar(0));
  EXPECT_TRUE(tracker.process(black).empty());
  EXPECT_TRUE(tracker.process(black).empty());
  // Tracking resumes when there is something to see.
  EXPECT_EQ(tracker.process(warpView(texture(), similarity(0, {}, kCentred), kView)).size(), 50u);
}

TEST(FeatureTracker, SizeChangeStartsOver) {
  FeatureTracker tracker;
  tracker.process(warpView(texture(), similarity(0, {}, kCentred), kView));
  const auto& points =
      tracker.process(warpView(texture(), similarity(0, {}, kCentred), {320, 240}));
  EXPECT_TRUE(tracker.previous().empty());
  ASSERT_FALSE(points.empty());
  for (const auto& p : points) EXPECT_TRUE(p.is_new);
}

TEST(FeatureTracker, RejectsWrongImageTypes) {
  FeatureTracker tracker;
  EXPECT_THROW(tracker.process(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(tracker.process(cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
  EXPECT_THROW(tracker.process(cv::Mat(10, 10, CV_32FC1)), std::invalid_argument);
}

// Images smaller than the tracker's windows are refused with the reason (the sizes),
// never an OpenCV assert; the smallest accepted size is tracked, whatever the windows.
TEST(FeatureTracker, RefusesImagesSmallerThanItsWindows) {
  FeatureTracker tracker;
  const int side = minimumImageSide(tracker.params());
  EXPECT_EQ(side, 11);  // cornerSubPix: 2 x 3 + 5
  try {
    tracker.process(cv::Mat(1, 1, CV_8UC1, cv::Scalar(0)));
    ADD_FAILURE() << "a 1x1 image was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("1x1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("11 px"), std::string::npos) << e.what();
  }
  EXPECT_THROW(tracker.process(cv::Mat(side - 1, 200, CV_8UC1, cv::Scalar(0))),
               std::invalid_argument);
  EXPECT_THROW(tracker.process(cv::Mat(200, side - 1, CV_8UC1, cv::Scalar(0))),
               std::invalid_argument);
  EXPECT_TRUE(imageSizeError({side, side}, tracker.params()).empty());
  EXPECT_FALSE(imageSizeError({side - 1, side}, tracker.params()).empty());
}

TEST(FeatureTracker, SmallestAcceptedImagesAreTrackedWithAnyWindows) {
  for (int reanchor : {1, 3, 15}) {
    for (int lk_window : {3, 51}) {
      for (int block : {1, 31}) {
        TrackerParams params;
        params.reanchor_window_px = reanchor;
        params.window_size_px = lk_window;
        params.block_size = block;
        params.pyramid_levels = 10;
        params.min_distance_px = 0;
        const int side = minimumImageSide(params);
        for (const cv::Size size : {cv::Size(side, side), cv::Size(side + 1, side + 3),
                                    cv::Size(4 * side, side)}) {
          FeatureTracker tracker(params);
          const auto hs = translations(12, kCentred, {0.5, 0.3});
          for (const auto& H : hs) {
            ASSERT_NO_THROW(tracker.process(warpView(texture(), H, size)))
                << size << " reanchor " << reanchor << " window " << lk_window << " block "
                << block;
            for (const auto& p : tracker.current()) {
              EXPECT_TRUE(p.uv.x >= 0 && p.uv.y >= 0 && p.uv.x <= size.width - 1 &&
                          p.uv.y <= size.height - 1);
            }
          }
        }
      }
    }
  }
}

TEST(FeatureTracker, ResetKeepsIdsIncreasing) {
  FeatureTracker tracker;
  const cv::Mat view = warpView(texture(), similarity(0, {}, kCentred), kView);
  std::uint64_t highest = 0;
  for (const auto& p : tracker.process(view)) highest = std::max(highest, p.id);
  tracker.reset();
  EXPECT_TRUE(tracker.current().empty());
  const auto& again = tracker.process(view);
  ASSERT_FALSE(again.empty());
  for (const auto& p : again) EXPECT_GT(p.id, highest);
}

TEST(FeatureTracker, FrameCountCountsProcessedImagesAcrossResets) {
  // Like the ids, the image count goes on over a reset (lost points' ages are counted
  // in it); a refused image is not counted.
  FeatureTracker tracker;
  EXPECT_EQ(tracker.frameCount(), 0);
  const cv::Mat view = warpView(texture(), similarity(0, {}, kCentred), kView);
  tracker.process(view);
  tracker.process(view);
  EXPECT_EQ(tracker.frameCount(), 2);
  EXPECT_THROW(tracker.process(cv::Mat(10, 10, CV_32FC1)), std::invalid_argument);
  EXPECT_EQ(tracker.frameCount(), 2);
  tracker.reset();
  EXPECT_EQ(tracker.frameCount(), 2);
  tracker.process(view);
  EXPECT_EQ(tracker.frameCount(), 3);
}

TEST(FeatureTracker, AddedTargetCornersAreTrackedAndKeepTheirFlag) {
  FeatureTracker tracker;
  const auto hs = translations(6, kCentred, {1.0, 0.5});
  tracker.process(warpView(texture(), hs[0], kView));
  // Four texture corners stand in for the target's.
  std::vector<cv::Point2f> corners;
  for (int i = 0; i < 4; ++i)
    corners.push_back(tracker.current()[i * 5].uv + cv::Point2f(0.f, 0.f));
  const auto ids = tracker.addPoints(corners, true);
  ASSERT_EQ(ids.size(), 4u);
  for (auto id : ids) EXPECT_GT(id, tracker.current().front().id);
  EXPECT_EQ(tracker.addPoints({{-5.f, 10.f}}, true).size(), 0u);  // outside the image
  for (size_t k = 1; k < hs.size(); ++k) {
    const auto& points = tracker.process(warpView(texture(), hs[k], kView));
    int flagged = 0;
    for (const auto& p : points) {
      if (!p.is_target_corner) continue;
      ++flagged;
      EXPECT_TRUE(p.is_tracked);
      const cv::Point2d truth = transfer(hs[k] * hs[0].inv(), cv::Point2d(corners[flagged - 1]));
      EXPECT_LT(cv::norm(truth - cv::Point2d(p.uv)), 0.3);
    }
    EXPECT_EQ(flagged, 4) << "image " << k;
  }
}

// movePoints (the re-detected target's corners): the point keeps its id and flags, is
// tracked on from its new place; unknown ids and positions outside the image are skipped.
TEST(FeatureTracker, MovedPointsKeepTheirIdsAndAreTrackedFromTheirNewPlace) {
  FeatureTracker tracker;
  const auto hs = translations(3, kCentred, {1.0, 0.5});
  tracker.process(warpView(texture(), hs[0], kView));
  ASSERT_GT(tracker.current().size(), 10u);
  const TrackedPoint a = tracker.current()[3], b = tracker.current()[7];
  // A point pushed 0.7 px off its corner, then brought back exactly: the truth.
  const cv::Point2f off(0.5f, -0.5f);
  ASSERT_EQ(tracker.movePoints({a.id, b.id}, {a.uv + off, b.uv}), 2);
  const auto& moved = tracker.current();
  EXPECT_EQ(moved[3].id, a.id);
  EXPECT_EQ(moved[3].uv, a.uv + off);
  EXPECT_EQ(moved[7].uv, b.uv);
  EXPECT_EQ(tracker.movePoints({999999}, {{10.f, 10.f}}), 0);    // no such id
  EXPECT_EQ(tracker.movePoints({a.id}, {{-5.f, 10.f}}), 0);       // outside the image
  EXPECT_EQ(tracker.current()[3].uv, a.uv + off);
  tracker.process(warpView(texture(), hs[1], kView));
  int seen = 0;
  for (const auto& p : tracker.current()) {
    if (p.id != a.id) continue;
    ++seen;
    EXPECT_TRUE(p.is_tracked);
    // Lucas-Kanade from the moved place: the offset carried (partly pulled back to
    // the corner by the window), not the original track.
    const cv::Point2d was = transfer(hs[1] * hs[0].inv(), cv::Point2d(a.uv));
    EXPECT_GT(cv::norm(cv::Point2d(p.uv) - was), 0.1);
  }
  EXPECT_EQ(seen, 1);  // the moved point is still followed
}

// Something moves in front of half of the scene: the points there cannot be followed,
// Lucas-Kanade still converges somewhere on the new texture, and the forward-backward
// check (its short pass from the image's median motion, then the full pass) must drop
// them, while it keeps the points of the visible half.
TEST(FeatureTracker, ForwardBackwardCheckDropsPointsUnderAnOccluder) {
  auto run = [](bool check) {
    TrackerParams params;
    params.max_features = 150;
    params.forward_backward_check = check;
    FeatureTracker tracker(params);
    tracker.process(warpView(texture(), similarity(0, {}, kCentred), kView));
    const std::vector<TrackedPoint> first = tracker.current();
    cv::Mat second = warpView(texture(), similarity(0, {}, kCentred + cv::Point2d(3, 2)), kView);
    const cv::Rect occluder(0, 0, kView.width / 2, kView.height);
    const cv::Mat other = makeCornerTexture({1000, 800}, 7);
    other(cv::Rect(100, 100, occluder.width, occluder.height)).copyTo(second(occluder));
    const auto& points = tracker.process(second);
    // Points well inside the occluder (its edge is still half background) and outside.
    int hidden = 0, hidden_kept = 0, visible = 0, visible_kept = 0;
    std::set<std::uint64_t> kept;
    for (const auto& p : points) kept.insert(p.id);
    for (const auto& p : first) {
      if (p.uv.x < occluder.width - 12) {
        ++hidden;
        hidden_kept += static_cast<int>(kept.count(p.id));
      } else if (p.uv.x > occluder.width + 12) {
        ++visible;
        visible_kept += static_cast<int>(kept.count(p.id));
      }
    }
    return std::array<int, 4>{hidden, hidden_kept, visible, visible_kept};
  };
  const auto with = run(true), without = run(false);
  ASSERT_GT(with[0], 40);
  ASSERT_GT(with[2], 40);
  EXPECT_LE(with[1], with[0] / 10) << "of " << with[0] << " hidden points";
  EXPECT_GE(with[3], with[2] * 9 / 10) << "of " << with[2] << " visible points";
  // Without the check many hidden points are reported tracked: the test can fail.
  EXPECT_GT(without[1], with[1] + with[0] / 4) << without[1] << " of " << without[0];
}

// A search is spread over search_spread_images images: the corner response of the search
// image in bands on the first ones, the choice of corners on the next, and their adoption
// (followed to the image then) on the last: new corners appear only on the last image of
// a search, and the tracker is refilled there.
TEST(FeatureTracker, SearchSpreadsOverSuccessiveImages) {
  TrackerParams params;
  params.max_features = 150;
  params.search_spread_images = 5;
  FeatureTracker tracker(params);
  const auto hs = translations(45, kCentred, {4.0, 0.0});  // points leave at the side
  int parts_seen[6] = {0, 0, 0, 0, 0, 0};
  int part = 0;
  for (size_t k = 0; k < hs.size(); ++k) {
    const auto& points = tracker.process(warpView(texture(), hs[k], kView));
    const auto& stats = tracker.lastStats();
    if (k == 0) continue;  // the first image searches the whole image at once
    part = stats.searched ? 1 : stats.search_rest ? part + 1 : 0;
    ASSERT_LE(part, 5) << "image " << k;
    int fresh = 0;
    for (const auto& p : points) fresh += p.is_new;
    parts_seen[part] += fresh > 0;
    if (part == 5) {
      EXPECT_GT(fresh, 0) << "image " << k;
      EXPECT_GE(points.size(), 140u) << "image " << k;  // refilled
    } else {
      EXPECT_EQ(fresh, 0) << "new corners on image " << k << ", part " << part << " of a search";
    }
  }
  EXPECT_GE(parts_seen[5], 3);
}

// With the camera moving, the corners a spread search adds on its last image are those a
// whole-image search adds on the search image, followed there: each at its whole-image
// position plus the image's motion since (the response of the kept image, the choice on
// it, the corners followed from it).
TEST(FeatureTracker, ASpreadSearchAddsTheWholeImageSearchsCornersFollowedToItsLastImage) {
  const auto hs = translations(30, kCentred, {4.0, 1.0});
  for (const int spread : {2, 5}) {
    auto run = [&](int images_spread, std::vector<cv::Point2f>* added,
                   std::map<std::uint64_t, cv::Point2f>* at_search,
                   std::map<std::uint64_t, cv::Point2f>* at_added) {
      TrackerParams params;
      params.max_features = 150;
      params.search_spread_images = images_spread;
      FeatureTracker tracker(params);
      for (size_t k = 0; k < hs.size(); ++k) {
        const auto& points = tracker.process(warpView(texture(), hs[k], kView));
        if (k == 0) continue;
        if (tracker.lastStats().searched && at_search->empty())
          for (const auto& p : points) (*at_search)[p.id] = p.uv;
        for (const auto& p : points)
          if (p.is_new) added->push_back(p.uv);
        if (!added->empty()) {
          for (const auto& p : points) (*at_added)[p.id] = p.uv;
          return static_cast<int>(k);
        }
      }
      return -1;
    };
    std::vector<cv::Point2f> whole, spread_added;
    std::map<std::uint64_t, cv::Point2f> whole_search, whole_added, at_search, at_added;
    const int whole_image = run(1, &whole, &whole_search, &whole_added);
    const int spread_image = run(spread, &spread_added, &at_search, &at_added);
    ASSERT_GT(whole_image, 0);
    EXPECT_EQ(spread_image, whole_image + spread - 1);
    // The image's motion from the search image to the last: the live points' median.
    std::vector<float> dx, dy;
    for (const auto& [id, uv] : at_search)
      if (at_added.count(id)) {
        dx.push_back(at_added[id].x - uv.x);
        dy.push_back(at_added[id].y - uv.y);
      }
    ASSERT_GT(dx.size(), 50u);
    std::nth_element(dx.begin(), dx.begin() + dx.size() / 2, dx.end());
    std::nth_element(dy.begin(), dy.begin() + dy.size() / 2, dy.end());
    const cv::Point2f motion(dx[dx.size() / 2], dy[dy.size() / 2]);
    EXPECT_GT(cv::norm(motion), 3.0 * (spread - 1)) << "the camera moved";
    ASSERT_GE(whole.size(), 10u);
    EXPECT_EQ(spread_added.size(), whole.size()) << "spread " << spread;
    int matched = 0;
    for (const auto& w : whole) {
      double best = 1e9;
      for (const auto& p : spread_added) best = std::min(best, cv::norm(p - (w + motion)));
      matched += best < 0.05;
    }
    EXPECT_EQ(matched, static_cast<int>(whole.size())) << "spread " << spread;
  }
}

// A spread search in progress gives way: when every point is lost (a black image) the
// next textured image is searched whole at once, and a new image size starts over (no
// kept image of the old size is used).
TEST(FeatureTracker, ASpreadSearchInProgressGivesWayToAWholeSearchWhenNeeded) {
  TrackerParams params;
  params.max_features = 150;
  params.search_spread_images = 5;
  const auto hs = translations(30, kCentred, {4.0, 0.0});
  for (const bool black : {true, false}) {
    FeatureTracker tracker(params);
    size_t k = 0;
    for (; k < hs.size(); ++k) {
      tracker.process(warpView(texture(), hs[k], kView));
      if (k > 0 && tracker.lastStats().searched) break;  // a spread search starts here
    }
    ASSERT_LT(k, hs.size());
    ASSERT_EQ(tracker.lastStats().added, 0);  // (spread: nothing added on its first image)
    if (black) {
      EXPECT_TRUE(tracker.process(cv::Mat::zeros(kView, CV_8UC1)).empty());
    } else {
      const cv::Mat half = warpView(texture(), hs[k], kView);
      cv::Mat smaller;
      cv::resize(half, smaller, cv::Size(kView.width / 2, kView.height / 2));
      EXPECT_GE(tracker.process(smaller).size(), 60u);  // started over, searched whole
    }
    const cv::Size size = black ? kView : cv::Size(kView.width / 2, kView.height / 2);
    cv::Mat next = warpView(texture(), hs[k + 1], kView);
    if (!black) cv::resize(next, next, size);
    const auto& points = tracker.process(next);
    if (black) {
      EXPECT_TRUE(tracker.lastStats().searched);
      EXPECT_GE(points.size(), 140u) << "refilled at once, not at the spread's end";
    } else {
      EXPECT_GE(points.size(), 50u);  // followed on the new size
    }
    for (int more = 2; more < 8; ++more) {
      cv::Mat image = warpView(texture(), hs[k + more], kView);
      if (!black) cv::resize(image, image, size);
      EXPECT_GE(tracker.process(image).size(), 40u) << "image " << k + more;
    }
  }
}

// The spread search takes the corners a search of the whole image would take on its
// first image: with the camera still from there on, the corners it adds on its last image
// are those search_spread_images 1 adds on the search image (the live points masked, the
// same quality bar and spread), at the same positions.
TEST(FeatureTracker, ASpreadSearchTakesTheCornersOfTheWholeImageSearch) {
  std::vector<cv::Matx33d> hs = translations(10, kCentred, {6.0, 0.0});  // points leave
  for (int k = 0; k < 6; ++k) hs.push_back(hs.back());                    // then still
  auto added = [&](int spread, size_t* on_image) {
    TrackerParams params;
    params.max_features = 150;
    params.search_spread_images = spread;
    FeatureTracker tracker(params);
    std::vector<cv::Point2f> fresh;
    for (size_t k = 0; k < hs.size(); ++k) {
      const auto& points = tracker.process(warpView(texture(), hs[k], kView));
      if (k == 0) continue;
      for (const auto& p : points)
        if (p.is_new) fresh.push_back(p.uv);
      if (!fresh.empty()) {
        *on_image = k;
        break;
      }
    }
    std::sort(fresh.begin(), fresh.end(), [](const cv::Point2f& a, const cv::Point2f& b) {
      return a.x < b.x || (a.x == b.x && a.y < b.y);
    });
    return fresh;
  };
  size_t whole_image = 0, spread_image = 0;
  const auto whole = added(1, &whole_image), spread = added(5, &spread_image);
  EXPECT_EQ(whole_image, 10u);
  EXPECT_EQ(spread_image, 14u);
  ASSERT_GE(whole.size(), 10u);
  ASSERT_EQ(spread.size(), whole.size());
  for (size_t i = 0; i < whole.size(); ++i)
    EXPECT_LT(cv::norm(spread[i] - whole[i]), 0.01) << whole[i] << " / " << spread[i];
}

namespace {

// 150 corners, with or without predict_motion.
TrackerParams predicting(bool predict_motion) {
  TrackerParams params;
  params.max_features = 150;
  params.predict_motion = predict_motion;
  return params;
}

GroundTruthRun trackViews(const TrackerParams& params, const std::vector<cv::Matx33d>& hs) {
  FeatureTracker tracker(params);
  return runOnViews(tracker, texture(), hs, kView);
}

}  // namespace

// predict_motion: the image's motion measured on a sample, the other points start from
// it on fewer pyramid levels, and follow as many points as the full pyramid, as exactly.
TEST(FeatureTracker, PredictedMotionTracksOnFewerLevelsAsWellAsTheFullPyramid) {
  const auto hs = translations(40, kCentred, {6.0, -2.5}, 0.002);
  const auto predicted = trackViews(predicting(true), hs), full = trackViews(predicting(false), hs);
  int short_images = 0, tracked_predicted = 0, tracked_full = 0, retried = 0;
  for (size_t k = 1; k < full.stats.size(); ++k) {
    EXPECT_EQ(full.stats[k].lk_levels, 5) << "image " << k;
    short_images += predicted.stats[k].lk_levels <= 2;
    tracked_predicted += predicted.stats[k].tracked;
    tracked_full += full.stats[k].tracked;
    retried += predicted.stats[k].lk_retried;
  }
  EXPECT_GE(short_images, 38);
  // The short pass itself follows them (started anywhere else they would all be retried).
  EXPECT_LT(retried, tracked_predicted / 50);
  EXPECT_GE(tracked_predicted, tracked_full * 99 / 100);
  ASSERT_GT(predicted.score.errors().size(), 3000u);
  EXPECT_LT(predicted.score.meanError(), 0.2);
  EXPECT_LT(predicted.score.meanError(), full.score.meanError() + 0.01);
  EXPECT_LT(percentile(predicted.score.errors(), 0.99), 1.0);
}

// A jolt (a bump: 40 px in one image after 2 px per image) is measured by the sample, so
// the short pass starts from it: no track lost, none misplaced.
TEST(FeatureTracker, AJoltIsMeasuredNotPredicted) {
  std::vector<cv::Matx33d> hs = translations(12, kCentred, {2.0, 1.0});
  const cv::Point2d jolted = kCentred + cv::Point2d(11 * 2.0 + 40.0, 11 * 1.0 - 10.0);
  for (int k = 0; k < 6; ++k) hs.push_back(similarity(0, {}, jolted + k * cv::Point2d(2.0, 1.0)));
  const auto predicted = trackViews(predicting(true), hs), full = trackViews(predicting(false), hs);
  const size_t jolt = 12;
  EXPECT_LE(predicted.stats[jolt].lk_levels, 2);
  EXPECT_LT(predicted.stats[jolt].lk_retried, predicted.stats[jolt].tracked / 10);
  EXPECT_GE(predicted.stats[jolt].tracked, full.stats[jolt].tracked * 98 / 100);
  EXPECT_GE(predicted.stats[jolt].tracked, 100);
  ASSERT_GT(predicted.score.errors().size(), 1500u);
  EXPECT_LT(predicted.score.meanError(), 0.2);
  EXPECT_LT(predicted.score.meanError(), full.score.meanError() + 0.01);
}

// Points that move unlike the image (an object crossing: a patch 20 px off the image's
// motion) fail the short pass and get the full pyramid: followed to where they went.
TEST(FeatureTracker, PointsMovingUnlikeTheImageGetTheFullPyramid) {
  const cv::Rect patch(380, 60, 170, 170);
  const cv::Point2d image_step(3, 2), patch_step(23, 12);
  auto run = [&](bool predict) {
    FeatureTracker tracker(predicting(predict));
    tracker.process(warpView(texture(), similarity(0, {}, kCentred), kView));
    const std::vector<TrackedPoint> first = tracker.current();
    cv::Mat second = warpView(texture(), similarity(0, {}, kCentred + image_step), kView);
    const cv::Mat moved = warpView(texture(), similarity(0, {}, kCentred + patch_step), kView);
    moved(patch).copyTo(second(patch));
    tracker.process(second);
    int inside = 0, followed = 0, right = 0;
    for (const auto& p : first) {
      const cv::Point2f to = p.uv + cv::Point2f(patch_step);
      const cv::Rect inner(patch.x + 12, patch.y + 12, patch.width - 24, patch.height - 24);
      if (!inner.contains(p.uv) || !inner.contains(to)) continue;
      ++inside;
      for (const auto& q : tracker.current()) {
        if (q.id != p.id) continue;
        ++followed;
        right += cv::norm(q.uv - to) < 0.3;
      }
    }
    return std::array<int, 6>{inside, followed, right, tracker.lastStats().lk_levels,
                              tracker.lastStats().lk_retried,
                              static_cast<int>(tracker.previous().size())};
  };
  const auto predicted = run(true), full = run(false);
  ASSERT_GE(full[0], 5);
  EXPECT_EQ(full[2], full[0]);  // the full pyramid follows them all
  EXPECT_LE(predicted[3], 2) << "the short pass ran";
  // (At most one of them is in the sample, which had the full pass already: with two
  // the sample's spread would have asked for the full pyramid for all.)
  EXPECT_GE(predicted[4], predicted[0] - 1) << "they were retried";
  // ... and few others (those at the patch's border, whose window changed).
  EXPECT_LT(predicted[4], predicted[5] / 4) << "of " << predicted[5];
  EXPECT_EQ(predicted[1], predicted[0]);
  EXPECT_EQ(predicted[2], predicted[0]);
}

// predict_motion falls back to the full pyramid for all points, exactly as without it,
// when there are too few points to measure the image's motion (fewer than 36) or the
// pyramid has no levels to leave out.
TEST(FeatureTracker, PredictedMotionFallsBackToTheFullPyramidExactly) {
  auto run = [](bool predict, int features, int levels) {
    TrackerParams params = predicting(predict);
    params.max_features = features;
    params.pyramid_levels = levels;
    return trackViews(params, translations(15, kCentred, {3.0, -1.5}, 0.002));
  };
  for (const auto& [features, levels] : {std::pair{30, 5}, std::pair{150, 2}}) {
    const auto predicted = run(true, features, levels), full = run(false, features, levels);
    ASSERT_EQ(predicted.states.size(), full.states.size());
    for (size_t k = 0; k < full.states.size(); ++k) {
      EXPECT_EQ(predicted.stats[k].lk_levels, full.stats[k].lk_levels) << "image " << k;
      ASSERT_EQ(predicted.states[k].size(), full.states[k].size()) << "image " << k;
      for (size_t i = 0; i < full.states[k].size(); ++i) {
        EXPECT_EQ(predicted.states[k][i].id, full.states[k][i].id);
        EXPECT_EQ(predicted.states[k][i].uv, full.states[k][i].uv);
      }
    }
  }
}

// predict_motion without the forward-backward check: the short pass's results stand, as
// exact as the full pyramid's without the check.
TEST(FeatureTracker, PredictedMotionWithoutTheCheckTracksAsExactly) {
  auto run = [](bool predict) {
    TrackerParams params = predicting(predict);
    params.forward_backward_check = false;
    return trackViews(params, translations(30, kCentred, {5.0, 2.0}, 0.002));
  };
  const auto predicted = run(true), full = run(false);
  EXPECT_LE(predicted.stats.back().lk_levels, 2);
  ASSERT_GT(predicted.score.errors().size(), 2500u);
  EXPECT_LT(predicted.score.meanError(), full.score.meanError() + 0.01)
      << "full pyramid " << full.score.meanError();
  EXPECT_GE(predicted.score.errors().size(), full.score.errors().size() * 99 / 100);
}

// setParams (dynamic_reconfigure): a lower max_features drops the youngest points on the
// next image (here all are as old: the newest ids), the others keep their ids and tracks,
// and the drop triggers no search; a higher one is filled by the next search.
TEST(FeatureTracker, ALowerMaxFeaturesDropsTheYoungestPointsAndKeepsTheOthers) {
  TrackerParams params;
  params.max_features = 100;
  FeatureTracker tracker(params);
  const auto hs = translations(30, kCentred, {1.0, 0.5});
  tracker.process(warpView(texture(), hs[0], kView));
  tracker.process(warpView(texture(), hs[1], kView));
  ASSERT_EQ(tracker.current().size(), 100u);
  std::vector<std::uint64_t> oldest;
  for (size_t i = 0; i < 30; ++i) oldest.push_back(tracker.current()[i].id);

  params.max_features = 30;
  EXPECT_EQ(tracker.setParams(params), "");
  EXPECT_EQ(tracker.params().max_features, 30);
  const auto& points = tracker.process(warpView(texture(), hs[2], kView));
  ASSERT_EQ(points.size(), 30u);
  EXPECT_FALSE(tracker.lastStats().searched);  // (the loss counts from what is left)
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(points[i].id, oldest[i]);
    EXPECT_TRUE(points[i].is_tracked);
    // prev_index still points at the same point in the previous image's state.
    EXPECT_EQ(tracker.previous()[points[i].prev_index].id, points[i].id);
  }
  // Back up: the next search (every 10 images) fills to the new maximum.
  params.max_features = 80;
  EXPECT_EQ(tracker.setParams(params), "");
  size_t most = 0;
  for (size_t k = 3; k < 15; ++k)
    most = std::max(most, tracker.process(warpView(texture(), hs[k], kView)).size());
  EXPECT_EQ(most, 80u);
}

// The target's corners are never the ones dropped.
TEST(FeatureTracker, ALowerMaxFeaturesKeepsTheTargetsCorners) {
  FeatureTracker tracker;  // 50
  const auto hs = translations(4, kCentred, {1.0, 0.5});
  tracker.process(warpView(texture(), hs[0], kView));
  std::vector<cv::Point2f> corners;
  for (int i = 0; i < 4; ++i) corners.push_back(tracker.current()[i * 5].uv);
  const auto ids = tracker.addPoints(corners, true);  // the newest: last in current()
  TrackerParams params;
  params.max_features = 10;
  ASSERT_EQ(tracker.setParams(params), "");
  const auto& points = tracker.process(warpView(texture(), hs[1], kView));
  EXPECT_EQ(points.size(), 10u);
  int flagged = 0;
  for (const auto& p : points) flagged += p.is_target_corner;
  EXPECT_EQ(flagged, 4);
}

// The parameters that size the pyramids are refused, and nothing changes.
TEST(FeatureTracker, SetParamsRefusesWhatSizesThePyramids) {
  FeatureTracker tracker;
  tracker.process(warpView(texture(), similarity(0, {}, kCentred), kView));
  for (int which = 0; which < 3; ++which) {
    TrackerParams params;
    params.max_features = 20;
    if (which == 0) params.pyramid_levels = 3;
    if (which == 1) params.window_size_px = 15;
    if (which == 2) params.reanchor_window_px = TrackerParams().reanchor_window_px + 2;
    EXPECT_NE(tracker.setParams(params), "") << which;
    EXPECT_EQ(tracker.params().max_features, 50) << which;
  }
  EXPECT_EQ(tracker.process(warpView(texture(), similarity(0, {1, 0}, kCentred), kView)).size(),
            50u);
}

namespace {

TrackerParams spreadOverFive() {
  TrackerParams params;
  params.max_features = 150;
  params.search_spread_images = 5;
  return params;
}

// Processes hs until a spread search starts; returns that image's index (hs.size(): none).
size_t runToASpreadSearch(FeatureTracker& tracker, const std::vector<cv::Matx33d>& hs) {
  tracker.process(warpView(texture(), hs[0], kView));  // (the first searches whole)
  for (size_t k = 1; k < hs.size(); ++k) {
    tracker.process(warpView(texture(), hs[k], kView));
    if (tracker.lastStats().searched) return k;
  }
  return hs.size();
}

// A tracker of 150 features spreading its searches over 5 images, run on views moving
// sideways (points leave at the side) until a spread search starts, on hs[k].
struct SpreadSearchStarted {
  TrackerParams params = spreadOverFive();
  FeatureTracker tracker{params};
  std::vector<cv::Matx33d> hs = translations(40, kCentred, {4.0, 0.0});
  size_t k = runToASpreadSearch(tracker, hs);
};

}  // namespace

// A spread search in progress finishes under the values it started with; the new ones
// apply from the image after it.
TEST(FeatureTracker, NewParamsWaitForASpreadSearchToEnd) {
  SpreadSearchStarted started;
  auto& [params, tracker, hs, k] = started;
  ASSERT_LT(k, hs.size());
  TrackerParams changed = params;
  changed.quality_level = 0.05;
  ASSERT_EQ(tracker.setParams(changed), "");
  EXPECT_EQ(tracker.params().quality_level, params.quality_level);  // not yet
  int rest = 0;
  for (++k; k < hs.size() && rest < 4; ++k) {
    tracker.process(warpView(texture(), hs[k], kView));
    ASSERT_TRUE(tracker.lastStats().search_rest) << "image " << k;
    ++rest;
  }
  EXPECT_EQ(rest, 4);
  EXPECT_EQ(tracker.params().quality_level, 0.05);  // after its last image
}

// A reset takes the parameters waiting for a spread search at once (there is none left).
TEST(FeatureTracker, ResetTakesWaitingParams) {
  SpreadSearchStarted started;
  auto& [params, tracker, hs, k] = started;
  ASSERT_LT(k, hs.size());
  TrackerParams changed = params;
  changed.max_features = 20;
  ASSERT_EQ(tracker.setParams(changed), "");
  EXPECT_EQ(tracker.params().max_features, 150);  // waits for the spread search
  tracker.reset();
  EXPECT_EQ(tracker.params().max_features, 20);
  EXPECT_EQ(tracker.process(warpView(texture(), hs[0], kView)).size(), 20u);
}

// Youngest first: points of different ages, the youngest go, whatever their place.
TEST(FeatureTracker, ALowerMaxFeaturesDropsTheYoungestWhateverTheirPlace) {
  TrackerParams params;
  params.max_features = 60;
  params.redetect_every = 3;  // new corners join every third image
  FeatureTracker tracker(params);
  const auto hs = translations(12, kCentred, {3.0, 0.0});  // points leave at the side
  for (size_t k = 0; k < 7; ++k) tracker.process(warpView(texture(), hs[k], kView));
  const auto before = tracker.current();
  std::vector<int> ages;
  for (const auto& p : before) ages.push_back(p.age);
  ASSERT_GT(*std::max_element(ages.begin(), ages.end()),
            *std::min_element(ages.begin(), ages.end()));
  const size_t keep = before.size() / 2;
  params.max_features = static_cast<int>(keep);
  ASSERT_EQ(tracker.setParams(params), "");
  const auto& after = tracker.process(warpView(texture(), hs[7], kView));
  ASSERT_LE(after.size(), keep);
  // Every point kept is at least as old as every point dropped that was still followed.
  int youngest_kept = 1 << 30;
  std::set<std::uint64_t> kept;
  for (const auto& p : after) {
    kept.insert(p.id);
    youngest_kept = std::min(youngest_kept, p.age - 1);  // (one image older now)
  }
  int oldest_dropped = -1;
  for (const auto& p : before)
    if (!kept.count(p.id)) oldest_dropped = std::max(oldest_dropped, p.age);
  EXPECT_LE(oldest_dropped, youngest_kept);
  EXPECT_EQ(tracker.lastStats().tracked, static_cast<int>(after.size()));
}

// Values out of their range are refused as the nodelets' parameters are (no OpenCV assert).
TEST(FeatureTracker, SetParamsRefusesValuesOutOfRange) {
  FeatureTracker tracker;
  TrackerParams params;
  params.block_size = 0;
  EXPECT_NE(tracker.setParams(params).find("block_size"), std::string::npos);
  EXPECT_EQ(tracker.params().block_size, TrackerParams().block_size);
}

// A lower max_features set while a spread search runs: the search adds no more than it.
TEST(FeatureTracker, ASpreadSearchAddsNoMoreThanAWaitingLowerMax) {
  SpreadSearchStarted started;
  auto& [params, tracker, hs, k] = started;
  ASSERT_LT(k, hs.size());
  const size_t live = tracker.current().size();
  ASSERT_LT(live, 150u);
  TrackerParams lower = params;
  lower.max_features = static_cast<int>(live);
  ASSERT_EQ(tracker.setParams(lower), "");
  for (int rest = 0; rest < 4 && ++k < hs.size(); ++rest) {
    const auto& points = tracker.process(warpView(texture(), hs[k], kView));
    EXPECT_LE(points.size(), live) << "image " << k;
  }
}
