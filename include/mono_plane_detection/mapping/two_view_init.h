// Metric start from two views (beyond the paper). From 2 m the small target fixes its
// own tilt only to a few degrees, and a tilted map puts every landmark in the wrong
// place. So the first image's target corners are averaged over many images (each
// image's corners carried back by the homography of the target's wall, estimated from
// all tracks on it); the pose from those corners fixes map frame and scale (its
// orientation, when the caller has a better one, e.g. each image's own pose averaged:
// first_rotation), and the same wall homography gives the camera's motion to the later
// image, from which all tracks are triangulated. ROS-free.
#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "mono_plane_detection/geometry/pose.h"
#include "mono_plane_detection/tracking/target_detector.h"

namespace mono_plane_detection {

struct TwoViewParams {
  double min_parallax_deg = 3.0;     // median angle between the two rays of the points
  int min_inliers = 20;              // tracks on the target's plane needed
  double max_error_px = 1.0;         // homography RANSAC threshold, triangulation check / 2
  double max_target_error_px = 3.0;  // target corners transferred by the target's plane
};

// The homography (normalised coordinates, first -> second) of the plane the target lies
// on: the largest plane of the tracks whose homography also carries the target's corners.
struct TargetPlaneHomography {
  bool ok = false;
  cv::Matx33d H;
  std::vector<int> inliers;  // indices of the tracks on the plane
};
TargetPlaneHomography targetPlaneHomography(const std::vector<cv::Point2d>& first,
                                            const std::vector<cv::Point2d>& second,
                                            const std::array<int, 4>& target, double focal_px,
                                            const TwoViewParams& params = TwoViewParams());

struct TwoViewInit {
  bool ok = false;
  std::string reason;  // why not, when !ok
  Pose map_from_first, map_from_second;
  std::vector<int> points;            // indices of the triangulated points
  std::vector<cv::Vec3d> points_map;  // their positions, map frame, m
  double parallax_deg = 0;            // median over the points
};

// second_from_first given the plane's homography H ~ R + t n^T / d (normalised
// coordinates, first -> second; first-camera plane n . x = d, n away from the camera).
Pose motionFromPlane(cv::Matx33d H, const cv::Vec3d& n, double d);

// The nearest rotation to M (SVD), e.g. to a sum of rotations.
cv::Matx33d nearestRotation(const cv::Matx33d& M);

// map_from_camera with a known orientation (map_from_camera.R = R) from the target's
// corners (normalised coordinates, TargetDetection order): the position is linear then.
std::optional<Pose> poseFromCornersWithRotation(const std::array<cv::Point2d, 4>& corners,
                                                const cv::Matx33d& R,
                                                const TargetParams& target_params);

// first/second: undistorted normalised coordinates of the same points in two images;
// target: the indices of the target's four corners (TargetDetection order) among them;
// first_corners: better (averaged) normalised corners of the first image, if known;
// first_rotation: a better orientation of the first camera (map_from_first.R), if known.
TwoViewInit initialiseFromTwoViews(
    const std::vector<cv::Point2d>& first, const std::vector<cv::Point2d>& second,
    const std::array<int, 4>& target, double focal_px, const TargetParams& target_params,
    const TwoViewParams& params = TwoViewParams(),
    const std::optional<std::array<cv::Point2d, 4>>& first_corners = std::nullopt,
    const std::optional<cv::Matx33d>& first_rotation = std::nullopt);

}  // namespace mono_plane_detection
