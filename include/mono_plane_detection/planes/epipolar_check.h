// Only plane-induced homographies: a homography H induced by a plane between two views
// with fundamental matrix F satisfies H^T F + F^T H = 0 (Hartley & Zisserman, 13.1), i.e.
// H x lies on the epipolar line F x of every point x. A homography that fits points of
// two planes at once, or of no plane, does not.
#pragma once

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace mono_plane_detection {

// F (view 1 -> view 2: x2^T F x1 = 0) by RANSAC with the given threshold, or nothing when
// there are fewer than 15 points or its inliers are fewer than min_inlier_share of them.
// (A scene of one plane leaves F undetermined; then F says nothing about H.)
std::optional<cv::Matx33d> estimateFundamental(const std::vector<cv::Point2d>& view1,
                                               const std::vector<cv::Point2d>& view2,
                                               double threshold_px, double min_inlier_share = 0.3,
                                               unsigned seed = 1);

// Median over `probe` (view-1 points) of the distance in view 2 between H x and the
// epipolar line F x, pixels: 0 for a plane-induced H. Infinity when no probe gives one.
double epipolarTransferError(const cv::Matx33d& H, const cv::Matx33d& F,
                             const std::vector<cv::Point2d>& probe);

// Distance in view 2 from x2 to the epipolar line F x1, pixels (infinity when F x1 is not
// a line).
double epipolarLineDistance(const cv::Matx33d& F, const cv::Point2d& x1, const cv::Point2d& x2);

// The algebraic form: || H^T F + F^T H || / (2 || H^T F ||) with H, F at unit norm;
// 0 when H^T F is skew-symmetric (plane-induced), up to 1.
double skewSymmetryError(const cv::Matx33d& H, const cv::Matx33d& F);

// F through the points (view 1 -> view 2: x2^T F x1 = 0) by the normalised eight-point
// least squares, rank 2 enforced, then `rounds` re-weighted rounds (Cauchy weights on the
// Sampson distance at scale_px): the precise F once RANSAC has found the inliers (points
// of one plane leave a family of F: the caller checks that they span two). Nothing when
// fewer than 8 points or a family of F fits exactly.
std::optional<cv::Matx33d> refineFundamental(const std::vector<cv::Point2d>& view1,
                                             const std::vector<cv::Point2d>& view2,
                                             double scale_px, int rounds = 3);

// The plane-induced homography through the points, given the homography H1 of one plane
// and the epipole e2 of view 2 (or H1 = [e2]x F): H = H1 + e2 v^T (every homography a
// plane induces has this form; 3 unknowns instead of 8), v by least squares on the
// transfer error (linearised, re-weighted), optionally with a weight per point. Nothing
// when fewer than 3 points or the points do not fix v.
std::optional<cv::Matx33d> fitInducedHomography(const cv::Matx33d& H1, const cv::Vec3d& e2,
                                                const std::vector<cv::Point2d>& from,
                                                const std::vector<cv::Point2d>& to,
                                                const std::vector<double>& weights = {});

}  // namespace mono_plane_detection
