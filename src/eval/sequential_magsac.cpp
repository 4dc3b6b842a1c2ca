#include "mono_plane_detection/eval/sequential_magsac.h"

#include <opencv2/calib3d.hpp>

#include "mono_plane_detection/geometry/opencv_usac.h"

namespace mono_plane_detection {

namespace {
#if MPD_HAVE_USAC
constexpr int kMethod = cv::USAC_MAGSAC;
#else
constexpr int kMethod = cv::RANSAC;
#endif
}  // namespace

std::vector<int> sequentialMagsac(const std::vector<cv::Point2d>& a,
                                  const std::vector<cv::Point2d>& b, double threshold,
                                  int min_support, int max_planes) {
  std::vector<int> labels(a.size(), 0), remaining(a.size());
  for (size_t i = 0; i < a.size(); ++i) remaining[i] = static_cast<int>(i);
  for (int plane = 1; plane <= max_planes && static_cast<int>(remaining.size()) >= min_support;
       ++plane) {
    std::vector<cv::Point2d> ra, rb;
    for (int i : remaining) {
      ra.push_back(a[i]);
      rb.push_back(b[i]);
    }
    cv::Mat mask;
    const cv::Mat H = cv::findHomography(ra, rb, kMethod, threshold, mask, 1000, 0.99);
    if (H.empty() || cv::countNonZero(mask) < min_support) break;
    std::vector<int> rest;
    for (size_t k = 0; k < remaining.size(); ++k) {
      if (mask.at<uchar>(static_cast<int>(k)))
        labels[remaining[k]] = plane;
      else
        rest.push_back(remaining[k]);
    }
    remaining.swap(rest);
  }
  return labels;
}

}  // namespace mono_plane_detection
