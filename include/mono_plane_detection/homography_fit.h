// Least-squares homography between two point sets and its transfer error.
#pragma once

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace mono_plane_detection {

// Normalised DLT (Hartley): both sets moved to zero mean and mean distance sqrt(2),
// the 9x9 normal matrix of the DLT rows solved for its smallest eigenvector, optionally
// weighted per point. Nothing when fewer than 4 points, weights do not match, or the
// points are degenerate. (cv::findHomography has no weights and costs ~10x more on the
// 5-point groups this is called for hundreds of times per image.)
std::optional<cv::Matx33d> fitHomography(const std::vector<cv::Point2d>& from,
                                         const std::vector<cv::Point2d>& to,
                                         const std::vector<double>& weights = {});

// Distance in pixels between H * from and to (the paper's vote criterion); infinity
// when H sends the point to infinity.
double transferError(const cv::Matx33d& H, const cv::Point2d& from, const cv::Point2d& to);

}  // namespace mono_plane_detection
