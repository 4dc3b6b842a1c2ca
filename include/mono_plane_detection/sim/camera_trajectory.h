// The camera of a synthetic sequence and how it moves: a pinhole with optional radial
// distortion, and the paths of a wheeled robot, a walking (humanoid) robot and a pure
// rotation in place (the paper's hard case), and two that turn a lot while moving little:
// a wheeled robot turning on the spot and a humanoid looking around as it walks slowly.
// ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "mono_plane_detection/geometry/camera_model.h"
#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

struct TrajectoryParams {
  // wheeled | humanoid | rotation | turn_in_place | look_around
  std::string name = "wheeled";
  double speed_mps = 0.3;              // forward speed (wheeled, humanoid)
  double turn_deg = 150;               // total left turn over the sequence (wheeled, humanoid)
  double duration_s = 10;              // the turn is spread over this time
  double camera_height_m = 0.8;        // humanoid adds 0.4 m
  double pitch_down_deg = 10;          // camera tilt towards the floor
  double rotation_amplitude_deg = 60;  // rotation: yaw swings +- this, in place
  unsigned seed = 1;                   // humanoid jerks
  // turn_in_place: the robot turns by turn_deg on the spot; the camera sits this far
  // ahead of the turning axis, so it moves on a small arc (0.39 m for 150 deg).
  double camera_forward_m = 0.15;
  // look_around: a humanoid walking at a third of speed_mps whose head swings its yaw
  // by +- this with this period.
  double look_amplitude_deg = 35;
  double look_period_s = 4;
};

// The names trajectoryPose knows.
bool knownTrajectory(const std::string& name);

// world_from_camera at time t (s) with t = 0 the start: in front of the target, looking
// along +y. Smooth in t except for the humanoid's jerks.
Pose trajectoryPose(const TrajectoryParams& params, double t);

// The camera orientation for heading yaw (rad, 0 = +y, positive turns left), pitch down
// and roll (rad): columns are the optical axes x right, y down, z forward in the world.
cv::Matx33d cameraOrientation(double yaw, double pitch_down, double roll);

}  // namespace mono_plane_detection
