#include "mono_plane_detection/mapping/camera_height_scale.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>

#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/geometry/triangulation.h"

namespace mono_plane_detection {
namespace {

cv::Vec3d ray(const cv::Point2d& n) { return cv::Vec3d(n.x, n.y, 1.0); }
cv::Vec3d unit(const cv::Vec3d& v) { return v / cv::norm(v); }
double angleDeg(const cv::Vec3d& a, const cv::Vec3d& b) {
  return std::acos(std::max(-1.0, std::min(1.0, unit(a).dot(unit(b))))) * 180.0 / CV_PI;
}

// The floor's homography alone, from a strip of floor, fixes the motion poorly (measured:
// 7 % scale, 4 deg tilt on the rendered room). The motion's direction comes better from
// every track (essential matrix), the floor then only gives the scale and the down
// direction: its tracks triangulated with that motion and fitted with a plane.
void refineWithAllTracks(const std::vector<cv::Point2d>& first,
                         const std::vector<cv::Point2d>& second, double focal_px,
                         const FloorParams& params, FloorStart& out) {
  std::vector<uchar> mask;
  const cv::Mat E = cv::findEssentialMat(first, second, 1.0, cv::Point2d(0, 0), cv::RANSAC, 0.999,
                                         params.max_error_px / focal_px, mask);
  if (E.rows != 3 || E.cols != 3) return;  // several solutions or none: keep the homography's
  cv::Mat Rm, tm;
  cv::recoverPose(E, first, second, Rm, tm, 1.0, cv::Point2d(0, 0), mask);
  const cv::Matx33d R(Rm);
  const cv::Vec3d t = unit(cv::Vec3d(tm));
  const cv::Vec3d t_h = out.second_from_first.t;
  // The two must agree, else the essential matrix is the one in doubt.
  const cv::Matx33d dR = R * out.second_from_first.R.t();
  const double rotation_deg =
      std::acos(std::max(-1.0, std::min(1.0, (dR(0, 0) + dR(1, 1) + dR(2, 2) - 1) / 2))) * 180 /
      CV_PI;
  if (rotation_deg > 2.0 || angleDeg(t, t_h) > 15.0) return;
  const cv::Matx34d P1(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0);
  const cv::Matx34d P2(R(0, 0), R(0, 1), R(0, 2), t[0], R(1, 0), R(1, 1), R(1, 2), t[1], R(2, 0),
                       R(2, 1), R(2, 2), t[2]);
  std::vector<cv::Vec3d> floor;
  for (int i : out.floor_points) {
    const auto p = triangulate(P1, P2, first[i], second[i]);
    if (p && p->depth1 > 0 && p->depth2 > 0) floor.push_back(p->x);
  }
  if (static_cast<int>(floor.size()) < params.min_inliers) return;
  cv::Vec3d c(0, 0, 0);
  for (const auto& x : floor) c += x;
  c /= static_cast<double>(floor.size());
  cv::Matx33d S = cv::Matx33d::zeros();
  for (const auto& x : floor) S += (x - c) * (x - c).t();
  cv::Mat W, U, Vt;
  cv::SVD::compute(cv::Mat(S), W, U, Vt);
  cv::Vec3d n(Vt.at<double>(2, 0), Vt.at<double>(2, 1), Vt.at<double>(2, 2));
  if (n.dot(c) < 0) n = -n;
  const double d = n.dot(c);  // in units of the motion
  if (!(d > 0) || angleDeg(n, out.down) > 10.0) return;
  out.down = unit(n);
  out.second_from_first = Pose{R, t * (params.camera_height_m / d)};
}

}  // namespace

FloorStart floorStart(const std::vector<cv::Point2d>& first,
                      const std::vector<cv::Point2d>& second, double focal_px,
                      const FloorParams& params) {
  FloorStart out;
  if (!(params.camera_height_m > 0)) {
    out.reason = "camera height unknown";
    return out;
  }
  if (first.size() != second.size() || static_cast<int>(first.size()) < params.min_inliers) {
    out.reason = "too few tracks";
    return out;
  }
  const double pitch = params.pitch_down_deg * CV_PI / 180.0;
  const cv::Vec3d nominal_down(0, std::cos(pitch), std::sin(pitch));  // x right, y down, z ahead
  std::vector<int> remaining(first.size());
  for (size_t i = 0; i < first.size(); ++i) remaining[i] = static_cast<int>(i);
  double best_angle = params.max_floor_angle_deg;
  out.reason = "no plane near the nominal floor";
  for (int plane = 0; plane < params.max_planes; ++plane) {
    if (static_cast<int>(remaining.size()) < params.min_inliers) break;
    std::vector<cv::Point2d> a, b;
    for (int i : remaining) {
      a.push_back(first[i]);
      b.push_back(second[i]);
    }
    std::vector<uchar> mask;
    const cv::Mat Hm =
        cv::findHomography(a, b, cv::RANSAC, params.max_error_px / focal_px, mask, 2000, 0.999);
    if (Hm.empty()) break;
    std::vector<int> inliers, rest;
    for (size_t k = 0; k < remaining.size(); ++k)
      (mask[k] ? inliers : rest).push_back(remaining[k]);
    remaining = rest;
    if (static_cast<int>(inliers.size()) < params.min_inliers) break;
    // One homography for (nearly) every track: a rotation, or too little motion to
    // tell the planes apart yet.
    if (plane == 0 && inliers.size() * 10 >= first.size() * 9)
      out.reason = "not enough motion yet (parallax): one homography fits the tracks";
    std::vector<cv::Mat> Rs, ts, ns;
    cv::decomposeHomographyMat(Hm, cv::Mat::eye(3, 3, CV_64F), Rs, ts, ns);
    // H = R + t n^T with the plane n . x = 1 in the first camera: n is the unit normal
    // towards the plane and t is in units of the plane's distance. Keep the solutions
    // that put every inlier in front of both cameras.
    // The largest plane's motion in its own distances: below 3 % the decomposition
    // is noise (a still or only turning camera).
    if (plane == 0) {
      double largest_t = 0;
      for (const cv::Mat& t : ts) largest_t = std::max(largest_t, cv::norm(t));
      if (largest_t < 0.03) {
        out.reason = "not enough motion yet (parallax)";
        return out;
      }
    }
    for (size_t s = 0; s < Rs.size(); ++s) {
      const cv::Matx33d R(Rs[s]);
      const cv::Vec3d t(ts[s]), n(ns[s]);
      int in_front = 0;
      for (int i : inliers) {
        const double nm = n.dot(ray(first[i]));
        if (nm <= 0) continue;
        const cv::Vec3d x2 = R * (ray(first[i]) / nm) + t;
        in_front += x2[2] > 0;
      }
      const double angle = angleDeg(n, nominal_down);
      if (in_front * 10 < static_cast<int>(inliers.size()) * 9) continue;
      if (angle >= best_angle) continue;
      // Parallax of the floor's tracks: the decomposition needs motion relative to d.
      std::vector<double> parallax;
      for (int i : inliers) parallax.push_back(angleDeg(ray(first[i]), R.t() * ray(second[i])));
      best_angle = angle;
      out.down = unit(n);
      out.second_from_first = Pose{R, t * params.camera_height_m};
      out.floor_points = inliers;
      out.parallax_deg = median(parallax);
      out.ok = true;
    }
  }
  if (out.ok && out.parallax_deg >= params.min_parallax_deg) refineWithAllTracks(first, second, focal_px, params, out);
  if (out.ok && cv::norm(out.second_from_first.t) < params.min_motion * params.camera_height_m) {
    out.ok = false;
    out.reason = "floor found, not enough motion yet";
  }
  if (out.ok && out.parallax_deg < params.min_parallax_deg) {
    out.ok = false;
    out.reason = "floor found, not enough motion yet (parallax)";
  }
  if (out.ok) out.reason.clear();
  return out;
}

Pose floorMapFromCamera(const cv::Vec3d& down, double camera_height_m) {
  const cv::Vec3d up = -unit(down);
  cv::Vec3d ahead = cv::Vec3d(0, 0, 1) - up[2] * up;  // the optical axis along the floor
  ahead = unit(ahead);
  const cv::Vec3d y = up, z = -ahead, x = y.cross(z);
  // camera_from_map: the map's axes and origin in the camera frame.
  const cv::Matx33d R(x[0], y[0], z[0], x[1], y[1], z[1], x[2], y[2], z[2]);
  const Pose camera_from_map{R, unit(down) * camera_height_m};
  return camera_from_map.inverse();
}

}  // namespace mono_plane_detection
