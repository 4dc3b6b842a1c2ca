// The ROS map frame (REP 103: x forward, y left, z up, metres) against the core's map,
// which is the start-up target's frame (x along the target to the right, y up along it,
// z out of the wall towards the camera). With the target mounted upright on a wall, the
// ROS map has z up, x pointing into the target's wall (forward for a camera facing it at
// start) and its origin at the target's centre. Every ROS output (planes, markers, map
// points, camera pose, tf) is given in this frame; the core never sees it.
#pragma once

#include <cmath>
#include <opencv2/core.hpp>

#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

// ros_map_from_target: x' = -z, y' = -x, z' = y (a proper rotation).
inline const Pose& rosMapFromTarget() {
  static const Pose pose{cv::Matx33d(0, 0, -1, -1, 0, 0, 0, 1, 0), {0, 0, 0}};
  return pose;
}

// A pose in the ROS map back in the core's (target) frame: target_from_x.
inline Pose targetFromRosMap(const Pose& ros_map_from_x) {
  return rosMapFromTarget().inverse() * ros_map_from_x;
}

// A plane {x : n . x = distance} of the core's map as shape_msgs/Plane and PCL write it
// in the ROS map: a x + b y + c z + d = 0 with (a, b, c) the rotated unit normal.
struct RosPlane {
  cv::Vec3d normal;
  double d = 0;
};

inline RosPlane toRosPlane(const cv::Vec3d& target_normal, double target_distance) {
  return {rosMapFromTarget().R * target_normal, -target_distance};
}

// What a plane is, from its normal in the ROS map (z against gravity). The normal points
// to the side the plane was seen from: a floor's up, a ceiling's down.
enum class PlaneKind { kOther = 0, kFloor = 1, kWall = 2, kCeiling = 3 };

// Within max_tilt_deg of horizontal (floor, ceiling) or of vertical (wall).
inline PlaneKind planeKind(const cv::Vec3d& ros_normal, double max_tilt_deg = 15.0) {
  const double n = cv::norm(ros_normal);
  if (!(n > 0)) return PlaneKind::kOther;
  const double z = ros_normal[2] / n;
  const double tilt = std::sin(max_tilt_deg * CV_PI / 180.0);
  if (z >= std::cos(max_tilt_deg * CV_PI / 180.0)) return PlaneKind::kFloor;
  if (z <= -std::cos(max_tilt_deg * CV_PI / 180.0)) return PlaneKind::kCeiling;
  if (std::abs(z) <= tilt) return PlaneKind::kWall;
  return PlaneKind::kOther;
}

inline const char* planeKindName(PlaneKind kind) {
  switch (kind) {
    case PlaneKind::kFloor:
      return "floor";
    case PlaneKind::kWall:
      return "wall";
    case PlaneKind::kCeiling:
      return "ceiling";
    default:
      return "other";
  }
}

}  // namespace mono_plane_detection
