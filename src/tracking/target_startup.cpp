#include "mono_plane_detection/tracking/target_startup.h"

#include <algorithm>
#include <opencv2/video/tracking.hpp>
#include <sstream>
#include <vector>

namespace mono_plane_detection {

void TargetStartup::reset() {
  found_ = false;
  consecutive_ = 0;
  previous_.release();
  last_ = TargetDetection();
}

std::optional<TargetDetection> TargetStartup::process(const cv::Mat& gray, FeatureTracker& tracker,
                                                      double focal_px,
                                                      cv::Point2d principal_px) {
  if (found_) return {};
  TargetDetection target = detectConfiguredTarget(gray, params_, focal_px, principal_px);
  if (!target.found) {
    consecutive_ = 0;
    previous_.release();
    last_ = target;
    return {};
  }
  // Consistent with the previous image: its corners, tracked by Lucas-Kanade into this
  // image, land on this image's corners.
  bool consistent = false;
  if (consecutive_ > 0 && !previous_.empty() && previous_.size() == gray.size()) {
    const std::vector<cv::Point2f> before(last_.corners.begin(), last_.corners.end());
    std::vector<cv::Point2f> after;
    std::vector<uchar> status;
    std::vector<float> error;
    cv::calcOpticalFlowPyrLK(previous_, gray, before, after, status, error, cv::Size(21, 21), 3);
    consistent = true;
    for (int i = 0; i < 4; ++i)
      consistent = consistent && status[i] &&
                   cv::norm(after[i] - target.corners[i]) <= params_.confirm_tolerance_px;
  }
  consecutive_ = consistent ? consecutive_ + 1 : 1;
  previous_ = gray.clone();
  last_ = target;
  if (consecutive_ < std::max(1, params_.confirm_frames)) {
    std::ostringstream why;
    why << "target seen in " << consecutive_ << " of " << params_.confirm_frames
        << " consecutive images needed";
    last_.reason = why.str();
    return {};
  }
  tracker.addPoints({target.corners.begin(), target.corners.end()}, true);
  found_ = true;
  previous_.release();
  return target;
}

}  // namespace mono_plane_detection
