// Metric start from two views (beyond the paper): the camera's motion between the first
// image of the target and a later one comes from the essential matrix of all tracks,
// which is far better conditioned than the small target's own pose (its tilt is only
// known to 0.4-3.3 deg from 2 m). The target then fixes what two views cannot: the
// scale, and the map frame (origin, axes) on the plane the target lies on. ROS-free.
#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/indoor_scene.h"
#include "mono_plane_detection/target_detector.h"

namespace mono_plane_detection {

struct TwoViewParams {
  double min_parallax_deg = 3.0;  // median angle between the two rays of the points
  int min_inliers = 20;           // essential-matrix inliers needed
  double max_error_px = 1.0;      // essential-matrix RANSAC threshold
  double max_target_error_px = 3.0;  // target corners transferred by the target's plane
};

struct TwoViewInit {
  bool ok = false;
  std::string reason;             // why not, when !ok
  Pose map_from_first, map_from_second;
  std::vector<int> points;        // indices of the triangulated points
  std::vector<cv::Vec3d> points_map;  // their positions, map frame, m
  double parallax_deg = 0;        // median over the points
};

// first/second: undistorted normalised coordinates of the same points in two images;
// target: the indices of the target's four corners (TargetDetection order) among them.
TwoViewInit initialiseFromTwoViews(const std::vector<cv::Point2d>& first,
                                   const std::vector<cv::Point2d>& second,
                                   const std::array<int, 4>& target, double focal_px,
                                   const TargetParams& target_params,
                                   const TwoViewParams& params = TwoViewParams());

}  // namespace mono_plane_detection
