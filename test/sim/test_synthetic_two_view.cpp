#include <gtest/gtest.h>

#include "mono_plane_detection/eval/segmentation_error.h"
#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/sim/synthetic_two_view.h"

using namespace mono_plane_detection;

TEST(SyntheticTwoView, PointsFollowTheirPlanesHomography) {
  TwoViewSceneParams p;
  p.planes = 4;
  p.noise_px = 0.0;
  p.outlier_fraction = 0.25;
  const auto s = makeTwoViewScene(p);
  ASSERT_EQ(s.homographies.size(), 4u);
  ASSERT_EQ(s.view1.size(), s.labels.size());
  int outliers = 0;
  for (size_t i = 0; i < s.labels.size(); ++i) {
    if (s.labels[i] == 0) {
      ++outliers;
      continue;
    }
    EXPECT_LT(transferError(s.homographies[s.labels[i] - 1], s.view1[i], s.view2[i]), 1e-6);
  }
  EXPECT_NEAR(static_cast<double>(outliers) / s.labels.size(), 0.25, 0.01);
  EXPECT_EQ(makeTwoViewScene(p).view2, s.view2);  // deterministic
}

TEST(SyntheticTwoView, PlanesInduceDistinctHomographies) {
  const auto s = makeTwoViewScene(TwoViewSceneParams());
  // A point of plane 1 is far (> 3 px) from where the other planes would send it.
  int checked = 0;
  for (size_t i = 0; i < s.labels.size(); ++i) {
    if (s.labels[i] != 1) continue;
    ++checked;
    double nearest_other = 1e9;
    for (size_t k = 1; k < s.homographies.size(); ++k)
      nearest_other =
          std::min(nearest_other, transferError(s.homographies[k], s.view1[i], s.view2[i]));
    EXPECT_GT(nearest_other, 3.0);
  }
  EXPECT_GT(checked, 20);
}

TEST(BestPossibleLabels, ExactDataIsPerfectNoiseIsNot) {
  TwoViewSceneParams p;
  p.noise_px = 0.0;
  p.outlier_fraction = 0.0;
  auto scene = makeTwoViewScene(p);
  EXPECT_EQ(misclassificationError(scene.labels, bestPossibleLabels(scene, 2.0)), 0.0);
  p.noise_px = 1.0;
  scene = makeTwoViewScene(p);
  const double noisy = misclassificationError(scene.labels, bestPossibleLabels(scene, 4.0));
  EXPECT_GT(noisy, 0.0);  // near the planes' intersections noise decides
  EXPECT_LT(noisy, 0.10);
  // A threshold far below the noise rejects most true points.
  EXPECT_GT(misclassificationError(scene.labels, bestPossibleLabels(scene, 0.5)), 0.5);
}
