#include "mono_plane_detection/geometry/plane_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace mono_plane_detection {
namespace {

// Least-squares plane through the chosen points: the centroid and the direction of
// least spread. Also returns the spread along the second direction (collinearity check).
PlaneFit leastSquares(const std::vector<cv::Vec3d>& points, const std::vector<int>& chosen,
                      double& second_spread) {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i : chosen) centroid += Eigen::Vector3d(points[i][0], points[i][1], points[i][2]);
  centroid /= static_cast<double>(chosen.size());
  Eigen::MatrixXd centred(chosen.size(), 3);
  for (size_t k = 0; k < chosen.size(); ++k) {
    const cv::Vec3d& p = points[chosen[k]];
    centred.row(k) = Eigen::Vector3d(p[0], p[1], p[2]) - centroid;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeThinV);
  const Eigen::Vector3d n = svd.matrixV().col(2);
  second_spread = svd.singularValues()(1) / std::sqrt(static_cast<double>(chosen.size()));
  PlaneFit fit;
  fit.normal = cv::Vec3d(n.x(), n.y(), n.z());
  fit.distance = n.dot(centroid);
  fit.ok = true;
  return fit;
}

std::vector<int> within(const std::vector<cv::Vec3d>& points, const cv::Vec3d& n, double d,
                        double max_residual) {
  std::vector<int> in;
  for (size_t i = 0; i < points.size(); ++i)
    if (std::abs(n.dot(points[i]) - d) <= max_residual) in.push_back(static_cast<int>(i));
  return in;
}

}  // namespace

PlaneFit fitPlane(const std::vector<cv::Vec3d>& points, double max_residual_m, int min_points,
                  double min_spread_m) {
  PlaneFit best;
  const int n = static_cast<int>(points.size());
  if (n < std::max(3, min_points)) return best;
  // RANSAC on triples: the points come from an image-space homography, which can mix
  // in a few points of another plane near their common line. Deterministic sampling.
  cv::RNG rng(0x5eed);
  std::vector<int> best_inliers;
  const int tries = std::min(200, n * n);
  for (int t = 0; t < tries; ++t) {
    const int a = rng.uniform(0, n), b = rng.uniform(0, n), c = rng.uniform(0, n);
    if (a == b || b == c || a == c) continue;
    cv::Vec3d normal = (points[b] - points[a]).cross(points[c] - points[a]);
    const double length = cv::norm(normal);
    if (length < 1e-9) continue;
    normal /= length;
    std::vector<int> in = within(points, normal, normal.dot(points[a]), max_residual_m);
    if (in.size() > best_inliers.size()) best_inliers.swap(in);
  }
  if (static_cast<int>(best_inliers.size()) < min_points) return best;
  // Least squares on the consensus, then once more on the points it keeps.
  double spread = 0;
  PlaneFit fit;
  std::vector<int> inliers = best_inliers;
  for (int round = 0; round < 2; ++round) {
    fit = leastSquares(points, inliers, spread);
    std::vector<int> again = within(points, fit.normal, fit.distance, max_residual_m);
    if (static_cast<int>(again.size()) < min_points) break;
    inliers.swap(again);
  }
  fit = leastSquares(points, inliers, spread);
  if (spread < min_spread_m) return best;
  double sum = 0;
  for (int i : inliers) {
    const double r = fit.normal.dot(points[i]) - fit.distance;
    sum += r * r;
  }
  fit.rms_m = std::sqrt(sum / static_cast<double>(inliers.size()));
  fit.inliers = inliers;
  return fit;
}

void orientTowards(PlaneFit& plane, const cv::Vec3d& viewpoint) {
  if (plane.normal.dot(viewpoint) - plane.distance < 0) {
    plane.normal = -plane.normal;
    plane.distance = -plane.distance;
  }
}

void planeAxes(const cv::Vec3d& normal, cv::Vec3d& u, cv::Vec3d& v) {
  // Start from the world axis least aligned with the normal, for a well-conditioned cross.
  const cv::Vec3d helper = std::abs(normal[2]) < 0.9 ? cv::Vec3d(0, 0, 1) : cv::Vec3d(1, 0, 0);
  u = helper.cross(normal);
  u /= cv::norm(u);
  v = normal.cross(u);
}

std::vector<cv::Vec3d> planePolygon(const cv::Vec3d& normal, double distance,
                                    const std::vector<cv::Vec3d>& points) {
  if (points.size() < 3) return {};
  cv::Vec3d u, v;
  planeAxes(normal, u, v);
  std::vector<cv::Point2f> flat;
  flat.reserve(points.size());
  for (const auto& p : points)
    flat.emplace_back(static_cast<float>(u.dot(p)), static_cast<float>(v.dot(p)));
  std::vector<cv::Point2f> hull;
  cv::convexHull(flat, hull, false);  // counter-clockwise in (u, v)
  std::vector<cv::Vec3d> polygon;
  for (const auto& h : hull)
    polygon.push_back(distance * normal + double(h.x) * u + double(h.y) * v);
  return polygon;
}

double normalAngleDeg(const cv::Vec3d& a, const cv::Vec3d& b) {
  const double c = a.dot(b) / (cv::norm(a) * cv::norm(b));
  return std::acos(std::max(-1.0, std::min(1.0, c))) * 180.0 / CV_PI;
}

}  // namespace mono_plane_detection
