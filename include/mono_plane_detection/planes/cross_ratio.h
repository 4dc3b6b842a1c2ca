// Five-point projective invariants (paper III-B2, figure 6): the two cross ratios of
// five coplanar points, no three collinear. Computed from 3x3 determinants of the
// homogeneous points, which is equivalent to the paper's two four-collinear-point
// cross ratios and needs no line intersections.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/core.hpp>
#include <optional>

namespace mono_plane_detection {

struct FivePointInvariants {
  double i1 = 0.0;  // (m431 m521) / (m421 m531)
  double i2 = 0.0;  // (m421 m532) / (m432 m521), m_ijk = det[p_i p_j p_k]
};

// How far three points are from a line: twice the triangle's area over its longest
// side squared. 0 for collinear or repeated points, about 0.87 for an equilateral
// triangle; independent of scale.
double triangleShape(const cv::Point2d& a, const cv::Point2d& b, const cv::Point2d& c);

// True when every triple of the five points has triangleShape >= min_shape and all
// coordinates are finite.
bool wellSpread(const std::array<cv::Point2d, 5>& p, double min_shape);

// One triple of wellSpread's test, triangleShape(a, b, c) >= min_shape, given its squared
// side lengths |a - b|^2, |b - c|^2, |a - c|^2 (callers testing triples that share sides
// measure each side once). Inline: the group draw runs it for every group tried.
inline bool spreadTriple(const cv::Point2d& a, const cv::Point2d& b, const cv::Point2d& c,
                         double ab2, double bc2, double ac2, double min_shape) {
  const double longest2 = std::max({ab2, bc2, ac2});
  const double det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
  return longest2 > 0.0 && !(std::abs(det) < min_shape * longest2);
}

// The invariants, or nothing when the points are degenerate (see wellSpread).
std::optional<FivePointInvariants> fivePointInvariants(const std::array<cv::Point2d, 5>& p,
                                                       double min_shape = 0.05);

// Relative difference of two invariant pairs: max over i1, i2 of |a-b| / max(|a|,|b|).
// Bounded in [0, 2] and scale-free, so a large invariant does not dominate; opposite
// signs give more than 1.
double invariantDistance(const FivePointInvariants& a, const FivePointInvariants& b);

}  // namespace mono_plane_detection
