#include "mono_plane_detection/mapping/camera_height_scale.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <optional>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/geometry/plane_fit.h"
#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/geometry/triangulation.h"

namespace mono_plane_detection {
namespace {

cv::Vec3d ray(const cv::Point2d& n) { return cv::Vec3d(n.x, n.y, 1.0); }
cv::Vec3d unit(const cv::Vec3d& v) { return v / cv::norm(v); }

}  // namespace

namespace {

// The motion between two views from every track, its length 1, and every inlier track
// triangulated with it (first camera frame).
struct Motion {
  cv::Matx33d R;
  cv::Vec3d t;
  double sigma = 0;                  // the tracks' measured noise (normalised units)
  double threshold = 0;              // RANSAC threshold used (normalised units)
  std::vector<int> index;            // tracks triangulated in front of both views
  std::vector<cv::Vec3d> points;     // their points
  std::vector<double> parallax_of;   // their parallax, deg
  std::vector<double> all_parallax;  // every inlier's parallax, deg
};

// The motion's direction from every track (essential matrix): a strip of floor alone
// fixes it poorly. The tracks' noise is measured, not assumed: a first RANSAC at the
// largest threshold, its inliers' median Sampson error gives sigma, the second uses
// 3 sigma (never above max_error_px). Empty (and `reason`) when there is no motion.
std::optional<Motion> measureMotion(const std::vector<cv::Point2d>& first,
                                    const std::vector<cv::Point2d>& second, double focal_px,
                                    double max_error_px, std::string& reason,
                                    bool select_plane = false) {
  const int n = static_cast<int>(first.size());
  std::vector<uchar> mask;
  cv::Mat Em = cv::findEssentialMat(first, second, 1.0, cv::Point2d(0, 0), cv::RANSAC, 0.999,
                                    max_error_px / focal_px, mask);
  if (Em.rows != 3 || Em.cols != 3) {
    reason = "no motion between the views (essential matrix)";
    return std::nullopt;
  }
  Motion m;
  std::vector<double> residuals;
  for (int i = 0; i < n; ++i)
    if (mask[i]) residuals.push_back(sampsonDistance(cv::Matx33d(Em), first[i], second[i]));
  m.sigma = std::max(1.4826 * median(residuals), 0.05 / focal_px);
  m.threshold = std::min(3 * m.sigma, max_error_px / focal_px);
  Em = cv::findEssentialMat(first, second, 1.0, cv::Point2d(0, 0), cv::RANSAC, 0.999, m.threshold,
                            mask);
  if (Em.rows != 3 || Em.cols != 3) {
    reason = "no motion between the views (essential matrix)";
    return std::nullopt;
  }
  const int essential_inliers = cv::countNonZero(mask);
  cv::Mat Rm, tm;
  cv::recoverPose(Em, first, second, Rm, tm, 1.0, cv::Point2d(0, 0), mask);
  m.R = cv::Matx33d(Rm);
  m.t = unit(cv::Vec3d(tm));
  if (select_plane) {
    // A view filled by one plane (a wall ahead) leaves the essential matrix poorly
    // determined: the motion then comes from that plane's homography (model selection
    // as ORB-SLAM's initialisation: the homography when it explains the tracks about as
    // well, its inliers over both counts above 0.45). Of its decompositions, the one
    // whose epipolar geometry the most tracks agree with (those off the plane decide).
    std::vector<uchar> on_plane;
    const cv::Mat Hm = cv::findHomography(first, second, cv::RANSAC, m.threshold, on_plane);
    const int homography_inliers = Hm.empty() ? 0 : cv::countNonZero(on_plane);
    if (homography_inliers > 0.45 * (homography_inliers + essential_inliers)) {
      std::vector<cv::Mat> Rs, ts, normals;
      cv::decomposeHomographyMat(Hm, cv::Mat::eye(3, 3, CV_64F), Rs, ts, normals);
      const cv::Matx34d P1(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0);
      int best = 0;  // a decomposition no track agrees with keeps the essential motion
      std::vector<uchar> best_mask;
      for (size_t c = 0; c < Rs.size(); ++c) {
        const cv::Matx33d R(Rs[c]);
        const cv::Vec3d t(ts[c]);
        if (!(cv::norm(t) > 0)) continue;
        const cv::Vec3d tu = unit(t);
        const cv::Matx33d tx(0, -tu[2], tu[1], tu[2], 0, -tu[0], -tu[1], tu[0], 0);
        const cv::Matx33d E = tx * R;
        const cv::Matx34d P2 = projectionMatrix(R, tu);
        std::vector<uchar> agree(n, 0);
        int count = 0;
        for (int i = 0; i < n; ++i) {
          if (sampsonDistance(E, first[i], second[i]) > m.threshold) continue;
          const auto p = triangulate(P1, P2, first[i], second[i]);
          if (!p || p->depth1 <= 0 || p->depth2 <= 0) continue;
          agree[i] = 1;
          ++count;
        }
        if (count > best) {
          best = count;
          best_mask = agree;
          m.R = R;
          m.t = tu;
        }
      }
      if (best > 0) mask = best_mask;
    }
  }
  // Each inlier's parallax (rotation removed) and its point, the motion's length 1.
  const cv::Matx34d P1(1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0);
  const cv::Matx34d P2 = projectionMatrix(m.R, m.t);
  for (int i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    const double parallax = normalAngleDeg(ray(first[i]), m.R.t() * ray(second[i]));
    m.all_parallax.push_back(parallax);
    const auto p = triangulate(P1, P2, first[i], second[i]);
    if (!p || p->depth1 <= 0 || p->depth2 <= 0) continue;
    m.index.push_back(i);
    m.points.push_back(p->x);
    m.parallax_of.push_back(parallax);
  }
  return m;
}

// Why two views cannot start the map (camera height unknown, too few tracks), "" when
// they can: the floor start's and the up-to-scale start's common checks.
std::string startInputError(const std::vector<cv::Point2d>& first,
                            const std::vector<cv::Point2d>& second, const FloorParams& params,
                            int needed) {
  if (!(params.camera_height_m > 0)) return "camera height unknown";
  if (second.size() != first.size() || static_cast<int>(first.size()) < needed)
    return "too few tracks";
  return {};
}

cv::Vec3d nominalDown(const FloorParams& params) {
  const double pitch = params.pitch_down_deg * CV_PI / 180.0;
  return cv::Vec3d(0, std::cos(pitch), std::sin(pitch));  // x right, y down, z ahead
}

}  // namespace

FloorStart floorStart(const std::vector<cv::Point2d>& first, const std::vector<cv::Point2d>& second,
                      double focal_px, const FloorParams& params) {
  FloorStart out;
  out.reason = startInputError(first, second, params, std::max(8, params.min_inliers));
  if (!out.reason.empty()) return out;
  std::optional<Motion> motion =
      measureMotion(first, second, focal_px, params.max_error_px, out.reason);
  if (!motion) return out;
  const cv::Matx33d R = motion->R;
  const cv::Vec3d t = motion->t;
  const double sigma = motion->sigma, threshold = motion->threshold;
  out.noise_px = sigma * focal_px;
  const std::vector<int>& index = motion->index;
  const std::vector<cv::Vec3d>& points = motion->points;
  const std::vector<double>& parallax_of = motion->parallax_of;
  const std::vector<double>& all_parallax = motion->all_parallax;
  if (all_parallax.empty() || median(all_parallax) < 0.25 * params.min_parallax_deg) {
    out.reason = "not enough motion yet (parallax)";
    return out;
  }
  if (static_cast<int>(points.size()) < params.min_inliers) {
    out.reason = "too few tracks triangulate";
    return out;
  }
  // The floor: of the planes through three triangulated points whose normal is within
  // max_floor_angle_deg of the nominal down, the one whose homography (H = R + t n^T / d)
  // carries the most tracks within the noise threshold.
  const cv::Vec3d nominal_down = nominalDown(params);
  cv::RNG rng(1);  // repeatable
  std::vector<int> best;
  int best_telling = 0;
  struct Hypothesis {
    double d;
    int telling;
    std::vector<int> inliers;
  };
  std::vector<Hypothesis> hypotheses;
  const int m = static_cast<int>(points.size());
  // Tracks the rotation alone carries within the threshold (far, or near the direction
  // of motion) lie on every plane: they are counted for none.
  std::vector<bool> at_infinity(m);
  for (int k = 0; k < m; ++k)
    at_infinity[k] = transfersWithin(R, first[index[k]], second[index[k]], 2 * threshold);
  // Samples only from tracks below the nominal horizon that the rotation does not explain.
  std::vector<int> candidates;
  for (int k = 0; k < m; ++k)
    if (!at_infinity[k] && nominal_down.dot(points[k]) > 0) candidates.push_back(k);
  // How far beyond a plane a track must lie to say it is not the floor: 3 times its
  // depth's uncertainty (depth / parallax times the noise). The same for every plane.
  std::vector<double> beyond_tolerance(m);
  for (int k = 0; k < m; ++k)
    beyond_tolerance[k] = 3 * sigma / (parallax_of[k] * CV_PI / 180.0) * cv::norm(points[k]);
  const int c = static_cast<int>(candidates.size());
  for (int iteration = 0; iteration < 2000 && c >= 3; ++iteration) {
    const int i0 = candidates[rng.uniform(0, c)], i1 = candidates[rng.uniform(0, c)],
              i2 = candidates[rng.uniform(0, c)];
    if (i0 == i1 || i1 == i2 || i0 == i2) continue;
    cv::Vec3d normal = (points[i1] - points[i0]).cross(points[i2] - points[i0]);
    if (cv::norm(normal) <= 0) continue;
    normal = unit(normal);
    double d = normal.dot(points[i0]);
    if (d < 0) {
      normal = -normal;
      d = -d;
    }
    if (!(d > 0) || normalAngleDeg(normal, nominal_down) > params.max_floor_angle_deg) continue;
    const cv::Matx33d H = R + t * (normal / d).t();
    std::vector<int> inliers;
    int telling = 0;
    for (int k = 0; k < m; ++k)
      if (transfersWithin(H, first[index[k]], second[index[k]], 2 * threshold)) {
        inliers.push_back(k);
        telling += !at_infinity[k];
      }
    // The floor is the lowest surface: tracks clearly beyond it say the plane is not it.
    int beyond = 0;
    for (int k = 0; k < m; ++k) beyond += normal.dot(points[k]) - d > beyond_tolerance[k];
    if (beyond * 5 > telling || telling < params.min_inliers) continue;
    hypotheses.push_back({d, telling, std::move(inliers)});
    best_telling = std::max(best_telling, telling);
  }
  // A plane through tracks where the floor meets a wall, tilted to pass below the floor
  // near the camera, has nothing beyond it either and may hold as many tracks: of the
  // well supported planes (half the best's tracks) the floor is the highest (least d).
  double best_d = 0;
  for (Hypothesis& h : hypotheses)
    if (2 * h.telling >= best_telling && (best.empty() || h.d < best_d)) {
      best_d = h.d;
      best = std::move(h.inliers);
    }
  if (best_telling < params.min_inliers) {
    out.reason = "no plane near the nominal floor (" + std::to_string(best_telling) + " of " +
                 std::to_string(m) + " tracks, " + std::to_string(params.min_inliers) +
                 " needed)";
    return out;
  }
  // Its plane from the image measurements of all its tracks, the motion known: m = n / d
  // solves x2 x (R x1 + t (x1 . m)) = 0 in least squares (linear in m); then the
  // inliers of that plane's homography, and once more.
  cv::Vec3d m_plane(0, 0, 0);
  for (int round = 0; round < 2; ++round) {
    cv::Mat A(3 * static_cast<int>(best.size()), 3, CV_64F), rhs(A.rows, 1, CV_64F);
    for (size_t j = 0; j < best.size(); ++j) {
      const cv::Vec3d x1 = ray(first[index[best[j]]]), x2 = ray(second[index[best[j]]]);
      const cv::Vec3d a = x2.cross(t), b = x2.cross(R * x1);
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) A.at<double>(3 * static_cast<int>(j) + r, c) = a[r] * x1[c];
        rhs.at<double>(3 * static_cast<int>(j) + r) = -b[r];
      }
    }
    cv::Mat solution;
    if (!cv::solve(A, rhs, solution, cv::DECOMP_SVD)) break;
    m_plane = cv::Vec3d(solution);
    if (round == 1 || !(cv::norm(m_plane) > 0)) break;
    const cv::Matx33d H = R + t * m_plane.t();
    std::vector<int> again;
    for (int k = 0; k < m; ++k)
      if (transfersWithin(H, first[index[k]], second[index[k]], 2 * threshold)) again.push_back(k);
    if (again.size() < best.size() / 2) break;  // the fit went elsewhere: keep the first
    best = again;
  }
  std::vector<double> floor_parallax;
  for (int k : best) floor_parallax.push_back(parallax_of[k]);
  const double d = cv::norm(m_plane) > 0 ? 1.0 / cv::norm(m_plane) : 0;  // in lengths of the motion
  const cv::Vec3d normal = m_plane * d;
  if (!(d > 0) || normalAngleDeg(normal, nominal_down) > params.max_floor_angle_deg) {
    out.reason = "no plane near the nominal floor";
    return out;
  }
  out.down = unit(normal);
  out.second_from_first = Pose{R, t * (params.camera_height_m / d)};
  out.point_index = index;
  for (const cv::Vec3d& x : points) out.points.push_back(x * (params.camera_height_m / d));
  for (int k : best) out.floor_points.push_back(index[k]);
  out.parallax_deg = median(floor_parallax);
  out.ok = true;
  if (1.0 / d < params.min_motion) {
    out.ok = false;
    out.reason = "floor found, not enough motion yet";
  } else if (out.parallax_deg < params.min_parallax_deg) {
    out.ok = false;
    out.reason = "floor found, not enough motion yet (parallax)";
  }
  return out;
}

