// Least-squares homography between two point sets and its transfer error.
#pragma once

#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace mono_plane_detection {

// Normalised DLT (Hartley): both sets moved to zero mean and mean distance sqrt(2),
// the 9x9 normal matrix of the DLT rows solved for its smallest eigenvector, optionally
// weighted per point. Nothing when fewer than 4 points, weights do not match, or the
// points are degenerate. (cv::findHomography has no weights and costs ~10x more on the
// 5-point groups this is called for hundreds of times per image.)
std::optional<cv::Matx33d> fitHomography(const std::vector<cv::Point2d>& from,
                                         const std::vector<cv::Point2d>& to,
                                         const std::vector<double>& weights = {});

// transferError(H, from, to) < threshold_px without its square root and divisions
// (|H from - w to| < t |w|, w the homogeneous scale): the test of the vote, inliersOf and
// the floor search, run for every point and candidate.
inline bool transfersWithin(const cv::Matx33d& H, const cv::Point2d& from, const cv::Point2d& to,
                            double threshold_px) {
  const double w = H(2, 0) * from.x + H(2, 1) * from.y + H(2, 2);
  const double dx = (H(0, 0) * from.x + H(0, 1) * from.y + H(0, 2)) - to.x * w;
  const double dy = (H(1, 0) * from.x + H(1, 1) * from.y + H(1, 2)) - to.y * w;
  return std::abs(w) >= 1e-12 && dx * dx + dy * dy < threshold_px * threshold_px * (w * w);
}

// transferError squared (no square root: order statistics of residuals); infinity when H
// sends the point to infinity.
inline double transferErrorSquared(const cv::Matx33d& H, const cv::Point2d& from,
                                   const cv::Point2d& to) {
  const double w = H(2, 0) * from.x + H(2, 1) * from.y + H(2, 2);
  if (std::abs(w) < 1e-12) return std::numeric_limits<double>::infinity();
  const double x = (H(0, 0) * from.x + H(0, 1) * from.y + H(0, 2)) / w;
  const double y = (H(1, 0) * from.x + H(1, 1) * from.y + H(1, 2)) / w;
  const double dx = x - to.x, dy = y - to.y;
  return dx * dx + dy * dy;
}

// The same squared error as |H from - w to|^2 / w^2 (one division; w the third
// coordinate of H from): the noise scale's, the criterion's and the refits' form (its
// last bits differ from transferErrorSquared's, and the labels were measured with each
// where it is used); infinity when H sends the point to infinity.
inline double transferErrorSquaredOneDivision(const cv::Matx33d& H, const cv::Point2d& from,
                                              const cv::Point2d& to) {
  const double w = H(2, 0) * from.x + H(2, 1) * from.y + H(2, 2);
  const double dx = (H(0, 0) * from.x + H(0, 1) * from.y + H(0, 2)) - to.x * w;
  const double dy = (H(1, 0) * from.x + H(1, 1) * from.y + H(1, 2)) - to.y * w;
  const double e2 = (dx * dx + dy * dy) / (w * w);
  return std::abs(w) >= 1e-12 ? e2 : std::numeric_limits<double>::infinity();  // a select
}

// Distance in pixels between H * from and to (the paper's vote criterion); infinity
// when H sends the point to infinity. Inline: the vote calls it N x candidates times.
inline double transferError(const cv::Matx33d& H, const cv::Point2d& from, const cv::Point2d& to) {
  return std::sqrt(transferErrorSquared(H, from, to));  // not std::hypot: slow, and pixels do not overflow
}

}  // namespace mono_plane_detection
