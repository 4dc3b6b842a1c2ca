// Start-up (paper II-A): the white rectangle on a black background of known size is
// found in the image, its four corners refined to sub-pixel, and they give the camera's
// pose in metres in the map frame (the target's frame). ROS-free.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

struct TargetParams {
  double width_m = 0.297;  // white rectangle, the longer side
  double height_m = 0.210;
  double min_area_px = 400;  // smaller candidates are ignored
  double max_aspect_distortion =
      2.5;                      // image long/short side may differ from width/height by this factor
  double min_contrast = 120;    // grey levels between the white inside and the dark ring
  double min_structure = 0.95;  // share of the inside above / the ring below Otsu's level
  double max_ring_ratio = 0.3;  // the black border's mean over the white inside's mean
};

struct TargetDetection {
  bool found = false;
  // Ordered as the map frame's corners: (-w/2,-h/2), (+w/2,-h/2), (+w/2,+h/2), (-w/2,+h/2),
  // i.e. for an upright camera bottom-left, bottom-right, top-right, top-left.
  std::array<cv::Point2f, 4> corners;
  double contrast = 0;  // inside minus ring, grey levels
  std::string reason;   // why nothing was found
};

// The target in an 8-bit grey image: Otsu threshold, contours, a convex quadrilateral
// with the target's aspect ratio, white inside and dark around, the most contrasted one;
// corners refined as intersections of lines fitted to sub-pixel edge points.
TargetDetection detectTarget(const cv::Mat& gray, const TargetParams& params = TargetParams());

// The target's corners in the map frame, in TargetDetection's order.
std::array<cv::Point3d, 4> targetCornersInMap(const TargetParams& params);

struct TargetPose {
  Pose map_from_camera;              // the camera's pose in the map frame
  double reprojection_error_px = 0;  // rms over the 4 corners
};

// solvePnP with the planar IPPE solver. Nothing when the intrinsics are unusable
// (non-positive or non-finite focal length) or the solver fails.
std::optional<TargetPose> cameraPoseFromTarget(const TargetDetection& detection,
                                               const cv::Matx33d& K, const cv::Mat& distortion,
                                               const TargetParams& params = TargetParams());

}  // namespace mono_plane_detection
