// Paper II-A on the image side: until the start-up target has been found, each image is
// searched for it; its four corners then join the tracker as points flagged as target
// corners (in TargetDetection's order), so the plane stage can place the camera. ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <optional>

#include "mono_plane_detection/tracking/feature_tracker.h"
#include "mono_plane_detection/tracking/target_detector.h"

namespace mono_plane_detection {

class TargetStartup {
 public:
  explicit TargetStartup(const TargetParams& params = TargetParams()) : params_(params) {}

  // Call after tracker.process(gray). Returns the detection on the image where the target
  // is found (once); nothing before and after.
  std::optional<TargetDetection> process(const cv::Mat& gray, FeatureTracker& tracker);

  bool found() const { return found_; }
  void reset() { found_ = false; }  // search again (the tracker was reset)
  const TargetParams& params() const { return params_; }

 private:
  TargetParams params_;
  bool found_ = false;
};

}  // namespace mono_plane_detection
