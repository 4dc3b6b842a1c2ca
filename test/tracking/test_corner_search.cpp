// The corner search on a coarser pyramid level against corners whose place is known
// exactly: the corners of bright squares on a dark background.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "mono_plane_detection/tracking/corner_search.h"
#include "mono_plane_detection/tracking/feature_tracker.h"

using namespace mono_plane_detection;

namespace {

// Squares of 20 px every 50 px from (40, 40); a square filling pixels x0..x0+19 has its
// corners where its edges meet: (x0 - 0.5, y0 - 0.5), (x0 + 19.5, y0 - 0.5), ...
struct Squares {
  cv::Mat image;
  std::vector<cv::Point2f> corners;
};

Squares squares(const cv::Size& size) {
  Squares s;
  s.image = cv::Mat(size, CV_8UC1, cv::Scalar(40));
  for (int y0 = 40; y0 + 20 < size.height - 20; y0 += 50) {
    for (int x0 = 40; x0 + 20 < size.width - 20; x0 += 50) {
      s.image(cv::Rect(x0, y0, 20, 20)).setTo(200);
      for (float dx : {-0.5f, 19.5f})
        for (float dy : {-0.5f, 19.5f}) s.corners.push_back({x0 + dx, y0 + dy});
    }
  }
  cv::GaussianBlur(s.image, s.image, cv::Size(3, 3), 0.8);  // symmetric: corners stay
  return s;
}

double nearest(const cv::Point2f& p, const std::vector<cv::Point2f>& truth) {
  double best = 1e9;
  for (const auto& t : truth) best = std::min(best, cv::norm(p - t));
  return best;
}

std::vector<cv::Mat> pyramidOf(const cv::Mat& image, int* levels) {
  std::vector<cv::Mat> pyramid;
  *levels = cv::buildOpticalFlowPyramid(image, pyramid, cv::Size(7, 7), 4);
  return pyramid;
}

}  // namespace

TEST(CornerSearch, LevelIsOneWhereTheSpacingAndImageAllowIt) {
  TrackerParams params;  // min_distance 15 px
  EXPECT_EQ(cornerSearchLevel({640, 480}, 4, params), 1);
  EXPECT_EQ(cornerSearchLevel({320, 240}, 4, params), 1);
  EXPECT_EQ(cornerSearchLevel({640, 480}, 0, params), 0);  // no coarser level built
  EXPECT_EQ(cornerSearchLevel({21, 480}, 4, params), 0);   // level 1 narrower than 11 px
  EXPECT_EQ(cornerSearchLevel({22, 22}, 4, params), 1);
  params.min_distance_px = 7.9;  // 3.95 px on level 1: the spacing would lose its meaning
  EXPECT_EQ(cornerSearchLevel({640, 480}, 4, params), 0);
  params.min_distance_px = 100;  // never coarser than level 1
  EXPECT_EQ(cornerSearchLevel({640, 480}, 4, params), 1);
}

TEST(CornerSearch, KeepApartKeepsTheFirstOfCloseCorners) {
  std::vector<cv::Point2f> corners{{0, 0}, {10, 0}, {20, 0}, {5, 5}, {40, 0}, {50, 0}};
  EXPECT_EQ(keepApart(corners, {}, 15.0, 100), 3);
  EXPECT_EQ(corners, (std::vector<cv::Point2f>{{0, 0}, {20, 0}, {40, 0}}));

  corners = {{0, 0}, {20, 0}, {40, 0}, {60, 0}};
  EXPECT_EQ(keepApart(corners, {{41, 3}}, 15.0, 100), 1);  // the live point takes (40, 0)
  EXPECT_EQ(corners, (std::vector<cv::Point2f>{{0, 0}, {20, 0}, {60, 0}}));

  corners = {{0, 0}, {20, 0}, {40, 0}, {60, 0}};
  EXPECT_EQ(keepApart(corners, {}, 15.0, 2), 2);  // at most `wanted`, strongest first
  EXPECT_EQ(corners, (std::vector<cv::Point2f>{{0, 0}, {20, 0}}));

  corners = {{0, 0}, {15, 0}};  // exactly min_distance apart is apart
  EXPECT_EQ(keepApart(corners, {}, 15.0, 10), 0);
}

