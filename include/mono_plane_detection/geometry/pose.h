// A rigid transform between two frames, named by what it maps: `a_from_b` takes a point
// in frame b to frame a. ROS-free.
#pragma once

#include <opencv2/core.hpp>

namespace mono_plane_detection {

// X_to = R * X_from + t.
struct Pose {
  cv::Matx33d R = cv::Matx33d::eye();
  cv::Vec3d t{0, 0, 0};
  cv::Vec3d apply(const cv::Vec3d& x) const { return R * x + t; }
  Pose inverse() const { return {R.t(), -(R.t() * t)}; }
  Pose operator*(const Pose& o) const { return {R * o.R, R * o.t + t}; }
};

}  // namespace mono_plane_detection
