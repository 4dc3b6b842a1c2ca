#include "mono_plane_detection/mapping/structure_fit.h"

#include <algorithm>
#include <cmath>

#include "mono_plane_detection/geometry/plane_fit.h"

namespace mono_plane_detection {

StructuredPlane structuredPlane(const std::vector<cv::Vec3d>& points,
                                const cv::Vec3d& free_normal, double normal_sigma_deg,
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
  // The points' information on the normal (n' S n / variance: the residuals' chi-square)
  // plus each relation's: a right angle (n . m)^2 / sigma^2, parallel |n x m|^2 / sigma^2.
  cv::Matx33d information = scatter * (1.0 / variance);
  for (const ReferencePlane& ref : references) {
    const double angle = normalAngleDeg(free_normal, ref.normal);
    const double gate = sigmas * std::hypot(normal_sigma_deg, ref.normal_sigma_deg);
    const double sigma_rad = std::max(ref.normal_sigma_deg, 0.01) * CV_PI / 180;
    const cv::Matx33d along = ref.normal * ref.normal.t();
    if (std::abs(angle - 90) <= gate) {
      information += along * (1 / (sigma_rad * sigma_rad));
      ++out.perpendicular;
    } else if (std::min(angle, 180 - angle) <= gate) {
      information += (cv::Matx33d::eye() - along) * (1 / (sigma_rad * sigma_rad));
      ++out.parallel;
    }
  }
  if (out.perpendicular + out.parallel == 0) return out;
  cv::Mat values, vectors;
  cv::eigen(cv::Mat(information), values, vectors);  // descending: the last is the minimum
  cv::Vec3d n(vectors.at<double>(2, 0), vectors.at<double>(2, 1), vectors.at<double>(2, 2));
  if (n.dot(free_normal) < 0) n = -n;
  // The points must not reject it: their residuals may grow by sigmas^2 per degree of
  // freedom the relations take (at most the normal's two).
  const double taken = std::min(2, out.perpendicular + 2 * out.parallel);
  if ((n.dot(scatter * n) - free_ssr) / variance > sigmas * sigmas * taken) {
    out.perpendicular = out.parallel = 0;
    return out;
  }
  out.normal = n;
  out.distance = n.dot(centroid);
  return out;
}

}  // namespace mono_plane_detection
