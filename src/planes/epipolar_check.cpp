#include "mono_plane_detection/planes/epipolar_check.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>

namespace mono_plane_detection {

std::optional<cv::Matx33d> estimateFundamental(const std::vector<cv::Point2d>& view1,
                                               const std::vector<cv::Point2d>& view2,
                                               double threshold_px, double min_inlier_share,
                                               unsigned seed) {
  if (view1.size() != view2.size() || view1.size() < 15) return std::nullopt;
  cv::theRNG().state = seed;  // findFundamentalMat's RANSAC draws from it: repeatable
  cv::Mat mask;
  const cv::Mat F =
      cv::findFundamentalMat(view1, view2, cv::FM_RANSAC, threshold_px, 0.999, mask);
  if (F.rows != 3 || F.cols != 3) return std::nullopt;  // none, or several solutions
  if (cv::countNonZero(mask) < min_inlier_share * static_cast<double>(view1.size()))
    return std::nullopt;
  return cv::Matx33d(F);
}

double epipolarTransferError(const cv::Matx33d& H, const cv::Matx33d& F,
                             const std::vector<cv::Point2d>& probe) {
  std::vector<double> d;
  d.reserve(probe.size());
  for (const cv::Point2d& p : probe) {
    const cv::Vec3d x(p.x, p.y, 1.0);
    const cv::Vec3d y = H * x;
    const cv::Vec3d line = F * x;
    const double n = std::hypot(line[0], line[1]);
    if (std::abs(y[2]) < 1e-12 || n < 1e-15) continue;
    d.push_back(std::abs(line.dot(y / y[2])) / n);
  }
  if (d.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

double skewSymmetryError(const cv::Matx33d& H, const cv::Matx33d& F) {
  const double nh = cv::norm(H), nf = cv::norm(F);
  if (nh <= 0 || nf <= 0) return 1.0;
  const cv::Matx33d S = (H * (1.0 / nh)).t() * (F * (1.0 / nf));
  const double ns = cv::norm(S);
  if (ns <= 0) return 0.0;
  return cv::norm(S + S.t()) / (2.0 * ns);
}

}  // namespace mono_plane_detection