// cornerSubPix puts a blurred square's far corners 0.15 px inside (measured alike at
// either level): 0.25 px is the refinement's own accuracy.
TEST(CornerSearch, CoarseLevelFindsTheTrueCornersAsWellAsFullResolution) {
  const Squares truth = squares({640, 480});
  int levels = 0;
  const std::vector<cv::Mat> pyramid = pyramidOf(truth.image, &levels);
  ASSERT_GE(levels, 1);
  TrackerParams params;
  CornerSearchBuffers buffers;
  const std::vector<cv::Point2f> coarse =
      findCorners(truth.image, pyramid[2], 1, {}, 50, params, buffers, &pyramid[1]);
  ASSERT_EQ(coarse.size(), 50u);
  for (const auto& c : coarse) EXPECT_LT(nearest(c, truth.corners), 0.25) << c;
  for (size_t i = 0; i < coarse.size(); ++i)
    for (size_t j = i + 1; j < coarse.size(); ++j)
      EXPECT_GE(cv::norm(coarse[i] - coarse[j]), params.min_distance_px);

  // Full resolution (level 0) finds corners just as true, the same ones when all are wanted.
  const std::vector<cv::Point2f> fine =
      findCorners(truth.image, truth.image, 0, {}, 1000, params, buffers);
  ASSERT_EQ(fine.size(), truth.corners.size());
  for (const auto& c : fine) EXPECT_LT(nearest(c, truth.corners), 0.25) << c;
  // The same refined places either way.
  for (const auto& c : coarse) EXPECT_LT(nearest(c, fine), 0.01) << c;
}

TEST(CornerSearch, LivePointsMaskTheSearch) {
  const Squares truth = squares({320, 240});
  int levels = 0;
  const std::vector<cv::Mat> pyramid = pyramidOf(truth.image, &levels);
  TrackerParams params;
  CornerSearchBuffers buffers;
  // Live points on every corner of the top row of squares.
  std::vector<cv::Point2f> live;
  for (const auto& c : truth.corners)
    if (c.y < 40) live.push_back(c);
  ASSERT_GT(live.size(), 4u);
  const auto& corners = findCorners(truth.image, pyramid[2], 1, live, 500, params, buffers);
  ASSERT_FALSE(corners.empty());
  for (const auto& c : corners) {
    EXPECT_LT(nearest(c, truth.corners), 0.25);
    EXPECT_GE(nearest(c, live), params.min_distance_px) << c;
  }
  // Every corner not masked is found: the squares are 20 px, more than 15 px apart.
  EXPECT_EQ(corners.size(), truth.corners.size() - live.size());
}

TEST(CornerSearch, NothingWantedOrNothingToFind) {
  TrackerParams params;
  CornerSearchBuffers buffers;
  const cv::Mat flat(240, 320, CV_8UC1, cv::Scalar(90));
  EXPECT_TRUE(findCorners(flat, flat, 0, {}, 50, params, buffers).empty());
  const Squares truth = squares({320, 240});
  EXPECT_TRUE(findCorners(truth.image, truth.image, 0, {}, 0, params, buffers).empty());
}

