// Only plane-induced homographies: a homography H induced by a plane between two views
// with fundamental matrix F satisfies H^T F + F^T H = 0 (Hartley & Zisserman, 13.1), i.e.
// H x lies on the epipolar line F x of every point x. A homography that fits points of
// two planes at once, or of no plane, does not.
#pragma once

#include <functional>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "mono_plane_detection/planes/homography_voting.h"

namespace mono_plane_detection {

// F (view 1 -> view 2: x2^T F x1 = 0) by RANSAC with the given threshold, or nothing when
// there are fewer than 15 points or its inliers (both points within the threshold of their
// epipolar lines) are fewer than min_inlier_share of all points. (A scene of one plane
// leaves F undetermined; then F says nothing about H.) With OpenCV 4.5.2 or later
// (geometry/opencv_usac.h) OpenCV's USAC (USAC_FAST, its own fixed seed) on at most
// max_sample points, every (n / max_sample)-th of the list (give it plane after plane:
// each keeps its share); before (Noetic's 4.2; or built with -DMPD_FORCE_PLAIN_RANSAC)
// the plain RANSAC on all points, drawing from `seed`, its F polished on its inliers
// (refineFundamental) as USAC's is. USAC's F, and so the figures measured with it, may
// differ between OpenCV versions (measured on 4.6).
std::optional<cv::Matx33d> estimateFundamental(const std::vector<cv::Point2d>& view1,
                                               const std::vector<cv::Point2d>& view2,
                                               double threshold_px, double min_inlier_share = 0.3,
                                               unsigned seed = 1, size_t max_sample = 256);

// Median over `probe` (view-1 points) of the distance in view 2 between H x and the
// epipolar line F x, pixels: 0 for a plane-induced H. Infinity when no probe gives one.
double epipolarTransferError(const cv::Matx33d& H, const cv::Matx33d& F,
                             const std::vector<cv::Point2d>& probe);

// Distance in view 2 from x2 to the epipolar line F x1, pixels (infinity when F x1 is not
// a line).
double epipolarLineDistance(const cv::Matx33d& F, const cv::Point2d& x1, const cv::Point2d& x2);

// How far beyond chance a plane's points sit from their epipolar lines: a genuine
// plane's distances are |N(0, s)|, median 0.674 s, and under that model the median of n
// of them has a standard error of 0.79 s / sqrt(n). Real residuals are over-dispersed
// against it (genuine AdelaideRMF planes reached 3.05 such errors), so the error is taken
// 1.59 times wider, 1.25 s / sqrt(n): an empirical factor measured on the development
// data, not the normal model's (docs/plane_core.md, design item 7). So
// (median - 0.674 s) / (1.25 s / sqrt(n)); s is the larger of the plane's own noise scale
// and epipolarScale over every plane's points (what F's own error and the calibration
// add). A mismatched cluster of 17 points 2.5 scales off its lines scores 6; minus
// infinity without distances or without a positive scale.
double epipolarOffsetScore(const std::vector<double>& distances, double scale_px);

// The score beyond which one of `planes` planes tested together is off its epipolar lines:
// the normal quantile of one-sided 0.1 % for all of them at once (0.1 % / planes each,
// Bonferroni), as the vote's bail-out's 3.09 for one: 3.29 for two planes, 3.40 for
// three. With the widened error of epipolarOffsetScore the level under Gaussian noise is
// far below 0.1 % (about 5e-7 for one plane); each round after a drop tests again.
double epipolarOffsetThreshold(size_t planes);

// The scale of distances to the epipolar lines, |N(0, s)|: their median / 0.674.
double epipolarScale(const std::vector<double>& distances);

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

// fitInducedHomography through points whose noise scales differ (pieces of one plane in
// different parts of the image, e.g. where the lens model is poorer): `rounds` re-weighted
// fits, each point weighted by Cauchy(r / 2s) / s^2 (s its scale, r its transfer error:
// residual_px in the first round, then the last fit's). Nothing when a fit fails or the
// sizes differ.
std::optional<cv::Matx33d> fitInducedRobust(const cv::Matx33d& H1, const cv::Vec3d& e2,
                                            const std::vector<cv::Point2d>& from,
                                            const std::vector<cv::Point2d>& to,
                                            const std::vector<double>& scale_px,
                                            const std::vector<double>& residual_px, int rounds = 3);

// The terms of the segmentation's criterion (planes/homography_voting.cpp) that
// mergeInducedPieces uses.
struct PlaneCriterion {
  // The points' costs under a plane at the plane's own scale (outlier_cost at most).
  std::function<std::vector<double>(const HomographyPlane&, const std::vector<int>&)> costs;
  // The plane's noise scale and threshold from its residuals over these points.
  std::function<void(HomographyPlane&, const std::vector<int>&)> measure;
  // Every point to its cheapest plane; planes that do not pay dropped.
  std::function<void(std::vector<HomographyPlane>&)> assign;
  double outlier_cost = 0.0;
  double label_cost = 0.0;  // one plane's
};

// Pieces of one 3D plane merged, judged in the family of homographies F induces
// (H1 + e2 v^T, H1 = [e2]x F): each plane's induced fit at its own measured scale; two
// planes are merged when one induced homography through both, each piece's points costed
// at that piece's scale, is cheaper than the two induced fits plus one label cost (every
// point keeping its cheapest label). A piece's own scale holds what the camera model gets
// wrong in its part of the image, so that a strip of tape on the floor, whose free
// homography fits the lens model's error there (not plane-induced: 16-49 deg off), joins
// the floor. Best merge first; the merged plane takes the induced homography and a scale
// measured over the union (mostly the larger piece's). That is a deliberate trade: at one
// scale for both the criterion would keep a strip apart (EuRoC: gains -191 and -178,
// docs/plane_core.md), so this move puts an induced homography before the criterion's
// optimum. Points assigned again after each. Only planes whose induced fit pays for itself
// take part. Returns the number of merges.
int mergeInducedPieces(std::vector<HomographyPlane>& planes, const cv::Matx33d& H1,
                       const cv::Vec3d& e2, const std::vector<cv::Point2d>& view1,
                       const std::vector<cv::Point2d>& view2, const PlaneCriterion& criterion);

}  // namespace mono_plane_detection
