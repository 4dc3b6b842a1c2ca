#include "mono_plane_detection/mapping/two_view_init.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>

#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/geometry/triangulation.h"

namespace mono_plane_detection {
namespace {

cv::Vec3d rayOf(const cv::Point2d& n) { return cv::Vec3d(n.x, n.y, 1.0); }

cv::Vec3d normalised(const cv::Vec3d& v) { return v / cv::norm(v); }

}  // namespace

// Directions in the plane move with R alone.
Pose motionFromPlane(cv::Matx33d H, const cv::Vec3d& n, double d) {
  if (cv::determinant(H) < 0) H = -H;
  const cv::Vec3d helper = std::abs(n[0]) < 0.9 ? cv::Vec3d(1, 0, 0) : cv::Vec3d(0, 1, 0);
  const cv::Vec3d v1 = normalised(n.cross(helper)), v2 = n.cross(v1);
  const cv::Vec3d w1 = H * v1, w2 = H * v2;
  const double lambda = (cv::norm(w1) + cv::norm(w2)) / 2;
  // Orthogonal Procrustes on (v1, v2, v1 x v2) -> (w1, w2, w1 x w2).
  const cv::Vec3d u1 = w1 / lambda, u2 = w2 / lambda, u3 = normalised(u1.cross(u2));
  const cv::Matx33d M = u1 * v1.t() + u2 * v2.t() + u3 * n.t();
  cv::Mat W, U, Vt;
  cv::SVD::compute(cv::Mat(M), W, U, Vt);
  cv::Matx33d R(cv::Mat(U * Vt));
  if (cv::determinant(R) < 0) R = -R;
  const cv::Vec3d t = d * (H * n / lambda - R * n);
  return {R, t};
}

cv::Matx33d nearestRotation(const cv::Matx33d& M) {
  cv::Mat W, U, Vt;
  cv::SVD::compute(cv::Mat(M), W, U, Vt);
  cv::Mat D = cv::Mat::eye(3, 3, CV_64F);
  D.at<double>(2, 2) = cv::determinant(U * Vt) < 0 ? -1 : 1;
  return cv::Matx33d(cv::Mat(U * D * Vt));
}

std::optional<Pose> poseFromCornersWithRotation(const std::array<cv::Point2d, 4>& corners,
                                                const cv::Matx33d& R,
                                                const TargetParams& target_params) {
  // Each corner's ray u (camera frame) is parallel to R^T (X - c): u x R^T c = u x R^T X.
  const std::array<cv::Point3d, 4> X = targetCornersInMap(target_params);
  cv::Matx33d A = cv::Matx33d::zeros();
  cv::Vec3d b(0, 0, 0);
  for (int k = 0; k < 4; ++k) {
    const cv::Vec3d u = normalised(rayOf(corners[k]));
    const cv::Matx33d ux(0, -u[2], u[1], u[2], 0, -u[0], -u[1], u[0], 0);
    const cv::Matx33d M = ux * R.t();
    A += M.t() * M;
    b += M.t() * (M * cv::Vec3d(X[k].x, X[k].y, X[k].z));
  }
  cv::Vec3d c;
  if (!cv::solve(A, b, c, cv::DECOMP_CHOLESKY)) return std::nullopt;
  const Pose map_from_camera{R, c};
  for (int k = 0; k < 4; ++k)
    if (map_from_camera.inverse().apply(cv::Vec3d(X[k].x, X[k].y, X[k].z))[2] <= 0)
      return std::nullopt;
  return map_from_camera;
}

TargetPlaneHomography targetPlaneHomography(const std::vector<cv::Point2d>& first,
                                            const std::vector<cv::Point2d>& second,
                                            const std::array<int, 4>& target, double focal_px,
                                            const TwoViewParams& params) {
  TargetPlaneHomography out;
  const int n = static_cast<int>(first.size());
  if (n != static_cast<int>(second.size())) return out;
  std::vector<bool> active(static_cast<size_t>(n), true);
  for (int k : target) {
    if (k < 0 || k >= n) return out;
    active[static_cast<size_t>(k)] = false;
  }
  // A few tries: the floor may be larger than the target's wall.
  for (int attempt = 0; attempt < 3; ++attempt) {
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
    const cv::Mat found =
        cv::findHomography(a, b, cv::RANSAC, params.max_error_px / focal_px, mask, 2000, 0.999);
    if (found.empty()) break;
    std::vector<int> inliers;
    for (size_t k = 0; k < a.size(); ++k)
      if (mask.at<uchar>(static_cast<int>(k))) inliers.push_back(index[k]);
    if (static_cast<int>(inliers.size()) < params.min_inliers) break;
    const cv::Matx33d H(found);
    double worst = 0;
    for (int k : target) {
      const cv::Vec3d moved = H * rayOf(first[k]);
      worst = std::max(worst, focal_px * std::hypot(moved[0] / moved[2] - second[k].x,
                                                    moved[1] / moved[2] - second[k].y));
    }
    if (worst <= params.max_target_error_px) {
      out.ok = true;
      out.H = H;
      out.inliers = inliers;
      return out;
    }
    for (int i : inliers) active[static_cast<size_t>(i)] = false;
  }
  return out;
}

TwoViewInit initialiseFromTwoViews(const std::vector<cv::Point2d>& first,
                                   const std::vector<cv::Point2d>& second,
                                   const std::array<int, 4>& target, double focal_px,
                                   const TargetParams& target_params, const TwoViewParams& params,
                                   const std::optional<std::array<cv::Point2d, 4>>& first_corners,
                                   const std::optional<cv::Matx33d>& first_rotation) {
  TwoViewInit out;
  const int n = static_cast<int>(first.size());
  if (n < params.min_inliers || second.size() != first.size()) {
    out.reason = "too few points seen in both images";
    return out;
  }
  const TargetPlaneHomography plane =
      targetPlaneHomography(first, second, target, focal_px, params);
  if (!plane.ok) {
    out.reason = "no plane of the tracks carries the target";
    return out;
  }
  // The first camera from the target's corners (K = identity: normalised coordinates).
  TargetDetection detection;
  detection.found = true;
  for (int k = 0; k < 4; ++k) {
    const cv::Point2d c = first_corners ? (*first_corners)[k] : first[target[k]];
    detection.corners[k] = cv::Point2f(static_cast<float>(c.x), static_cast<float>(c.y));
  }
  const auto start = cameraPoseFromTarget(detection, cv::Matx33d::eye(), cv::Mat(), target_params);
  if (!start) {
    out.reason = "no pose from the target's corners";
    return out;
  }
  out.map_from_first = start->map_from_camera;
  if (first_rotation) {
    std::array<cv::Point2d, 4> corners;
    for (int k = 0; k < 4; ++k) corners[k] = first_corners ? (*first_corners)[k] : first[target[k]];
    const auto placed = poseFromCornersWithRotation(corners, *first_rotation, target_params);
    if (placed) out.map_from_first = *placed;
  }
  const Pose first_from_map = out.map_from_first.inverse();
  const cv::Vec3d toward_plane =
      -(first_from_map.R * cv::Vec3d(0, 0, 1));  // map z faces the camera
  const double d = toward_plane.dot(first_from_map.t);
  if (!(d > 0)) {
    out.reason = "the target's plane is behind the camera";
    return out;
  }
  const Pose second_from_first = motionFromPlane(plane.H, toward_plane, d);
  out.map_from_second = out.map_from_first * second_from_first.inverse();

  // Every point seen in both views, triangulated with the now known motion.
  const cv::Matx33d& R = second_from_first.R;
  const cv::Vec3d& t = second_from_first.t;
  const cv::Matx34d P1 = projectionMatrix(cv::Matx33d::eye(), cv::Vec3d(0, 0, 0));
  const cv::Matx34d P2 = projectionMatrix(R, t);
  const double threshold = 2 * params.max_error_px / focal_px;
  std::vector<double> parallax;
  for (int i = 0; i < n; ++i) {
    if (std::find(target.begin(), target.end(), i) != target.end()) continue;
    const auto p = triangulate(P1, P2, first[i], second[i]);
    if (!p || p->depth1 <= 0 || p->depth2 <= 0 || p->error > threshold) continue;
    const cv::Vec3d& x = p->x;
    const cv::Vec3d x2 = R * x + t;
    parallax.push_back(std::acos(std::min(1.0, normalised(x).dot(R.t() * normalised(x2)))) * 180.0 /
                       CV_PI);
    out.points.push_back(i);
    out.points_map.push_back(out.map_from_first.apply(x));
  }
  out.parallax_deg = median(parallax);
  if (static_cast<int>(out.points.size()) < params.min_inliers) {
    out.reason = "too few points triangulate";
    return out;
  }
  if (out.parallax_deg < params.min_parallax_deg) {
    out.reason = "not enough parallax yet";
    return out;
  }
  out.ok = true;
  return out;
}

}  // namespace mono_plane_detection