TEST(CornerSearch, ShiTomasiScoreMatchesOpenCVsMinEigenValue) {
  // cornerMinEigenVal uses Sobel derivatives scaled by 1/(4 * 255 * block): the score of
  // the Scharr derivatives differs by a constant factor, so the order is the same.
  const Squares truth = squares({320, 240});
  cv::Mat derivatives(truth.image.size(), CV_16SC2);
  cv::Mat dx, dy;
  cv::Sobel(truth.image, dx, CV_16S, 1, 0, 3);
  cv::Sobel(truth.image, dy, CV_16S, 0, 1, 3);
  cv::merge(std::vector<cv::Mat>{dx, dy}, derivatives);
  cv::Mat eig;
  cv::cornerMinEigenVal(truth.image, eig, 3, 3);
  const double scale = 1.0 / (4.0 * 255.0 * 3.0);
  for (const cv::Point p : {cv::Point(60, 60), cv::Point(59, 40), cv::Point(40, 40), cv::Point(100, 15),
                            cv::Point(49, 49), cv::Point(90, 40)}) {
    const double ours = shiTomasiScore(derivatives, p, 3) * scale * scale;
    EXPECT_NEAR(ours, eig.at<float>(p), 1e-4 + 1e-3 * eig.at<float>(p)) << p;
  }
  // A corner scores high, an edge and a flat area do not.
  EXPECT_GT(shiTomasiScore(derivatives, truth.corners[0], 3), 1e4);
  EXPECT_LT(shiTomasiScore(derivatives, {50, 30}, 3), 1.0);   // flat
  EXPECT_LT(shiTomasiScore(derivatives, {50, 60}, 3), 1e-6 + shiTomasiScore(derivatives, truth.corners[0], 3) / 100);  // edge
}

namespace {

// Squares on the left half; on the right half a checkerboard of 2 px cells and
// `contrast` grey levels, which pyrDown averages down to 1/16 of its contrast (1/256 of
// the corner score): its corners are strong at full resolution only.
cv::Mat squaresAndFineCheckerboard(int contrast) {
  cv::Mat image = squares({640, 480}).image;
  image.colRange(320, 640).setTo(40);
  for (int y = 40; y < 440; ++y)
    for (int x = 360; x < 600; ++x)
      if ((x / 2 + y / 2) % 2) image.at<uchar>(y, x) = static_cast<uchar>(40 + contrast);
  return image;
}

}  // namespace

TEST(CornerSearch, FullResolutionFillsWhatTheCoarseLevelLacks) {
  const cv::Mat image = squaresAndFineCheckerboard(160);
  int levels = 0;
  const std::vector<cv::Mat> pyramid = pyramidOf(image, &levels);
  TrackerParams params;
  CornerSearchBuffers buffers;
  const auto& corners = findCorners(image, pyramid[2], 1, {}, 400, params, buffers, &pyramid[1]);
  // The fill's corners come last: all on the checkerboard (the coarse level sees only
  // its outline's four corners).
  EXPECT_GT(buffers.from_full_resolution, 100);
  ASSERT_LE(buffers.from_full_resolution, static_cast<int>(corners.size()));
  for (size_t i = corners.size() - buffers.from_full_resolution; i < corners.size(); ++i)
    EXPECT_TRUE(cv::Rect(358, 38, 244, 404).contains(corners[i])) << corners[i];
  int coarse_on_board = 0;
  for (size_t i = 0; i < corners.size() - buffers.from_full_resolution; ++i)
    coarse_on_board += corners[i].x > 340;
  EXPECT_LE(coarse_on_board, 4);
  for (size_t i = 0; i < corners.size(); ++i)
    for (size_t j = i + 1; j < corners.size(); ++j)
      EXPECT_GE(cv::norm(corners[i] - corners[j]), params.min_distance_px);
}

TEST(CornerSearch, FillKeepsTheQualityBarOfTheWholeImage) {
  // A faint checkerboard (2 grey levels) scores far below 1 % of the squares' corners:
  // a search of the whole image would not take it, nor does the fill.
  const cv::Mat image = squaresAndFineCheckerboard(2);
  int levels = 0;
  const std::vector<cv::Mat> pyramid = pyramidOf(image, &levels);
  TrackerParams params;
  CornerSearchBuffers buffers;
  const auto& corners = findCorners(image, pyramid[2], 1, {}, 400, params, buffers, &pyramid[1]);
  ASSERT_FALSE(corners.empty());
  for (const auto& c : corners) EXPECT_LT(c.x, 340) << c;
  EXPECT_EQ(buffers.from_full_resolution, 0);
}

