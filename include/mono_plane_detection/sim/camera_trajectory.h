// The camera of a synthetic sequence and how it moves: a pinhole with optional radial
// distortion, and the paths of a wheeled robot, a walking (humanoid) robot and a pure
// rotation in place (the paper's hard case). ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "mono_plane_detection/geometry/camera_model.h"
#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

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
