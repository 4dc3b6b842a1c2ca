// A pinhole camera with optional radial distortion (OpenCV's model): what the renderer
// draws with and what the evaluation projects with. ROS-free.
#pragma once

#include <opencv2/core.hpp>

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

}  // namespace mono_plane_detection