// The live points mask the strongest corners: the quality bar of a full-resolution
// search is that of the whole image (quality_level x the best corner found or live), as
// the paper's unmasked search has it, not the best unmasked corner's. Faint squares
// (contrast 8 instead of 160: 0.25 % of the strong corners' score) beside live strong
// ones get no corner; at contrast 40 (6 %) they do.
TEST(CornerSearch, MaskedSearchKeepsTheQualityBarOfTheLivePoints) {
  const Squares strong = squares({640, 240});
  auto search = [&](double faint_gain) {
    cv::Mat image = strong.image.clone();
    cv::Mat right = image(cv::Rect(320, 0, 320, 240));
    right.convertTo(right, CV_8U, faint_gain, 40 * (1 - faint_gain));
    int levels = 0;
    const std::vector<cv::Mat> pyramid = pyramidOf(image, &levels);
    std::vector<cv::Point2f> live;
    for (const auto& c : strong.corners)
      if (c.x < 320) live.push_back(c);
    TrackerParams params;
    CornerSearchBuffers buffers;
    const std::vector<cv::Point2f> found =
        findCorners(image, image, 0, live, 100, params, buffers, &pyramid[1]);
    for (const auto& c : found) EXPECT_LT(nearest(c, strong.corners), 0.5) << c;
    return std::count_if(found.begin(), found.end(),
                         [](const cv::Point2f& c) { return c.x > 320; });
  };
  EXPECT_EQ(search(0.05), 0);
  EXPECT_GE(search(0.25), 20);
}

TEST(CornerSearch, SpreadOverCellsServesTheCellWithFewestPointsFirst) {
  // Strongest first: three corners in the cell at the origin, then two in the next one.
  const std::vector<cv::Point2f> input{{10, 10}, {30, 10}, {50, 10}, {110, 10}, {130, 10}};
  std::vector<cv::Point2f> corners = input;
  spreadOverCells(corners, {}, {200, 100}, 100, 4);
  EXPECT_EQ(corners, (std::vector<cv::Point2f>{{10, 10}, {110, 10}, {30, 10}, {130, 10}}));
  // Live points count: the second cell holds two already, so the first gives two first.
  corners = input;
  spreadOverCells(corners, {{150, 50}, {160, 60}}, {200, 100}, 100, 3);
  EXPECT_EQ(corners, (std::vector<cv::Point2f>{{10, 10}, {30, 10}, {50, 10}}));
  // Fewer corners than wanted: all of them, spread.
  corners = input;
  spreadOverCells(corners, {}, {200, 100}, 100, 50);
  EXPECT_EQ(corners.size(), input.size());
  // cell_px 0: strongest first, only truncated.
  corners = input;
  spreadOverCells(corners, {}, {200, 100}, 0, 2);
  EXPECT_EQ(corners, (std::vector<cv::Point2f>{{10, 10}, {30, 10}}));
}

