// The baseline finds the planes of a clean two-plane scene, and stops at min_support.
#include "mono_plane_detection/eval/sequential_magsac.h"

#include <gtest/gtest.h>

#include "mono_plane_detection/eval/segmentation_error.h"
#include "mono_plane_detection/sim/synthetic_two_view.h"

using namespace mono_plane_detection;

TEST(SequentialMagsac, FindsTheTwoPlanesOfACleanScene) {
  std::vector<cv::Point2d> a, b;
  std::vector<int> truth;
  const cv::Matx33d H1(1.02, 0.01, 5, 0, 1.0, -3, 0, 0, 1), H2(0.9, 0.05, 40, -0.04, 1.1, 10, 1e-4, 0, 1);
  for (int i = 0; i < 60; ++i) {
    const cv::Point2d p(20 + (i % 10) * 30, 20 + (i / 10) * 30), q(400 + (i % 10) * 25, 40 + (i / 10) * 40);
    for (const auto& [pt, H, label] : {std::make_tuple(p, H1, 1), std::make_tuple(q, H2, 2)}) {
      const cv::Vec3d x = H * cv::Vec3d(pt.x, pt.y, 1);
      a.push_back(pt);
      b.emplace_back(x[0] / x[2], x[1] / x[2]);
      truth.push_back(label);
    }
  }
  const std::vector<int> labels = sequentialMagsac(a, b, 1.0, 10, 5);
  EXPECT_LT(misclassificationError(truth, labels), 0.02);
  // Fewer points than min_support: no plane at all.
  const std::vector<int> none = sequentialMagsac(a, b, 1.0, 1000, 5);
  EXPECT_EQ(misclassificationError(std::vector<int>(a.size(), 0), none), 0.0);
}
