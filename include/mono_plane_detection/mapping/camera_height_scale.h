// Metres from the camera's height above the floor (beyond the paper; the monocular
// scale of libviso2): a wheeled robot's camera stays at a known height, so once the
// floor is found between two views the motion is known in floor distances and the known
// height turns it into metres. The motion's direction comes from every track (essential
// matrix, RANSAC at 3 sigma of the tracks' measured noise), the floor is a plane through
// triangulated tracks (RANSAC, then a least-squares fit to its tracks' image motion).
// Which plane is the floor (the assumption): of the planes whose normal lies within
// max_floor_angle_deg of the camera's down direction for a nominal downward pitch
// (roll 0), below the camera and with no tracks clearly beyond it (the floor is the
// lowest surface), the one whose homography carries the most tracks that the rotation
// alone does not. ROS-free.
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
  double min_parallax_deg = 4.0;     // median angle between the floor tracks' two rays
  double min_motion = 0.2;           // camera motion needed, in camera heights
  // Floor tracks needed, of those the rotation alone does not explain (those fit every
  // plane): the rendered room at 1.2 m shows 8-30 floor tracks of the tracker's 150.
  int min_inliers = 8;
  int confirmations = 5;             // images in a row that find the same floor ...
  double max_floor_change_deg = 4;   // ... its down direction changing less than this
  double max_error_px = 3.0;         // RANSAC threshold: 3 sigma of the measured noise, at most this
};

struct FloorStart {
  bool ok = false;
  std::string reason;            // why not, when !ok
  Pose second_from_first;        // metres
  cv::Vec3d down{0, 1, 0};       // first camera frame: unit normal from the camera to the floor
  std::vector<int> floor_points; // indices of the floor's tracks
  double parallax_deg = 0;       // median over the floor's tracks
  double noise_px = 0;           // the tracks' measured noise (sigma of the epipolar error)
  // Every track triangulated (indices into first/second), first camera frame, metres.
  std::vector<int> point_index;
  std::vector<cv::Vec3d> points;
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