TEST(CornerSearch, AWeaklyTexturedHalfGetsCornersWhenSpread) {
  // Left half: strong squares; right half: faint ones (contrast 40 instead of 160, score
  // 6 % of the strong ones: above the 1 % quality bar).
  const Squares strong = squares({640, 240});
  cv::Mat image = strong.image.clone();
  cv::Mat right = image(cv::Rect(320, 0, 320, 240));
  right.convertTo(right, CV_8U, 0.25, 30);
  int levels = 0;
  const std::vector<cv::Mat> pyramid = pyramidOf(image, &levels);
  TrackerParams params;
  CornerSearchBuffers buffers;
  auto on_right = [](const std::vector<cv::Point2f>& corners) {
    return std::count_if(corners.begin(), corners.end(),
                         [](const cv::Point2f& c) { return c.x > 320; });
  };
  params.spread_grid_columns = 0;  // strongest first: every corner on the strong half
  EXPECT_EQ(on_right(findCorners(image, pyramid[2], 1, {}, 20, params, buffers, &pyramid[1])), 0);
  params.spread_grid_columns = 8;
  const std::vector<cv::Point2f> spread =
      findCorners(image, pyramid[2], 1, {}, 20, params, buffers, &pyramid[1]);
  EXPECT_EQ(spread.size(), 20u);
  EXPECT_GE(on_right(spread), 8);
  for (const auto& c : spread) EXPECT_LT(nearest(c, strong.corners), 0.3) << c;
}

// The grid has the same columns at any resolution: a camera of twice the resolution
// gets cells of twice the side, not four times as many.
TEST(CornerSearch, SpreadCellFollowsTheImageSize) {
  EXPECT_EQ(spreadCellPx({640, 480}, 8), 80.0);
  EXPECT_EQ(spreadCellPx({1280, 960}, 8), 160.0);
  EXPECT_EQ(spreadCellPx({640, 480}, 0), 0.0);  // off: the paper's strongest first
  EXPECT_EQ(spreadCellPx({}, 8), 0.0);
}

TEST(CornerSearch, SpreadOverTinyCellsIsBounded) {
  // A cell side far below a pixel is taken as 8 px: no grid of billions of cells.
  std::vector<cv::Point2f> corners{{1, 1}, {2, 2}, {100, 100}};
  spreadOverCells(corners, {}, {640, 480}, 1e-6, 3);
  EXPECT_EQ(corners, (std::vector<cv::Point2f>{{1, 1}, {100, 100}, {2, 2}}));
}

namespace {

// White noise of sigma grey levels added to an image (seeded).
cv::Mat withNoise(const cv::Mat& image, double sigma, unsigned seed) {
  cv::Mat noise(image.size(), CV_32F), out;
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0, sigma);
  image.convertTo(out, CV_32F);
  out += noise;
  out.convertTo(out, CV_8U);
  return out;
}

int insideCount(const std::vector<cv::Point2f>& corners, const cv::Rect& region) {
  return static_cast<int>(std::count_if(corners.begin(), corners.end(), [&](const cv::Point2f& c) {
    return region.contains(cv::Point(cvRound(c.x), cvRound(c.y)));
  }));
}

}  // namespace

// The noise level is the flattest cell's: texture on three quarters of the image does
// not raise it, it follows the noise's sigma, and a clipped region is left out.
TEST(CornerSearch, NoiseLevelIsTheFlattestCellsNoise) {
  const cv::Mat flat(480, 640, CV_8UC1, cv::Scalar(100));
  const double plain = noiseLevel(withNoise(flat, 2, 1), 80);
  // 6 sigma x 0.6745 (the median of a normal's magnitude) for white noise.
  EXPECT_NEAR(plain, 6 * 0.6745 * 2, 0.1 * plain);
  cv::Mat textured = squares({640, 480}).image;
  flat(cv::Rect(0, 0, 160, 480)).copyTo(textured(cv::Rect(0, 0, 160, 480)));
  EXPECT_NEAR(noiseLevel(withNoise(textured, 2, 2), 80), plain, 0.1 * plain);
  EXPECT_NEAR(noiseLevel(withNoise(flat, 4, 3), 80), 2 * plain, 0.2 * plain);
  cv::Mat clipped = withNoise(flat, 2, 4);
  clipped(cv::Rect(0, 0, 320, 480)).setTo(255);
  EXPECT_NEAR(noiseLevel(clipped, 80), plain, 0.1 * plain);
  EXPECT_EQ(noiseLevel(flat, 80), 0.0);  // no noise to measure
  // The floor follows the noise's variance.
  EXPECT_NEAR(noiseCornerFloor(withNoise(flat, 4, 5), 0, 3, 80),
              4 * noiseCornerFloor(withNoise(flat, 2, 6), 0, 3, 80),
              0.4 * noiseCornerFloor(withNoise(flat, 4, 5), 0, 3, 80));
}

