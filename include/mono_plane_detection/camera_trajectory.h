// The camera of a synthetic sequence and how it moves: a pinhole with optional radial
// distortion, and the paths of a wheeled robot, a walking (humanoid) robot and a pure
// rotation in place (the paper's hard case). ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "mono_plane_detection/indoor_scene.h"

namespace mono_plane_detection {

struct CameraModel {
  cv::Size size{640, 480};
  double fx = 525, fy = 525, cx = 319.5, cy = 239.5;  // pixels
  double k1 = 0, k2 = 0;  // radial distortion (OpenCV's model), 0 = none
  cv::Matx33d K() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }
  cv::Mat distortion() const { return (cv::Mat_<double>(1, 5) << k1, k2, 0, 0, 0); }
  // Pixel of a point in the camera's optical frame (x right, y down, z forward).
  cv::Point2d project(const cv::Vec3d& x_camera) const;
};

struct TrajectoryParams {
  std::string name = "wheeled";        // wheeled | humanoid | rotation
  double speed_mps = 0.3;              // forward speed (wheeled, humanoid)
  double turn_deg = 150;               // total left turn over the sequence (wheeled, humanoid)
  double duration_s = 10;              // the turn is spread over this time
  double camera_height_m = 0.8;        // humanoid adds 0.4 m
  double pitch_down_deg = 10;          // camera tilt towards the floor
  double rotation_amplitude_deg = 60;  // rotation: yaw swings +- this, in place
  unsigned seed = 1;                   // humanoid jerks
};

// world_from_camera at time t (s) with t = 0 the start: in front of the target, looking
// along +y. Smooth in t except for the humanoid's jerks.
Pose trajectoryPose(const TrajectoryParams& params, double t);

// The camera orientation for heading yaw (rad, 0 = +y, positive turns left), pitch down
// and roll (rad): columns are the optical axes x right, y down, z forward in the world.
cv::Matx33d cameraOrientation(double yaw, double pitch_down, double roll);

}  // namespace mono_plane_detection
