#include "mono_plane_detection/planes/cross_ratio.h"

#include <algorithm>
#include <cmath>

namespace mono_plane_detection {
namespace {

double det3(const cv::Point2d& a, const cv::Point2d& b, const cv::Point2d& c) {
  return (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
}

double relativeDifference(double a, double b) {
  const double scale = std::max(std::abs(a), std::abs(b));
  return scale > 0.0 ? std::abs(a - b) / scale : 0.0;
}

}  // namespace

double triangleShape(const cv::Point2d& a, const cv::Point2d& b, const cv::Point2d& c) {
  const double longest2 = std::max({(a - b).dot(a - b), (b - c).dot(b - c), (c - a).dot(c - a)});
  if (!(longest2 > 0.0) || !std::isfinite(longest2)) return 0.0;
  return std::abs(det3(a, b, c)) / longest2;
}

bool wellSpread(const std::array<cv::Point2d, 5>& p, double min_shape) {
  for (const auto& q : p) {
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) return false;
  }
  // triangleShape for all 10 triples, with each of the 10 edges measured once: this
  // runs for every group tried.
  double edge2[5][5];
  for (int i = 0; i < 5; ++i)
    for (int j = i + 1; j < 5; ++j) edge2[i][j] = (p[i] - p[j]).dot(p[i] - p[j]);
  for (int i = 0; i < 5; ++i)
    for (int j = i + 1; j < 5; ++j)
      for (int k = j + 1; k < 5; ++k)
        if (!spreadTriple(p[i], p[j], p[k], edge2[i][j], edge2[j][k], edge2[i][k], min_shape))
          return false;
  return true;
}

std::optional<FivePointInvariants> fivePointInvariants(const std::array<cv::Point2d, 5>& p,
                                                       double min_shape) {
  if (!wellSpread(p, min_shape)) return std::nullopt;
  // Indices 1..5 of the textbook formula are p[0]..p[4]. Each point appears equally
  // often above and below the fraction, so the projective scale factors cancel.
  auto m = [&p](int i, int j, int k) { return det3(p[i - 1], p[j - 1], p[k - 1]); };
  FivePointInvariants out;
  out.i1 = (m(4, 3, 1) * m(5, 2, 1)) / (m(4, 2, 1) * m(5, 3, 1));
  out.i2 = (m(4, 2, 1) * m(5, 3, 2)) / (m(4, 3, 2) * m(5, 2, 1));
  return out;
}

double invariantDistance(const FivePointInvariants& a, const FivePointInvariants& b) {
  return std::max(relativeDifference(a.i1, b.i1), relativeDifference(a.i2, b.i2));
}

}  // namespace mono_plane_detection