// Without a noise floor the candidates are goodFeaturesToTrack's, in its order.
TEST(CornerSearch, CandidatesWithoutAFloorAreGoodFeaturesToTrack) {
  const cv::Mat image = withNoise(squares({320, 240}).image, 2, 7);
  std::vector<cv::Point2f> opencv, ours;
  cv::goodFeaturesToTrack(image, opencv, 0, 0.01, 10.0, cv::noArray(), 3);
  ShiTomasiBuffers buffers;
  std::vector<uchar> relaxed;
  shiTomasiCandidates(image, cv::Mat(), 0.01, 0.0, 40, 10.0, 3, 0, buffers, ours, relaxed);
  ASSERT_GT(opencv.size(), 50u);
  EXPECT_EQ(ours, opencv);
  EXPECT_TRUE(relaxed.empty());
  opencv.resize(20);  // at most max_corners, the strongest
  shiTomasiCandidates(image, cv::Mat(), 0.01, 0.0, 40, 10.0, 3, 20, buffers, ours, relaxed);
  EXPECT_EQ(ours, opencv);
  // Without noise the squares' corners have equal responses: ties broken as OpenCV does.
  const cv::Mat clean = squares({320, 240}).image;
  cv::goodFeaturesToTrack(clean, opencv, 0, 0.01, 10.0, cv::noArray(), 3);
  shiTomasiCandidates(clean, cv::Mat(), 0.01, 0.0, 40, 10.0, 3, 0, buffers, ours, relaxed);
  ASSERT_GT(opencv.size(), 50u);
  EXPECT_EQ(ours, opencv);
}

// Issue 18: a weakly textured patch beside a richly textured one (squares of 10 grey
// levels against 160: 0.4 % of the strong corners' score, under the image's 1 % bar) gets
// corners from its cells' own bar, on its true corners; a flat patch with the same noise
// gets none (the noise floor), nor does it at three times the noise.
TEST(CornerSearch, AWeakPatchGetsCornersAndAFlatNoisyPatchNone) {
  const Squares rich = squares({640, 480});
  cv::Mat image = rich.image.clone();
  const cv::Rect weak(320, 0, 160, 480), flat(480, 0, 160, 480);
  image(weak).convertTo(image(weak), CV_8U, 10.0 / 160.0, 40 - 40 * 10.0 / 160.0);
  image(flat).setTo(40);
  for (const double sigma : {2.0, 6.0}) {
    const cv::Mat noisy = withNoise(image, sigma, 8);
    int levels = 0;
    const std::vector<cv::Mat> pyramid = pyramidOf(noisy, &levels);
    TrackerParams params;
    CornerSearchBuffers buffers;
    params.corner_noise_margin = 0;  // the image's bar alone: nothing on the weak patch
    if (sigma == 2.0) {
      EXPECT_EQ(insideCount(
                    findCorners(noisy, pyramid[2], 1, {}, 150, params, buffers, &pyramid[1]), weak),
                0);
    }
    params = TrackerParams();
    params.corner_noise_margin = 2;  // the cells' own bars (off by default)
    const std::vector<cv::Point2f> corners =
        findCorners(noisy, pyramid[2], 1, {}, 150, params, buffers, &pyramid[1]);
    EXPECT_EQ(insideCount(corners, flat), 0) << "sigma " << sigma;
    if (sigma > 2) continue;  // (three times the noise drowns the 10 grey levels)
    const int on_weak = insideCount(corners, weak);
    EXPECT_GE(on_weak, 20);  // (measured 46 of its 96 corners)
    // On the squares' corners, not on the noise between them (30 px of flat paint): 10
    // grey levels under noise of 2 place them within a pixel, a few within 4.
    int within_1px = 0;
    for (const auto& c : corners) {
      if (!weak.contains(cv::Point(cvRound(c.x), cvRound(c.y)))) continue;
      EXPECT_LT(nearest(c, rich.corners), 4.0) << c;
      within_1px += nearest(c, rich.corners) < 1.0;
    }
    EXPECT_GE(within_1px, 0.8 * on_weak);
    EXPECT_TRUE(buffers.relaxed.contains({400, 240}));
  }
}

