// Two views of a scene of planes with exact ground truth, for tests and benchmarks of
// the plane core: physically consistent homographies (H = K (R - t n^T / d) K^-1),
// pixel noise and gross outliers.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mono_plane_detection {

struct TwoViewSceneParams {
  int planes = 3;  // 1..6, each seen in its own vertical strip of view 1
  int points_per_plane = 60;
  double outlier_fraction = 0.2;  // share of all points that are random pairs
  double noise_px = 0.7;          // Gaussian pixel noise in both views
  cv::Size image{640, 480};
  double focal_px = 525.0;
  double baseline_m = 0.5;  // camera 2 moves this far (planes are 2-6 m away)
  // Planes are redrawn until their homographies differ by at least this much (median
  // over both strips): closer planes cannot be told apart at a few px of noise.
  double min_separation_px = 10.0;
  unsigned seed = 1;
};

struct TwoViewScene {
  std::vector<cv::Point2d> view1, view2;
  std::vector<int> labels;                // 0 = outlier, k >= 1 = plane k
  std::vector<cv::Matx33d> homographies;  // view 1 -> view 2, plane k at [k-1]
};

TwoViewScene makeTwoViewScene(const TwoViewSceneParams& params);

// The labels an oracle gives that knows the true homographies: each point to the plane
// whose homography transfers it best, 0 beyond threshold_px. Its misclassification is
// what noise makes unavoidable (points near where two planes meet).
std::vector<int> bestPossibleLabels(const TwoViewScene& scene, double threshold_px);

}  // namespace mono_plane_detection
