#include "mono_plane_detection/two_view_init.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>

#include "mono_plane_detection/plane_fit.h"

namespace mono_plane_detection {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

cv::Vec3d rayOf(const cv::Point2d& n) { return cv::Vec3d(n.x, n.y, 1.0); }

}  // namespace

TwoViewInit initialiseFromTwoViews(const std::vector<cv::Point2d>& first,
                                   const std::vector<cv::Point2d>& second,
                                   const std::array<int, 4>& target, double focal_px,
                                   const TargetParams& target_params,
                                   const TwoViewParams& params) {
  TwoViewInit out;
  const int n = static_cast<int>(first.size());
  if (n < params.min_inliers || second.size() != first.size()) {
    out.reason = "too few points seen in both images";
    return out;
  }
  // The target's plane: the largest homography of the tracks that also carries the
  // target's corners from the first image to the second (a few tries: the floor may be
  // larger). A homography is well conditioned where the essential matrix is not: indoor
  // views are often mostly one wall.
  const double threshold = params.max_error_px / focal_px;
  std::vector<bool> active(static_cast<size_t>(n), true);
  for (int k : target) active[static_cast<size_t>(k)] = false;
  cv::Matx33d H;
  std::vector<int> plane_points;
  for (int attempt = 0; attempt < 3 && plane_points.empty(); ++attempt) {
    std::vector<cv::Point2d> a, b;
    std::vector<int> index;
    for (int i = 0; i < n; ++i)
      if (active[static_cast<size_t>(i)]) {
        a.push_back(first[i]);
        b.push_back(second[i]);
        index.push_back(i);
      }
    if (static_cast<int>(a.size()) < params.min_inliers) break;
    cv::Mat mask;
    const cv::Mat found = cv::findHomography(a, b, cv::RANSAC, threshold, mask, 2000, 0.999);
    if (found.empty()) break;
    std::vector<int> inliers;
    for (size_t k = 0; k < a.size(); ++k)
      if (mask.at<uchar>(static_cast<int>(k))) inliers.push_back(index[k]);
    if (static_cast<int>(inliers.size()) < params.min_inliers) break;
    const cv::Matx33d candidate(found);
    double worst = 0;
    for (int k : target) {
      const cv::Vec3d moved = candidate * rayOf(first[k]);
      worst = std::max(worst, focal_px * std::hypot(moved[0] / moved[2] - second[k].x,
                                                    moved[1] / moved[2] - second[k].y));
    }
    if (worst <= params.max_target_error_px) {
      H = candidate;
      plane_points = inliers;
    } else {
      for (int i : inliers) active[static_cast<size_t>(i)] = false;
    }
  }
  if (plane_points.empty()) {
    out.reason = "no plane of the tracks carries the target";
    return out;
  }
  std::vector<cv::Mat> rotations, translations, normals;
  cv::decomposeHomographyMat(cv::Mat(H), cv::Mat::eye(3, 3, CV_64F), rotations, translations,
                             normals);
  std::vector<cv::Point2f> before, after;
  for (int i : plane_points) {
    before.emplace_back(static_cast<float>(first[i].x), static_cast<float>(first[i].y));
    after.emplace_back(static_cast<float>(second[i].x), static_cast<float>(second[i].y));
  }
  std::vector<int> possible;
  cv::filterHomographyDecompByVisibleRefpoints(rotations, normals, before, after, possible);
  if (possible.empty()) {
    out.reason = "the target's plane homography has no physical decomposition";
    return out;
  }
  // Of the (usually two) remaining solutions, the target's own pose picks the normal.
  TargetDetection detection;
  detection.found = true;
  for (int k = 0; k < 4; ++k)
    detection.corners[k] = cv::Point2f(static_cast<float>(first[target[k]].x),
                                       static_cast<float>(first[target[k]].y));
  const auto rough = cameraPoseFromTarget(detection, cv::Matx33d::eye(), cv::Mat(), target_params);
  const cv::Vec3d rough_normal =
      rough ? rough->map_from_camera.inverse().R * cv::Vec3d(0, 0, 1) : cv::Vec3d(0, 0, -1);
  int best = possible.front();
  double best_angle = 1e9;
  for (int k : possible) {
    const cv::Vec3d nk(normals[k]);
    // OpenCV's normal points away from the camera; the map's z points towards it.
    const double angle = normalAngleDeg(-nk, rough_normal);
    if (angle < best_angle) {
      best_angle = angle;
      best = k;
    }
  }
  const cv::Matx33d R(rotations[best]);
  const cv::Vec3d t_over_d(translations[best]);  // second_from_first, in units of d
  PlaneFit target_plane;
  target_plane.normal = -cv::Vec3d(normals[best]);
  target_plane.distance = -1.0;  // plane at unit distance; the target gives the scale below
  target_plane.ok = true;
  orientTowards(target_plane, cv::Vec3d(0, 0, 0));
  const cv::Vec3d t = t_over_d;

  // Corners on that plane, then the scale from the target's known size.
  std::array<cv::Vec3d, 4> c;
  for (int k = 0; k < 4; ++k) {
    const cv::Vec3d ray = rayOf(first[target[k]]);
    c[k] = ray * (target_plane.distance / target_plane.normal.dot(ray));
  }
  const double measured = cv::norm(c[1] - c[0]) + cv::norm(c[2] - c[3]) + cv::norm(c[3] - c[0]) +
                          cv::norm(c[2] - c[1]);
  const double scale = 2 * (target_params.width_m + target_params.height_m) / measured;

  // Every point seen in both views, triangulated with the now known motion.
  const cv::Matx34d P1(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0);
  const cv::Matx34d P2(R(0, 0), R(0, 1), R(0, 2), t[0], R(1, 0), R(1, 1), R(1, 2), t[1], R(2, 0),
                       R(2, 1), R(2, 2), t[2]);
  std::vector<int> used;
  std::vector<cv::Vec3d> points;  // first camera's frame, units of d
  std::vector<double> parallax;
  for (int i = 0; i < n; ++i) {
    if (std::find(target.begin(), target.end(), i) != target.end()) continue;
    cv::Mat X;
    cv::triangulatePoints(cv::Mat(P1), cv::Mat(P2), cv::Mat(cv::Matx21d(first[i].x, first[i].y)),
                          cv::Mat(cv::Matx21d(second[i].x, second[i].y)), X);
    const double w = X.at<double>(3);
    if (std::abs(w) < 1e-12) continue;
    const cv::Vec3d x(X.at<double>(0) / w, X.at<double>(1) / w, X.at<double>(2) / w);
    const cv::Vec3d x2 = R * x + t;
    if (x[2] <= 0 || x2[2] <= 0) continue;
    const double e1 = std::hypot(x[0] / x[2] - first[i].x, x[1] / x[2] - first[i].y);
    const double e2 = std::hypot(x2[0] / x2[2] - second[i].x, x2[1] / x2[2] - second[i].y);
    if (std::max(e1, e2) > 2 * threshold) continue;
    const cv::Vec3d r1 = x / cv::norm(x), r2 = R.t() * (x2 / cv::norm(x2));
    parallax.push_back(std::acos(std::min(1.0, r1.dot(r2))) * 180.0 / CV_PI);
    used.push_back(i);
    points.push_back(x);
  }
  out.parallax_deg = median(parallax);
  if (static_cast<int>(used.size()) < params.min_inliers) {
    out.reason = "too few points triangulate";
    return out;
  }
  if (out.parallax_deg < params.min_parallax_deg) {
    out.reason = "not enough parallax yet";
    return out;
  }

  // Map axes in the first camera's frame: x along the width, z the plane's normal
  // (towards the camera, into the room), y = z x x.
  const cv::Vec3d z = target_plane.normal;
  cv::Vec3d x = (c[1] - c[0]) + (c[2] - c[3]);
  x -= z * z.dot(x);
  x /= cv::norm(x);
  const cv::Vec3d y = z.cross(x);
  const cv::Vec3d origin = scale * (c[0] + c[1] + c[2] + c[3]) / 4.0;
  const cv::Matx33d camera_from_map_R(x[0], y[0], z[0], x[1], y[1], z[1], x[2], y[2], z[2]);
  const Pose camera1_from_map{camera_from_map_R, origin};
  out.map_from_first = camera1_from_map.inverse();
  const Pose second_from_first{R, scale * t};
  out.map_from_second = out.map_from_first * second_from_first.inverse();
  out.points = used;
  for (const auto& p : points) out.points_map.push_back(out.map_from_first.apply(scale * p));
  out.ok = true;
  return out;
}

}  // namespace mono_plane_detection
