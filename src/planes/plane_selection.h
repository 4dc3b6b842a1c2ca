// Moves on the planes the vote found, each decided by one model-selection criterion
// (Energy): merge two planes that are one, split one that holds two, assign every point to
// the plane that explains it at least cost and drop planes that do not pay for their
// label, keep only plane-induced homographies (planes/epipolar_check.h). Internal to
// src/planes/ (homography_voting.cpp runs them; docs/plane_core.md says why each).
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/planes/homography_voting.h"

namespace mono_plane_detection {
namespace voting {

// The model-selection criterion (PlaneParams), -2 log-likelihood up to a constant: a
// point on plane p costs r^2 / sigma_p^2 + 4 ln(sigma_p / sigma) (a Gaussian of the
// plane's own scale, so that a plane made broad by points of two planes pays for its
// width), truncated at k^2, an outlier's cost.
struct Energy {
  double k2;                  // (membership threshold in noise scales)^2: an outlier's cost
  double sigma;               // the image pair's noise scale
  double plane_cost;          // label cost of one plane
  double fixed_threshold_px;  // > 0: the user's threshold, every plane's
  // width_cost: widthCost(p), computed once per plane (a logarithm per point otherwise).
  // On the squared transfer error (no square root): the assignment, split and merge
  // evaluate it for every point and plane, several times.
  double point(const HomographyPlane& p, const cv::Point2d& a, const cv::Point2d& b,
               double width_cost) const {
    const double e2 = transferErrorSquaredOneDivision(p.H, a, b);
    // As selects: every point and plane of the assignment's table, no pattern to predict.
    const double inside = std::min(e2 / (p.noise_px * p.noise_px) + width_cost, k2);
    return e2 < p.threshold_px * p.threshold_px ? inside : k2;
  }
  double widthCost(const HomographyPlane& p) const { return 4.0 * std::log(p.noise_px / sigma); }
  double sum(const HomographyPlane& p, const std::vector<int>& idx,
             const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2) const {
    double e = 0.0;
    const double width = widthCost(p);
    for (int i : idx) e += point(p, view1[i], view2[i], width);
    return e;
  }
};

// The plane's noise scale from its residuals over the points (medianScale from the
// image pair's scale, kept within a factor 4 of it), and its threshold.
void setPlaneNoise(HomographyPlane& plane, const std::vector<cv::Point2d>& view1,
                   const std::vector<cv::Point2d>& view2, const std::vector<int>& among,
                   const Energy& energy, const PlaneParams& params);

// Planes found one after another can be the same physical plane (split by noise):
// two are merged when the criterion says so: one homography refitted on both costs less
// than the two, one plane's label cost included. Best merge first, until none pays.
// Returns whether any two were merged.
bool mergeSamePlanes(std::vector<HomographyPlane>& planes, const std::vector<cv::Point2d>& view1,
                     const std::vector<cv::Point2d>& view2, const PlaneParams& params,
                     const Energy& energy);

// A plane found by the vote can hold two physical planes whose homographies agree within
// the vote's threshold. Split move under the same criterion: the candidate with most votes
// among the plane's points that does not explain nearly all of them, and the best
// candidate on the rest, each refitted with its own scale; the plane is replaced by the
// two when their cost plus one more label cost is below its cost. Returns whether any
// plane was split.
bool splitPlanes(std::vector<HomographyPlane>& planes, const std::vector<cv::Matx33d>& candidates,
                 const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2,
                 const PlaneParams& params, const Energy& energy, double vote_px);

// Alternates assigning every point to its best plane and refitting each plane on its
// points until the labels stop changing: pieces found early, which hold a few points of
// a neighbouring plane, give those points back. Leaves planes[k].inliers set. Returns
// whether the labels settled (a refit changed none) within refit_iterations rounds.
bool refineAssignment(std::vector<HomographyPlane>& planes, const std::vector<cv::Point2d>& view1,
                      const std::vector<cv::Point2d>& view2, const PlaneParams& params,
                      const Energy& energy);

// Only plane-induced homographies (planes/epipolar_check.h): the points of a plane whose
// homography a plane induces lie on their epipolar lines. F by RANSAC on the points of
// the planes found (the outliers left out: few samples are needed and a degenerate sample,
// mostly from one plane, loses to the true F), at the vote's threshold; when it is
// determined (its inliers hold at least a plane's worth of points off the plane holding
// most of them: points of one plane and a few others leave a family of F), a plane most of
// whose points are off their epipolar lines is dropped (on EuRoC: repeated texture matched
// one period off, consistent with a homography but not with the epipolar geometry), and
// otherwise the plane whose points are farthest off beyond chance
// (epipolarOffsetScore above epipolarOffsetThreshold: a cluster of 17 mismatched points
// whose median is just within the threshold); its points go to the other planes or become
// outliers. After a drop F is estimated again without the plane (which pulled F towards
// itself and off the others) and the planes checked again.
void dropNonInduced(std::vector<HomographyPlane>& planes, const std::vector<cv::Point2d>& view1,
                    const std::vector<cv::Point2d>& view2, const PlaneParams& params,
                    const Energy& energy, double vote_px, PlaneSegmentation& out);

}  // namespace voting
}  // namespace mono_plane_detection
