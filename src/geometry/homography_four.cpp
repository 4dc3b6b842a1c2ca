#include "mono_plane_detection/geometry/homography_four.h"

#include <cmath>

namespace mono_plane_detection {
namespace {

// The matrix whose columns are p0, p1, p2 (homogeneous) scaled so that they sum to p3.
std::optional<cv::Matx33d> basis(const cv::Point2d p[4]) {
  const cv::Matx33d M(p[0].x, p[1].x, p[2].x, p[0].y, p[1].y, p[2].y, 1.0, 1.0, 1.0);
  const double det = cv::determinant(M);
  // Relative to the triangle's squared size: collinear points give ~0.
  const double size = std::abs(p[1].x - p[0].x) + std::abs(p[1].y - p[0].y) +
                      std::abs(p[2].x - p[0].x) + std::abs(p[2].y - p[0].y);
  if (!std::isfinite(det) || std::abs(det) <= 1e-9 * size * size) return std::nullopt;
  const cv::Vec3d l = M.inv() * cv::Vec3d(p[3].x, p[3].y, 1.0);
  if (std::abs(l[0]) < 1e-12 || std::abs(l[1]) < 1e-12 || std::abs(l[2]) < 1e-12)
    return std::nullopt;  // the fourth point on a line through two others
  return cv::Matx33d(M(0, 0) * l[0], M(0, 1) * l[1], M(0, 2) * l[2], M(1, 0) * l[0],
                     M(1, 1) * l[1], M(1, 2) * l[2], l[0], l[1], l[2]);
}

}  // namespace

std::optional<cv::Matx33d> homographyFromFour(const cv::Point2d from[4], const cv::Point2d to[4]) {
  const auto A = basis(from);
  const auto B = basis(to);
  if (!A || !B) return std::nullopt;
  cv::Matx33d H = *B * A->inv();
  if (std::abs(H(2, 2)) > 1e-15) H *= 1.0 / H(2, 2);
  for (int k = 0; k < 9; ++k)
    if (!std::isfinite(H.val[k])) return std::nullopt;
  return H;
}

}  // namespace mono_plane_detection
