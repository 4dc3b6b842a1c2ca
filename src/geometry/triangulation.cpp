#include "mono_plane_detection/geometry/triangulation.h"

#include <cmath>
#include <opencv2/calib3d.hpp>

namespace mono_plane_detection {
namespace {

// Depth and reprojection error of x in the camera P.
double reproject(const cv::Matx34d& P, const cv::Vec3d& x, const cv::Point2d& n, double& depth) {
  const cv::Vec3d c = P * cv::Vec4d(x[0], x[1], x[2], 1.0);
  depth = c[2];
  return std::hypot(c[0] / c[2] - n.x, c[1] / c[2] - n.y);
}

}  // namespace

cv::Matx34d projectionMatrix(const cv::Matx33d& R, const cv::Vec3d& t) {
  return {R(0, 0), R(0, 1), R(0, 2), t[0], R(1, 0), R(1, 1), R(1, 2), t[1],
          R(2, 0), R(2, 1), R(2, 2), t[2]};
}

std::optional<TwoViewPoint> triangulate(const cv::Matx34d& P1, const cv::Matx34d& P2,
                                        const cv::Point2d& n1, const cv::Point2d& n2) {
  cv::Mat X;
  cv::triangulatePoints(cv::Mat(P1), cv::Mat(P2), cv::Mat(cv::Matx21d(n1.x, n1.y)),
                        cv::Mat(cv::Matx21d(n2.x, n2.y)), X);
  const double w = X.at<double>(3);
  if (!(std::abs(w) >= 1e-12)) return std::nullopt;
  TwoViewPoint p;
  p.x = cv::Vec3d(X.at<double>(0) / w, X.at<double>(1) / w, X.at<double>(2) / w);
  if (!std::isfinite(p.x[0]) || !std::isfinite(p.x[1]) || !std::isfinite(p.x[2])) return std::nullopt;
  p.error = std::max(reproject(P1, p.x, n1, p.depth1), reproject(P2, p.x, n2, p.depth2));
  return p;
}

double sampsonDistance(const cv::Matx33d& F, const cv::Point2d& x1, const cv::Point2d& x2) {
  const cv::Vec3d a(x1.x, x1.y, 1.0), b(x2.x, x2.y, 1.0);
  const cv::Vec3d Fa = F * a, Ftb = F.t() * b;
  const double den = Fa[0] * Fa[0] + Fa[1] * Fa[1] + Ftb[0] * Ftb[0] + Ftb[1] * Ftb[1];
  return den > 0 ? std::abs(b.dot(Fa)) / std::sqrt(den) : 0.0;
}

}  // namespace mono_plane_detection
