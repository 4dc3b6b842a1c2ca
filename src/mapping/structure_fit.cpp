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
  // Whether the points allow this normal: their residuals grow by at most sigmas^2 per
  // degree of freedom taken.
  auto allowed = [&](const cv::Vec3d& n, double taken) {
    const double grown = (n.dot(scatter * n) - free_ssr) / variance;
    return std::isfinite(grown) && grown <= sigmas * sigmas * taken;
  };
  // Each reference on its own: the nearer of its two relations, kept when the points
  // allow the normal fused with it alone (a relation they deny, a turn about an axis they
  // fix, does not cancel the others).
  cv::Matx33d information = own;
  int taken = 0;
  for (const ReferencePlane& ref : references) {
    const double length = cv::norm(ref.normal);
    if (!(length > 0) || !std::isfinite(ref.normal_sigma_deg)) continue;
    const cv::Vec3d m = ref.normal * (1 / length);
    const double angle = normalAngleDeg(free_normal, m);
    const bool right_angle = std::abs(angle - 90) <= std::min(angle, 180 - angle);
    const cv::Matx33d relation = relationInformation(m, right_angle, ref.normal_sigma_deg);
    if (!allowed(smallestDirection(own + relation, free_normal), right_angle ? 1 : 2)) continue;
    information += relation;
    taken += right_angle ? 1 : 2;
    ++(right_angle ? out.perpendicular : out.parallel);
  }
  if (taken == 0) return out;
  const cv::Vec3d n = smallestDirection(information, free_normal);
  if (!allowed(n, std::min(taken, 2))) {  // together they ask more than each alone
    out.perpendicular = out.parallel = 0;
    return out;
  }
  out.normal = n;
  out.distance = n.dot(centroid);
  return out;
}

}  // namespace mono_plane_detection
