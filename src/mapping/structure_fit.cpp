#include "mono_plane_detection/mapping/structure_fit.h"

#include <algorithm>
#include <cmath>

#include "mono_plane_detection/geometry/plane_fit.h"

namespace mono_plane_detection {
namespace {

// A relation's information on the normal: a right angle to m, (n . m)^2 / sigma^2; the
// parallel, |n x m|^2 / sigma^2 (sigma in rad).
cv::Matx33d relationInformation(const cv::Vec3d& m, bool right_angle, double sigma_deg) {
  const double sigma = std::max(sigma_deg, 0.01) * CV_PI / 180;
  const cv::Matx33d along = m * m.t();
  return (right_angle ? along : cv::Matx33d::eye() - along) * (1 / (sigma * sigma));
}

// The unit normal minimising n' A n (the smallest eigenvector), on the side of `side`.
cv::Vec3d smallestDirection(const cv::Matx33d& a, const cv::Vec3d& side) {
  cv::Mat values, vectors;
  cv::eigen(cv::Mat(a), values, vectors);  // descending: the last row is the minimum
  cv::Vec3d n(vectors.at<double>(2, 0), vectors.at<double>(2, 1), vectors.at<double>(2, 2));
  return n.dot(side) < 0 ? -n : n;
}

}  // namespace

StructuredPlane structuredPlane(const std::vector<cv::Vec3d>& points,
                                const cv::Vec3d& free_normal,
                                const std::vector<ReferencePlane>& references, double sigmas,
                                double floor_m) {
  StructuredPlane out;
  out.normal = free_normal;
  if (points.empty()) return out;
  cv::Vec3d centroid(0, 0, 0);
  for (const auto& p : points) centroid += p;
  centroid *= 1.0 / static_cast<double>(points.size());
  out.distance = free_normal.dot(centroid);
  if (sigmas <= 0 || points.size() < 4 || references.empty()) return out;

  cv::Matx33d scatter = cv::Matx33d::zeros();
  for (const auto& p : points) scatter += (p - centroid) * (p - centroid).t();
  const double free_ssr = free_normal.dot(scatter * free_normal);
  const double variance =
      std::max(free_ssr / static_cast<double>(points.size() - 3), floor_m * floor_m);
  if (!(variance > 0) || !std::isfinite(variance)) return out;
  // The points' information on the normal: n' S n / variance is their residuals' chi-square.
  const cv::Matx33d own = scatter * (1.0 / variance);
  const double free_chi = free_ssr / variance;
  // Whether the points allow the fused normal: their residuals grow by at most sigmas^2
  // per degree of freedom the relations take (at most the normal's two). Not the
  // innovation's chi-square (growth plus the priors' own cost): the planes' sigmas count
  // their points as independent and are 1.5-5 times too small (docs/mapping.md), so it
  // refused true right angles (furnished runs: mean normal error 0.34 against 0.32 deg,
  // worst 1.09 against 0.69). A loose reference far from a well-known plane may pass
  // this way, but it moves it only by its share, angle x s_p^2 / (s_p^2 + s_r^2).
  auto agree = [&](const cv::Matx33d& information, int taken, cv::Vec3d& n) {
    n = smallestDirection(information, free_normal);
    const double grown = n.dot(own * n) - free_chi;
    return std::isfinite(grown) && grown <= sigmas * sigmas * std::min(taken, 2);
  };
  // Best-known reference first, each with the nearer of its two relations, kept while
  // the kept ones and it still agree with the points: a relation they deny (a turn about
  // an axis they fix) is left out without the others.
  std::vector<ReferencePlane> order = references;
  std::stable_sort(order.begin(), order.end(), [](const ReferencePlane& a, const ReferencePlane& b) {
    return a.normal_sigma_deg < b.normal_sigma_deg;
  });
  cv::Matx33d information = own;
  int taken = 0;
  cv::Vec3d n = free_normal;
  for (const ReferencePlane& ref : order) {
    const double length = cv::norm(ref.normal);
    if (!(length > 0) || !std::isfinite(length) || !std::isfinite(ref.normal_sigma_deg)) continue;
    const cv::Vec3d m = ref.normal * (1 / length);
    const double angle = normalAngleDeg(free_normal, m);
    const bool right_angle = std::abs(angle - 90) <= std::min(angle, 180 - angle);
    const cv::Matx33d with = information + relationInformation(m, right_angle, ref.normal_sigma_deg);
    const int with_taken = taken + (right_angle ? 1 : 2);
    cv::Vec3d candidate;
    if (!agree(with, with_taken, candidate)) continue;
    information = with;
    taken = with_taken;
    n = candidate;
    ++(right_angle ? out.perpendicular : out.parallel);
  }
  if (taken == 0) return out;
  out.normal = n;
  out.distance = n.dot(centroid);
  return out;
}

}  // namespace mono_plane_detection
