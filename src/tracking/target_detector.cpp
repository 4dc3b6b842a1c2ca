#include "mono_plane_detection/tracking/target_detector.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <vector>

namespace mono_plane_detection {
namespace {

double meanIn(const cv::Mat& gray, const cv::Mat& mask) { return cv::mean(gray, mask)[0]; }

// Orders a quadrilateral as the map frame's corners: the two longer opposite sides are
// the target's width; of those, the lower one in the image (an upright camera) joins
// corners 0 and 1, left to right.
std::array<cv::Point2f, 4> orderCorners(std::vector<cv::Point> quad) {
  std::array<cv::Point2f, 4> q;
  for (int i = 0; i < 4; ++i) q[i] = quad[i];
  auto length = [&](int i) { return cv::norm(q[(i + 1) % 4] - q[i]); };
  // Sides i -> i+1; pair (0, 2) or (1, 3) is the width.
  const int first = (length(0) + length(2) >= length(1) + length(3)) ? 0 : 1;
  const int other = first + 2;
  auto midY = [&](int i) { return (q[i].y + q[(i + 1) % 4].y) / 2; };
  const int bottom = midY(first) > midY(other) ? first : other;
  cv::Point2f b0 = q[bottom], b1 = q[(bottom + 1) % 4];
  cv::Point2f t0 = q[(bottom + 3) % 4], t1 = q[(bottom + 2) % 4];  // above b0, above b1
  if (b0.x > b1.x) {
    std::swap(b0, b1);
    std::swap(t0, t1);
  }
  return {b0, b1, t1, t0};
}

// Sub-pixel position, along the normal through p, where the profile crosses halfway
// between its dark and bright levels: the edge between the white rectangle and its
// black border. (Not the gradient maximum: a magnified, bilinearly sampled edge is a
// ramp whose gradient is flat across it.) Nothing when the contrast is too weak.
std::optional<cv::Point2f> edgePoint(const cv::Mat& gray, const cv::Point2f& p,
                                     const cv::Point2f& normal, int reach) {
  std::vector<float> profile;
  for (int k = -reach; k <= reach; ++k) {
    const cv::Point2f q = p + static_cast<float>(k) * normal;
    if (q.x < 1 || q.y < 1 || q.x > gray.cols - 2 || q.y > gray.rows - 2) return std::nullopt;
    cv::Mat v;
    cv::getRectSubPix(gray, {1, 1}, q, v, CV_32F);
    profile.push_back(v.at<float>(0, 0));
  }
  const auto [lo, hi] = std::minmax_element(profile.begin(), profile.end());
  if (*hi - *lo < 60) return std::nullopt;
  const float mid = (*lo + *hi) / 2;
  // The crossing nearest to p.
  double best = std::numeric_limits<double>::max();
  for (int k = 0; k + 1 < static_cast<int>(profile.size()); ++k) {
    const float a = profile[k] - mid, b = profile[k + 1] - mid;
    if ((a < 0) == (b < 0) || a == b) continue;
    const double at = k - reach + a / (a - b);
    if (std::abs(at) < std::abs(best)) best = at;
  }
  if (best == std::numeric_limits<double>::max()) return std::nullopt;
  return p + static_cast<float>(best) * normal;
}

// Corners as intersections of lines fitted (cv::fitLine) to sub-pixel edge points along
// each side, which uses the whole side rather than a window at the corner. A side with
// too few edge points keeps its corners as they were.
std::array<cv::Point2f, 4> refineByEdgeLines(const cv::Mat& gray,
                                             const std::array<cv::Point2f, 4>& c) {
  std::array<cv::Vec4f, 4> lines;
  for (int i = 0; i < 4; ++i) {
    const cv::Point2f a = c[i], b = c[(i + 1) % 4];
    const double length = cv::norm(b - a);
    if (length < 8) return c;
    const cv::Point2f along = (b - a) / static_cast<float>(length);
    const cv::Point2f normal(-along.y, along.x);
    std::vector<cv::Point2f> points;
    const int samples = static_cast<int>(length);
    for (int s = 0; s <= samples; ++s) {
      const double f = 0.15 + 0.7 * s / samples;  // away from the corners
      if (auto e = edgePoint(gray, a + static_cast<float>(f * length) * along, normal, 4))
        points.push_back(*e);
    }
    if (points.size() < 6) return c;
    cv::fitLine(points, lines[i], cv::DIST_HUBER, 0, 0.01, 0.01);
  }
  std::array<cv::Point2f, 4> out;
  for (int i = 0; i < 4; ++i) {
    // Corner i joins side i-1 (ending at it) and side i (starting at it).
    const cv::Vec4f& l1 = lines[(i + 3) % 4];
    const cv::Vec4f& l2 = lines[i];
    const double det = l1[0] * l2[1] - l1[1] * l2[0];
    if (std::abs(det) < 1e-6) return c;
    const double t = ((l2[2] - l1[2]) * l2[1] - (l2[3] - l1[3]) * l2[0]) / det;
    out[i] =
        cv::Point2f(static_cast<float>(l1[2] + t * l1[0]), static_cast<float>(l1[3] + t * l1[1]));
    if (cv::norm(out[i] - c[i]) > 3.0) return c;  // a wild fit: keep the contour's corners
  }
  return out;
}

}  // namespace

std::array<cv::Point3d, 4> targetCornersInMap(const TargetParams& p) {
  const double w = p.width_m / 2, h = p.height_m / 2;
  return {cv::Point3d(-w, -h, 0), cv::Point3d(w, -h, 0), cv::Point3d(w, h, 0),
          cv::Point3d(-w, h, 0)};
}

TargetDetection detectTarget(const cv::Mat& gray, const TargetParams& params) {
  TargetDetection out;
  if (gray.empty() || gray.type() != CV_8UC1) {
    out.reason = "needs a non-empty 8-bit grey image";
    return out;
  }
  if (gray.cols < 8 || gray.rows < 8) {
    out.reason = "image too small";
    return out;
  }
  cv::Mat binary;
  cv::threshold(gray, binary, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(binary, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
  const double expected_aspect = params.width_m / params.height_m;
  double best_contrast = params.min_contrast;
  std::vector<cv::Point> best;
  for (const auto& contour : contours) {
    const double area = cv::contourArea(contour);
    if (area < params.min_area_px) continue;
    std::vector<cv::Point> quad;
    cv::approxPolyDP(contour, quad, 0.03 * cv::arcLength(contour, true), true);
    if (quad.size() != 4 || !cv::isContourConvex(quad)) continue;
    const double s0 = cv::norm(quad[1] - quad[0]) + cv::norm(quad[3] - quad[2]);
    const double s1 = cv::norm(quad[2] - quad[1]) + cv::norm(quad[0] - quad[3]);
    const double aspect = std::max(s0, s1) / std::max(1e-9, std::min(s0, s1));
    // Perspective stretches or shrinks the aspect ratio (a target on the floor seen from
    // 1 m: 2.4 instead of 1.41), so only gross mismatches are rejected.
    if (aspect > expected_aspect * params.max_aspect_distortion ||
        aspect < expected_aspect / params.max_aspect_distortion) {
      continue;
    }
    // White inside, dark in a ring around it (the black border).
    // The whole target, its black border included, must be in view: a bright patch cut
    // by the image edge is not a target, and its corners would be the edge's.
    const int ring = std::max(2, static_cast<int>(0.08 * std::sqrt(area)));
    const cv::Rect clear(ring + 3, ring + 3, gray.cols - 2 * (ring + 3),
                         gray.rows - 2 * (ring + 3));
    if (clear.width <= 0 || clear.height <= 0 ||
        std::any_of(quad.begin(), quad.end(),
                    [&](const cv::Point& p) { return !clear.contains(p); })) {
      continue;
    }
    cv::Mat inside = cv::Mat::zeros(gray.size(), CV_8U), around, margin;
    cv::fillConvexPoly(inside, quad, 255);
    // The ring starts 2 px out, past the edge's blur, and stays within the border
    // (0.05 m of a 0.297 m target: ~17 % of its width).
    cv::dilate(inside, around,
               cv::getStructuringElement(cv::MORPH_RECT, {2 * (ring + 2) + 1, 2 * (ring + 2) + 1}));
    cv::dilate(inside, margin, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
    around -= margin;
    cv::Mat core;
    cv::erode(inside, core, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
    const int core_pixels = cv::countNonZero(core), ring_pixels = cv::countNonZero(around);
    if (core_pixels == 0 || ring_pixels == 0) continue;
    // The target's structure, not just its contrast: bright almost everywhere inside
    // and dark almost everywhere in the ring (its black border). Texture shapes next to
    // dark ones pass a contrast test, not this.
    cv::Mat bright_inside, dark_around;
    cv::bitwise_and(binary, core, bright_inside);
    cv::bitwise_and(~binary, around, dark_around);
    if (cv::countNonZero(bright_inside) < params.min_structure * core_pixels ||
        cv::countNonZero(dark_around) < params.min_structure * ring_pixels) {
      continue;
    }
    // Black around white: the border's mean is a small share of the inside's, whatever
    // the exposure (a light texture patch on grey has ~50 %).
    const double inside_mean = meanIn(gray, core), ring_mean = meanIn(gray, around);
    if (ring_mean > params.max_ring_ratio * inside_mean) continue;
    const double contrast = inside_mean - ring_mean;
    if (contrast > best_contrast) {
      best_contrast = contrast;
      best = quad;
    }
  }
  if (best.empty()) {
    out.reason = "no white quadrilateral with a dark border and the target's aspect ratio";
    return out;
  }
  out.corners = refineByEdgeLines(gray, orderCorners(best));
  out.contrast = best_contrast;
  out.found = true;
  return out;
}

std::optional<TargetPose> cameraPoseFromTarget(const TargetDetection& detection,
                                               const cv::Matx33d& K, const cv::Mat& distortion,
                                               const TargetParams& params) {
  if (!detection.found) return std::nullopt;
  if (!(K(0, 0) > 0) || !(K(1, 1) > 0) || !std::isfinite(K(0, 0)) || !std::isfinite(K(1, 1)) ||
      !std::isfinite(K(0, 2)) || !std::isfinite(K(1, 2))) {
    return std::nullopt;
  }
  const auto map_corners = targetCornersInMap(params);
  const std::vector<cv::Point3d> object(map_corners.begin(), map_corners.end());
  const std::vector<cv::Point2d> image(detection.corners.begin(), detection.corners.end());
  cv::Vec3d rvec, tvec;
  if (!cv::solvePnP(object, image, cv::Mat(K), distortion, rvec, tvec, false, cv::SOLVEPNP_IPPE)) {
    return std::nullopt;
  }
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  const Pose camera_from_map{R, tvec};
  std::vector<cv::Point2d> reprojected;
  cv::projectPoints(object, rvec, tvec, cv::Mat(K), distortion, reprojected);
  double sum = 0;
  for (int i = 0; i < 4; ++i) sum += std::pow(cv::norm(reprojected[i] - image[i]), 2);
  return TargetPose{camera_from_map.inverse(), std::sqrt(sum / 4)};
}

}  // namespace mono_plane_detection
