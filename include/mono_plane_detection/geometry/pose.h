// A rigid transform between two frames, named by what it maps: `a_from_b` takes a point
// in frame b to frame a. ROS-free.
#pragma once

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>

#include "mono_plane_detection/geometry/plane_fit.h"

namespace mono_plane_detection {

// X_to = R * X_from + t.
struct Pose {
  cv::Matx33d R = cv::Matx33d::eye();
  cv::Vec3d t{0, 0, 0};
  cv::Vec3d apply(const cv::Vec3d& x) const { return R * x + t; }
  Pose inverse() const { return {R.t(), -(R.t() * t)}; }
  Pose operator*(const Pose& o) const { return {R * o.R, R * o.t + t}; }
};

// The angle (deg) a rotation turns by, from its trace; of a * b.t() it is how far the
// rotations a and b are apart.
inline double rotationAngleDeg(const cv::Matx33d& R) {
  return std::acos(std::max(-1.0, std::min(1.0, (cv::trace(R) - 1) / 2))) * 180.0 / CV_PI;
}

// The angle (deg) between a camera's image up (its -y axis) and the direction `up`, both in
// the frame map_from_camera maps into: 0 for an upright camera, 90 for one rolled on its
// side or looking straight down.
inline double cameraUpAngleDeg(const Pose& map_from_camera, const cv::Vec3d& up) {
  return normalAngleDeg(map_from_camera.R * cv::Vec3d(0, -1, 0), up);
}

}  // namespace mono_plane_detection
