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

// second_from_first given the plane's homography H ~ R + t n^T / d (first-camera plane
// n . x = d, n away from the camera): directions in the plane move with R alone.
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

// Small rotation exp(w) (Rodrigues).
cv::Matx33d rotationOf(const cv::Vec3d& w) {
  cv::Matx33d R;
  cv::Rodrigues(w, R);
  return R;
}

cv::Point2d project(const cv::Vec3d& x) { return {x[0] / x[2], x[1] / x[2]}; }

}  // namespace

double refineStartOnTargetWall(const std::array<cv::Point2d, 4>& corners_first,
                               const std::array<cv::Point2d, 4>& corners_second,
                               const std::vector<cv::Point2d>& wall_first,
                               const std::vector<cv::Point2d>& wall_second,
                               const std::vector<cv::Point2d>& epipolar_first,
                               const std::vector<cv::Point2d>& epipolar_second,
                               const TargetParams& target_params, double huber,
                               Pose& map_from_first, Pose& second_from_first) {
  const std::array<cv::Point3d, 4> corners = targetCornersInMap(target_params);
  const size_t walls = std::min(wall_first.size(), wall_second.size());
  // Unknowns: first_from_map and second_from_first, each a rotation update on the left
  // and a translation update (12).
  struct State {
    Pose first_from_map, second_from_first;
  };
  auto moved = [](const State& s, const cv::Matx<double, 12, 1>& d) {
    State o = s;
    o.first_from_map.R = rotationOf({d(0), d(1), d(2)}) * s.first_from_map.R;
    o.first_from_map.t = rotationOf({d(0), d(1), d(2)}) * s.first_from_map.t +
                         cv::Vec3d(d(3), d(4), d(5));
    o.second_from_first.R = rotationOf({d(6), d(7), d(8)}) * s.second_from_first.R;
    o.second_from_first.t = s.second_from_first.t + cv::Vec3d(d(9), d(10), d(11));
    return o;
  };
  // Residuals (normalised units); empty when the wall is behind the first camera.
  auto residuals = [&](const State& s) {
    std::vector<double> r;
    const Pose second_from_map = s.second_from_first * s.first_from_map;
    for (int k = 0; k < 4; ++k) {
      const cv::Vec3d X(corners[k].x, corners[k].y, corners[k].z);
      const cv::Vec3d x1 = s.first_from_map.apply(X), x2 = second_from_map.apply(X);
      if (x1[2] <= 0 || x2[2] <= 0) return std::vector<double>();
      const cv::Point2d e1 = project(x1) - corners_first[k], e2 = project(x2) - corners_second[k];
      r.insert(r.end(), {e1.x, e1.y, e2.x, e2.y});
    }
    const cv::Vec3d n = -(s.first_from_map.R * cv::Vec3d(0, 0, 1));
    const double d = n.dot(s.first_from_map.t);
    if (!(d > 0)) return std::vector<double>();
    const cv::Matx33d H =
        s.second_from_first.R + s.second_from_first.t * n.t() * (1.0 / d);
    const cv::Matx33d Hinv = H.inv();
    // Every track, on the wall or not: the epipolar constraint (Sampson distance) fixes the
    // motion's direction, which the wall's homography alone leaves free with its normal
    // when the camera moves towards the wall.
    const cv::Vec3d& tm = s.second_from_first.t;
    const cv::Matx33d tx(0, -tm[2], tm[1], tm[2], 0, -tm[0], -tm[1], tm[0], 0);
    const double tn = cv::norm(tm);
    if (!(tn > 0)) return std::vector<double>();
    const cv::Matx33d E = tx * s.second_from_first.R * (1.0 / tn);
    for (size_t i = 0; i < epipolar_first.size(); ++i) {
      const cv::Vec3d a(epipolar_first[i].x, epipolar_first[i].y, 1),
          b(epipolar_second[i].x, epipolar_second[i].y, 1);
      const cv::Vec3d Ea = E * a, Etb = E.t() * b;
      const double g = std::sqrt(Ea[0] * Ea[0] + Ea[1] * Ea[1] + Etb[0] * Etb[0] + Etb[1] * Etb[1]);
      const double e = g > 0 ? b.dot(Ea) / g : 0;
      r.insert(r.end(), {e, 0.0});
    }
    for (size_t i = 0; i < walls; ++i) {
      const cv::Vec3d a(wall_first[i].x, wall_first[i].y, 1), b(wall_second[i].x, wall_second[i].y, 1);
      const cv::Vec3d ab = H * a, ba = Hinv * b;
      if (ab[2] <= 0 || ba[2] <= 0) return std::vector<double>();
      const cv::Point2d e2 = project(ab) - wall_second[i], e1 = project(ba) - wall_first[i];
      r.insert(r.end(), {e1.x, e1.y, e2.x, e2.y});
    }
    return r;
  };
  // Huber weights from the residuals of each point (the corners are never down-weighted).
  auto cost = [&](const std::vector<double>& r, std::vector<double>* weights) {
    double c = 0;
    if (weights) weights->assign(r.size(), 1.0);
    for (size_t j = 0; j < r.size(); j += 2) {
      const double e = std::hypot(r[j], r[j + 1]);
      double w = 1.0;
      if (j >= 16 && e > huber) w = huber / e;
      if (weights) (*weights)[j] = (*weights)[j + 1] = w;
      c += j >= 16 && e > huber ? huber * (2 * e - huber) : e * e;
    }
    return c;
  };
  State s{map_from_first.inverse(), second_from_first};
  std::vector<double> r = residuals(s);
  if (r.empty()) return -1;
  double current = cost(r, nullptr), lambda = 1e-3;
  for (int iteration = 0; iteration < 30; ++iteration) {
    std::vector<double> w;
    cost(r, &w);
    // Jacobian by central differences (12 unknowns: cheap next to the tracking).
    const double step = 1e-7;
    cv::Mat J(static_cast<int>(r.size()), 12, CV_64F);
    bool ok = true;
    for (int p = 0; p < 12 && ok; ++p) {
      cv::Matx<double, 12, 1> d = cv::Matx<double, 12, 1>::zeros();
      d(p) = step;
      const std::vector<double> plus = residuals(moved(s, d));
      d(p) = -step;
      const std::vector<double> minus = residuals(moved(s, d));
      ok = plus.size() == r.size() && minus.size() == r.size();
      for (size_t j = 0; ok && j < r.size(); ++j)
        J.at<double>(static_cast<int>(j), p) = (plus[j] - minus[j]) / (2 * step);
    }
    if (!ok) break;
    cv::Mat W = cv::Mat(w).clone(), R = cv::Mat(r).clone();
    cv::Mat JtW = J.t();
    for (int j = 0; j < JtW.cols; ++j) JtW.col(j) *= W.at<double>(j);
    const cv::Mat A = JtW * J, g = JtW * R;
    bool improved = false;
    for (int tries = 0; tries < 10 && !improved; ++tries) {
      cv::Mat damped = A.clone();
      for (int p = 0; p < 12; ++p) damped.at<double>(p, p) *= 1 + lambda;
      cv::Mat delta;
      if (!cv::solve(damped, -g, delta, cv::DECOMP_CHOLESKY)) {
        lambda *= 10;
        continue;
      }
      const State next = moved(s, cv::Matx<double, 12, 1>(delta.ptr<double>()));
      const std::vector<double> rn = residuals(next);
      const double c = rn.size() == r.size() ? cost(rn, nullptr) : HUGE_VAL;
      if (c < current) {
        improved = true;
        const bool converged = current - c < 1e-10 * current;
        s = next;
        r = rn;
        current = c;
        lambda = std::max(1e-7, lambda / 10);
        if (converged) iteration = 30;
      } else {
        lambda *= 10;
      }
    }
    if (!improved) break;
  }
  map_from_first = s.first_from_map.inverse();
  second_from_first = s.second_from_first;
  return std::sqrt(current / std::max<size_t>(1, r.size() / 2));
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
                                   const std::optional<std::array<cv::Point2d, 4>>& first_corners) {
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
