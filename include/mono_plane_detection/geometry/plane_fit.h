// A metric plane through 3D points: robust fit (RANSAC on triples, then least squares
// with Eigen's SVD) and the plane's extent as the convex hull of its points. ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mono_plane_detection {

// The plane {x : normal . x = distance}, normal of unit length.
struct PlaneFit {
  bool ok = false;
  cv::Vec3d normal{0, 0, 1};
  double distance = 0;       // m
  double rms_m = 0;          // point-to-plane distance over the inliers
  std::vector<int> inliers;  // indices of the points within max_residual_m, ascending
};

// Fails (ok = false) with fewer than min_points inliers or when they lie close to a
// line (second spread below min_spread_m). Deterministic for given points.
PlaneFit fitPlane(const std::vector<cv::Vec3d>& points, double max_residual_m, int min_points = 4,
                  double min_spread_m = 0.05);

// Flips the plane so that its normal points towards `viewpoint` (the side it was seen from).
void orientTowards(PlaneFit& plane, const cv::Vec3d& viewpoint);

// Two unit vectors spanning the plane, u x v = normal.
void planeAxes(const cv::Vec3d& normal, cv::Vec3d& u, cv::Vec3d& v);

// Convex hull of the points projected onto the plane, counter-clockwise seen from the
// normal's side, in 3D.
std::vector<cv::Vec3d> planePolygon(const cv::Vec3d& normal, double distance,
                                    const std::vector<cv::Vec3d>& points);

// Angle between two planes' normals, degrees in [0, 180].
double normalAngleDeg(const cv::Vec3d& a, const cv::Vec3d& b);

}  // namespace mono_plane_detection
