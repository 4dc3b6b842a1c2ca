// The baseline the plane core is measured against: the plane detector a user might pick
// instead. MAGSAC++ homography (cv::findHomography USAC_MAGSAC), remove its inliers,
// repeat while a plane with min_support points is found. (OpenCV before 4.5, as on
// Noetic, has no USAC: plain RANSAC there.)
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mono_plane_detection {

// Labels per point: 0 = no plane, k >= 1 = the k-th homography found.
std::vector<int> sequentialMagsac(const std::vector<cv::Point2d>& a,
                                  const std::vector<cv::Point2d>& b, double threshold,
                                  int min_support, int max_planes);

}  // namespace mono_plane_detection
