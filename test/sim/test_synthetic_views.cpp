#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "mono_plane_detection/sim/synthetic_views.h"

using namespace mono_plane_detection;

TEST(SyntheticViews, TextureIsDeterministicAndCornerRich) {
  const cv::Mat a = makeCornerTexture({400, 300}, 7);
  const cv::Mat b = makeCornerTexture({400, 300}, 7);
  const cv::Mat c = makeCornerTexture({400, 300}, 8);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, c, cv::NORM_L1), 0.0);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(a, corners, 200, 0.01, 15);
  EXPECT_GE(corners.size(), 150u);
}

TEST(SyntheticViews, WarpMatchesTransfer) {
  const cv::Mat texture = makeCornerTexture({400, 300}, 1);
  const cv::Matx33d H = similarity(0.1, {200, 150}, {5.5, -3.25}, 1.1);
  const cv::Mat view = warpView(texture, H, {400, 300});
  // A pixel of the texture appears where transfer() says, within interpolation error.
  const cv::Matx33d Hinv = H.inv();
  double total = 0;
  int n = 0;
  for (int y = 100; y < 200; y += 7) {
    for (int x = 120; x < 280; x += 7) {
      const cv::Point2d src = transfer(Hinv, {double(x), double(y)});
      cv::Mat patch;
      cv::getRectSubPix(texture, {1, 1}, cv::Point2f(src), patch);
      total += std::abs(int(view.at<uchar>(y, x)) - int(patch.at<uchar>(0, 0)));
      ++n;
    }
  }
  EXPECT_LT(total / n, 2.0);
}

TEST(SyntheticViews, SimilarityAndTransfer) {
  const cv::Matx33d H = similarity(CV_PI / 2, {0, 0}, {10, 0});
  const cv::Point2d p = transfer(H, {1, 0});
  EXPECT_NEAR(p.x, 10.0, 1e-12);
  EXPECT_NEAR(p.y, 1.0, 1e-12);
  const cv::Matx33d S = similarity(0, {5, 5}, {0, 0}, 2.0);
  const cv::Point2d q = transfer(S, {6, 5});
  EXPECT_NEAR(q.x, 7.0, 1e-12);
  EXPECT_NEAR(q.y, 5.0, 1e-12);
}
