#include "mono_plane_detection/tracking/target_startup.h"

namespace mono_plane_detection {

std::optional<TargetDetection> TargetStartup::process(const cv::Mat& gray,
                                                      FeatureTracker& tracker) {
  if (found_) return {};
  TargetDetection target = detectTarget(gray, params_);
  if (!target.found) return {};
  tracker.addPoints({target.corners.begin(), target.corners.end()}, true);
  found_ = true;
  return target;
}

}  // namespace mono_plane_detection
