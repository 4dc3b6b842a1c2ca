// One point from two views: the linear (DLT) triangulation of OpenCV, then the checks
// every caller needs (finite, in front of both cameras, reprojection error). ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <optional>

namespace mono_plane_detection {

// The projection matrix [R | t] of a pose camera_from_world, for normalised image
// coordinates (x / z, y / z).
cv::Matx34d projectionMatrix(const cv::Matx33d& R, const cv::Vec3d& t);

struct TwoViewPoint {
  cv::Vec3d x;                     // in the frame P1 and P2 project from
  double depth1 = 0, depth2 = 0;   // along each camera's optical axis
  double error = 0;                // the larger reprojection error, normalised units
};

// Triangulates the normalised points n1 (seen by P1) and n2 (seen by P2). Nothing when
// the rays are parallel (the point at infinity) or the result is not finite.
std::optional<TwoViewPoint> triangulate(const cv::Matx34d& P1, const cv::Matx34d& P2,
                                        const cv::Point2d& n1, const cv::Point2d& n2);

// Sampson distance of the correspondence x1 <-> x2 to the epipolar geometry F (or E
// for normalised coordinates): the first-order distance to the nearest pair that fits,
// in the units of the points. 0 when F maps the point to no line.
double sampsonDistance(const cv::Matx33d& F, const cv::Point2d& x1, const cv::Point2d& x2);

}  // namespace mono_plane_detection