FloorStart unscaledStart(const std::vector<cv::Point2d>& first,
                         const std::vector<cv::Point2d>& second, double focal_px,
                         const FloorParams& params) {
  FloorStart out;
  const int needed = std::max(8, params.min_check_points);
  out.reason = startInputError(first, second, params, needed);
  if (!out.reason.empty()) return out;
  std::optional<Motion> motion =
      measureMotion(first, second, focal_px, params.max_error_px, out.reason, true);
  if (!motion) return out;
  out.noise_px = motion->sigma * focal_px;
  // The map is built from these points: their own parallax, not the far tracks', must
  // reach what the floor start asks of the floor's tracks.
  if (motion->parallax_of.empty() || median(motion->parallax_of) < params.min_parallax_deg) {
    out.reason = "not enough motion yet (parallax)";
    return out;
  }
  if (static_cast<int>(motion->points.size()) < needed) {
    out.reason = "too few tracks triangulate";
    return out;
  }
  // A first guess of the scale, corrected by the floor landmarks later: the floor is the
  // lowest surface, so the lowest tracks (below the nominal horizon, a high percentile of
  // their depth below the camera) are taken to lie camera_height_m down. When no floor is
  // in view they lie higher and the guess is too large; the check does not bound it.
  const cv::Vec3d down = nominalDown(params);
  std::vector<double> below;
  for (const cv::Vec3d& x : motion->points)
    if (down.dot(x) > 0) below.push_back(down.dot(x));
  const double lowest = percentile(below, 0.9);
  if (!(lowest > 0)) {
    out.reason = "no tracks below the horizon";
    return out;
  }
  const double scale = params.camera_height_m / lowest;
  out.down = down;
  out.second_from_first = Pose{motion->R, motion->t * scale};
  out.point_index = motion->index;
  for (const cv::Vec3d& x : motion->points) out.points.push_back(x * scale);
  out.parallax_deg = median(motion->parallax_of);
  out.ok = true;
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

namespace {

// Weighted total least squares for two parallel planes sharing one normal (oriented
// like `towards`): the landmarks' floor and the plane of the camera positions (a wheeled
// camera stays at one height). Each group is centred on its own weighted centroid; the
// normal is the smallest eigenvector of their summed scatter.
bool fitPlane(const std::vector<cv::Vec3d>& points, const std::vector<double>& weight,
              const std::vector<int>& use, const std::vector<cv::Vec3d>& cameras,
              double camera_weight, const cv::Vec3d& towards, cv::Vec3d& up, double& offset) {
  double w_sum = 0;
  cv::Vec3d centre(0, 0, 0), camera_centre(0, 0, 0);
  for (int i : use) {
    w_sum += weight[i];
    centre += weight[i] * points[i];
  }
  if (use.size() < 3 || !(w_sum > 0)) return false;
  centre /= w_sum;
  for (const cv::Vec3d& c : cameras) camera_centre += c / static_cast<double>(cameras.size());
  cv::Matx33d C = cv::Matx33d::zeros();
  for (int i : use) {
    const cv::Vec3d d = points[i] - centre;
    C += weight[i] * d * d.t();
  }
  for (const cv::Vec3d& c : cameras) {
    const cv::Vec3d d = c - camera_centre;
    C += camera_weight * d * d.t();
  }
  cv::Matx31d values;
  cv::Matx33d vectors;
  cv::eigen(C, values, vectors);
  cv::Vec3d n(vectors(2, 0), vectors(2, 1), vectors(2, 2));  // smallest eigenvalue
  if (n.dot(towards) < 0) n = -n;
  up = unit(n);
  offset = up.dot(centre);
  return true;
}

}  // namespace

FloorFit fitFloorToLandmarks(const std::vector<cv::Vec3d>& points,
                             const std::vector<double>& sigma_m,
                             const std::vector<cv::Vec3d>& cameras, const cv::Vec3d& up,
                             double max_angle_deg, double tolerance_m, int min_points,
                             double camera_sigma_m, bool relative) {
  FloorFit out;
  const int n = static_cast<int>(points.size());
  if (n < std::max(3, min_points) || sigma_m.size() != points.size() || cameras.empty()) {
    out.reason = "too few landmarks";
    return out;
  }
  // relative: the tolerances are shares of the cameras' median height above the plane
  // (a map whose scale is not known yet).
  auto unit_length = [&](const cv::Vec3d& u, double offset) {
    if (!relative) return 1.0;
    std::vector<double> heights;
    for (const cv::Vec3d& c : cameras) heights.push_back(u.dot(c) - offset);
    return std::max(0.0, median(heights));
  };
  // One gate for every landmark, the tolerance, not widened to a landmark's own sigma (a
  // pixel over its parallax: 3-8 % of the height on the humanoid's floor, whose
  // landmarks lie within 1-4 %). Widened, a plane through a few floor landmarks and the
  // wall's foot, tilted, counted as many as the check needs where the floor alone had
  // too few (room --seed 2: map up 3.3 deg, every distance 9-15 % off; docs/mapping.md).
  // The sigmas weigh the fit below.
  // Below every camera: the floor is under the robot.
  auto below = [&](const cv::Vec3d& u, double offset, double tol) {
    for (const cv::Vec3d& c : cameras)
      if (u.dot(c) - offset <= tol) return false;
    return true;
  };
  // RANSAC over triples, deterministic (a fixed generator): repeatable maps.
  cv::RNG rng(12345);
  int best_count = 0;
  cv::Vec3d best_up = unit(up);
  double best_offset = 0;
  const double cos_max = std::cos(max_angle_deg * CV_PI / 180);
  for (int iter = 0; iter < 500; ++iter) {
    const int a = rng.uniform(0, n), b = rng.uniform(0, n), c = rng.uniform(0, n);
    if (a == b || b == c || a == c) continue;
    cv::Vec3d u = (points[b] - points[a]).cross(points[c] - points[a]);
    if (cv::norm(u) < 1e-9) continue;
    u = unit(u);
    if (u.dot(up) < 0) u = -u;
    if (u.dot(unit(up)) < cos_max) continue;
    const double offset = u.dot(points[a]);
    const double tol = tolerance_m * unit_length(u, offset);
    if (!(tol > 0) || !below(u, offset, tol)) continue;
    int count = 0, beyond = 0;
    for (int i = 0; i < n; ++i) {
      const double r = u.dot(points[i]) - offset;
      count += std::abs(r) <= tol;
      beyond += -r > tol;
    }
    // relative (the wider cone of an up-to-scale start): the floor is the lowest surface,
    // a plane with landmarks below its gate (one through the floor and the foot of a
    // wall, tilted) is not the floor (as floorStart's test). Measured on the synthetic
    // humanoid (test_pose_estimator): map tilt 8.5 -> 2.3 deg.
    if (relative && beyond * 5 > count) continue;
    if (count > best_count) {
      best_count = count;
      best_up = u;
      best_offset = offset;
    }
  }
  if (best_count < min_points) {
    out.reason = "no floor among the landmarks";
    return out;
  }
  std::vector<double> weight(points.size());
  for (int i = 0; i < n; ++i) weight[i] = 1.0 / std::max(1e-6, sigma_m[i] * sigma_m[i]);
  cv::Vec3d fit_up = best_up;
  double offset = best_offset;
  std::vector<int> use;
  for (int round = 0; round < 3; ++round) {
    const double length = unit_length(fit_up, offset);
    const double tol = tolerance_m * length, camera_sigma = camera_sigma_m * length;
    const double camera_weight = camera_sigma > 0 ? 1.0 / (camera_sigma * camera_sigma) : 0.0;
    use.clear();
    for (int i = 0; i < n; ++i)
      if (std::abs(fit_up.dot(points[i]) - offset) <= tol) use.push_back(i);
    if (static_cast<int>(use.size()) < min_points ||
        !fitPlane(points, weight, use, cameras, camera_weight, best_up, fit_up, offset)) {
      out.reason = "no floor among the landmarks";
      return out;
    }
  }
  double sq = 0;
  for (int i : use) sq += std::pow(fit_up.dot(points[i]) - offset, 2);
  out.ok = true;
  out.up = fit_up;
  out.offset = offset;
  out.inliers = use;
  out.rms_m = std::sqrt(sq / static_cast<double>(use.size()));
  return out;
}

double relativeHeightSpread(const FloorFit& floor, const std::vector<cv::Vec3d>& cameras) {
  std::vector<double> heights, deviation;
  for (const cv::Vec3d& c : cameras) heights.push_back(floor.up.dot(c) - floor.offset);
  if (heights.empty()) return HUGE_VAL;
  const double height = median(heights);
  if (!(height > 0)) return HUGE_VAL;
  for (double h : heights) deviation.push_back(std::abs(h - height));
  return 1.4826 * median(deviation) / height;
}

Similarity floorCorrection(const FloorFit& floor, const std::vector<cv::Vec3d>& cameras,
                           const cv::Vec3d& origin_camera, double camera_height_m) {
  Similarity s;
  // The smallest rotation taking the floor's up onto +y (Rodrigues about their cross).
  const cv::Vec3d y(0, 1, 0), axis = floor.up.cross(y);
  const double sin_a = cv::norm(axis), cos_a = floor.up.dot(y);
  if (sin_a > 1e-12) {
    const cv::Vec3d r = axis / sin_a * std::atan2(sin_a, cos_a);
    cv::Rodrigues(r, s.R);
  }
  std::vector<double> heights;
  for (const cv::Vec3d& c : cameras) heights.push_back(floor.up.dot(c) - floor.offset);
  const double height = heights.empty() ? 0 : median(heights);
  s.scale = height > 0 ? camera_height_m / height : 1.0;
  // Floor at y = 0, the origin below origin_camera.
  const cv::Vec3d o = s.scale * (s.R * origin_camera);
  s.t = cv::Vec3d(-o[0], -s.scale * floor.offset, -o[2]);
  return s;
}

}  // namespace mono_plane_detection
