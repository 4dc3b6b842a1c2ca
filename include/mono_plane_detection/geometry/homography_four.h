// The homography of exactly four correspondences in closed form: each quadruple is mapped
// from the projective basis (three points scaled so that they sum to the fourth), H = B A^-1.
// About 100 flops against the normalised DLT's 9x9 eigen problem: the coplanarity test
// calls it once per group tried (thousands per image pair).
#pragma once

#include <opencv2/core.hpp>
#include <optional>

namespace mono_plane_detection {

// H with to[k] ~ H from[k], k = 0..3, scaled so that H(2,2) = 1 when that is not ~0.
// Nothing when three of the points in either view are (nearly) collinear.
std::optional<cv::Matx33d> homographyFromFour(const cv::Point2d from[4], const cv::Point2d to[4]);

}  // namespace mono_plane_detection
