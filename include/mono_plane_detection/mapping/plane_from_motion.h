// A plane from an image plane's tracks under KNOWN camera motion (odometry), before its
// points have landmarks: a track seen first from camera j (ray r, centre c, both in the
// current camera's frame) and now at z lies on the plane {x : m . x = 1} (m = n / d, the
// current camera at the origin) when z ~ c + s r with s = (1 - m . c) / (m . r). Linear
// in m (two equations per track), then Gauss-Newton on the transfer error in pixels;
// the covariance from the residuals. ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mono_plane_detection {

struct MotionCorrespondence {
  cv::Vec3d centre;  // camera j's centre, current camera frame, m
  cv::Vec3d ray;     // the track's ray in camera j, rotated into the current frame (unit)
  cv::Point2d now;   // the track in the current image, normalised (x / z, y / z)
};

struct MotionPlane {
  bool ok = false;
  cv::Vec3d normal{0, 0, 1};  // unit, current camera frame, pointing away from the camera
  double distance = 0;        // m, > 0: the plane {x : normal . x = distance}
  double normal_sigma_deg = 180;  // 1 sigma, the least certain direction
  double distance_sigma = 1;      // relative (sigma_d / d)
  double rms_px = 0;              // transfer error over the tracks
};

// At least 4 tracks. focal_px converts normalised units to pixels (the residuals' scale).
MotionPlane planeFromMotion(const std::vector<MotionCorrespondence>& tracks, double focal_px);

}  // namespace mono_plane_detection
