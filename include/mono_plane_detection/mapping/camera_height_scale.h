// Metres from the camera's height above the floor (beyond the paper; the monocular
// scale of libviso2): a wheeled robot's camera stays at a known height, so once the
// floor's homography between two views is found, its decomposition gives the motion
// in floor distances (t / d) and the known height d turns it into metres.
// Which plane is the floor (the assumption): of the largest planes of the tracks, the
// one whose normal is closest to the camera's down direction for a nominal downward
// pitch (roll 0), within max_floor_angle_deg, and below the camera. ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

struct FloorParams {
  double camera_height_m = 0;        // optical centre above the floor; 0: unknown
  double pitch_down_deg = 10;        // nominal camera tilt below the horizon
  double max_floor_angle_deg = 25;   // the floor's normal within this of the nominal down
  double min_parallax_deg = 5.0;     // median angle between the floor tracks' two rays
  double min_motion = 0.3;           // camera motion needed, in camera heights
  int min_inliers = 20;              // floor tracks needed
  double max_error_px = 1.0;         // homography RANSAC threshold
  int max_planes = 4;                // largest planes tried for the floor
};

struct FloorStart {
  bool ok = false;
  std::string reason;            // why not, when !ok
  Pose second_from_first;        // metres
  cv::Vec3d down{0, 1, 0};       // first camera frame: unit normal from the camera to the floor
  std::vector<int> floor_points; // indices of the floor's tracks
  double parallax_deg = 0;       // median over the floor's tracks
};

// first/second: undistorted normalised coordinates of the same tracks in two images.
FloorStart floorStart(const std::vector<cv::Point2d>& first,
                      const std::vector<cv::Point2d>& second, double focal_px,
                      const FloorParams& params);

// The map frame the floor defines (core convention, y up): origin on the floor below the
// first camera, y up (against `down`), z backwards along the floor (so the ROS map's x
// is the camera's heading at the start). map_from_first camera.
Pose floorMapFromCamera(const cv::Vec3d& down, double camera_height_m);

}  // namespace mono_plane_detection