// cornerResponseRows: bands of rows of the response, on the images a spread search keeps
// (pyramid levels, whose rows beyond the image are its border), are bit for bit the whole
// response, for any block size and number of bands; rows outside the band are untouched.
TEST(CornerSearch, ResponseRowsInBandsAreTheWholeImagesResponse) {
  const cv::Mat image = squares({640, 480}).image;
  std::vector<cv::Mat> pyramid;
  cv::buildOpticalFlowPyramid(image, pyramid, cv::Size(7, 7), 2);
  cv::Mat whole, banded, work;
  for (int level = 0; level <= 2; ++level) {
    const cv::Mat& level_image = pyramid[2 * level];
    for (const int block : {1, 2, 3, 4, 7, 31}) {
      cv::cornerMinEigenVal(level_image, whole, block, 3);
      for (const int bands : {1, 3, 8}) {
        banded = cv::Mat(level_image.size(), CV_32FC1, cv::Scalar(-1));
        for (int b = 0; b < bands; ++b)
          cornerResponseRows(level_image, block, bandTop(b, level_image.rows, bands),
                             bandTop(b + 1, level_image.rows, bands), banded, work);
        EXPECT_EQ(cv::norm(whole, banded, cv::NORM_INF), 0.0)
            << "level " << level << ", block " << block << ", " << bands << " bands";
      }
    }
  }
  // One band: only its rows are written.
  banded = cv::Mat(image.size(), CV_32FC1, cv::Scalar(-1));
  cornerResponseRows(image, 3, 100, 200, banded, work);
  EXPECT_EQ(banded.at<float>(99, 320), -1.f);
  EXPECT_EQ(banded.at<float>(200, 320), -1.f);
  EXPECT_NE(banded.at<float>(150, 320), -1.f);
}

// A response given to shiTomasiCandidates is used instead of computing one: the same
// corners as computing it; zeros given give none (the test can fail); one of another size
// is not used.
TEST(CornerSearch, AGivenResponseIsUsedInsteadOfComputingIt) {
  const cv::Size size(640, 480);
  const cv::Mat image = squares(size).image;
  ShiTomasiBuffers buffers;
  std::vector<cv::Point2f> expected, corners;
  std::vector<uchar> relaxed;
  shiTomasiCandidates(image, cv::Mat(), 0.01, 0, 0, 15, 3, 0, buffers, expected, relaxed);
  ASSERT_GT(expected.size(), 50u);
  cv::Mat response, work;
  cornerResponseRows(image, 3, 0, size.height, response, work);
  shiTomasiCandidates(image, cv::Mat(), 0.01, 0, 0, 15, 3, 0, buffers, corners, relaxed,
                      &response);
  EXPECT_EQ(corners, expected);
  cv::Mat zeros = cv::Mat::zeros(size, CV_32FC1);
  shiTomasiCandidates(image, cv::Mat(), 0.01, 0, 0, 15, 3, 0, buffers, corners, relaxed, &zeros);
  EXPECT_TRUE(corners.empty());
  cv::Mat small = cv::Mat::zeros(10, 10, CV_32FC1);
  shiTomasiCandidates(image, cv::Mat(), 0.01, 0, 0, 15, 3, 0, buffers, corners, relaxed, &small);
  EXPECT_EQ(corners, expected);
}
