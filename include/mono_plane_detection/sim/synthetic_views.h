// Generated imagery with exact ground truth, for tests and benchmarks: a textured
// plane seen through known homographies. (Full indoor scenes are the renderer's job.)
#pragma once

#include <opencv2/core.hpp>

namespace mono_plane_detection {

// A grey texture rich in corners (random rectangles and triangles on a noisy
// background, lightly blurred so corners are sub-pixel stable). Deterministic in seed.
cv::Mat makeCornerTexture(const cv::Size& size, unsigned seed);

// The view of `texture` through H (texture pixel -> view pixel), bilinear sampling,
// black outside the texture.
cv::Mat warpView(const cv::Mat& texture, const cv::Matx33d& H, const cv::Size& view_size);

// Maps a pixel through H.
cv::Point2d transfer(const cv::Matx33d& H, const cv::Point2d& p);

// Homography of a similarity: rotation by angle_rad about `center`, then a shift.
cv::Matx33d similarity(double angle_rad, const cv::Point2d& center, const cv::Point2d& shift,
                       double scale = 1.0);

}  // namespace mono_plane_detection
