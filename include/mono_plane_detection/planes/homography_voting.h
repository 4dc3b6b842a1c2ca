// Paper IV-C: a homography per coplanar group, every point whose transfer error is
// under the threshold votes, the most votes wins (the first on ties). Beyond the paper:
// every dominant plane, by voting again among the points no plane has claimed yet.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/planes/coplanar_groups.h"
#include "mono_plane_detection/planes/noise_scale.h"

namespace mono_plane_detection {

// Every threshold is a number of noise scales (sigma, planes/noise_scale.h), estimated
// per image pair unless vote_threshold_px fixes it (then sigma = vote_threshold_px /
// vote_threshold_sigma and every plane uses that threshold). Estimated: the vote counts
// within vote_threshold_sigma, each plane then gets its own noise scale and takes its
// points within inlier_threshold_sigma of it. Number of planes, merges and drops: one
// criterion, the energy sum_points min(r^2 / sigma_plane^2, k^2) + plane_penalty * ln(N)
// per plane (a Gaussian data cost in the plane's own scale, truncated at k, the membership
// threshold in noise scales; a BIC-like label cost, 3 x the BIC's 8 parameters because the
// heavy-tailed residuals make the data cost larger than a Gaussian's, measured on
// AdelaideRMF). The same criterion adds planes, drops, splits and merges them.
struct PlaneParams {
  GroupParams groups;
  double vote_threshold_px = 0.0;       // 0: estimated (inlier_threshold_sigma x noise scale)
  // Real matches have heavy tails (AdelaideRMF: 90th percentile 3-4 median scales), hence
  // a wide membership threshold on a median-based scale (docs/plane_core.md).
  double inlier_threshold_sigma = 8.0;  // a point belongs within this many of its plane's scales
  double vote_threshold_sigma = 4.0;    // the vote counts within this many of the pair's scales
  double plane_penalty = 24.0;          // a plane costs this x ln(N) squared noise scales
  int min_plane_support = 8;            // and needs at least this many points
  int max_planes = 8;                   // stop after this many
  int refit_iterations = 4;             // refit on inliers / recompute inliers rounds
  bool robust_refit = true;             // Cauchy re-weighting in the refit
  NoiseScaleParams noise;               // the estimate's bounds
  int noise_pilot_groups = 20;          // candidate first planes the noise scale is taken from
  // Only plane-induced homographies: F by RANSAC on the points of the planes found, and
  // when it is determined, a plane most of whose points are off their epipolar lines
  // (beyond the vote's threshold) is dropped, and each plane's homography is replaced by
  // the best one F admits when that costs no more than the 5 parameters it saves
  // (planes/epipolar_check.h, docs/plane_core.md).
  bool epipolar_check = true;
};

// The threshold and noise scale params imply when vote_threshold_px fixes them
// (sigma = threshold / vote_threshold_sigma); {0, 0} when they are to be estimated.
struct Thresholds {
  double sigma_px = 0.0;
  double inlier_px = 0.0;
};
Thresholds fixedThresholds(const PlaneParams& params);

// Empty when params are usable by segmentPlanes, else why not (unknown coplanarity test).
std::string checkPlaneParams(const PlaneParams& params);

struct Vote {
  int winner = -1;          // index of the winning homography, -1 when none
  int votes = 0;            // its votes
  std::vector<int> voters;  // the points that voted for it
};

// Paper IV-C over the points with active[i] (all when active is empty).
// vote_bounds (optional, in/out, one per homography, start at INT_MAX): the counts of an
// earlier vote over a superset of the active points. Votes can only fall as points
// leave, so a homography whose bound cannot beat the best so far is not counted again;
// the result is the same as without bounds.
Vote voteDominant(const std::vector<cv::Matx33d>& homographies,
                  const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2,
                  const std::vector<bool>& active, double threshold_px,
                  std::vector<int>* vote_bounds = nullptr);

// Points (among active ones, all when empty) whose transfer error under H is below
// the threshold.
std::vector<int> inliersOf(const cv::Matx33d& H, const std::vector<cv::Point2d>& view1,
                           const std::vector<cv::Point2d>& view2, const std::vector<bool>& active,
                           double threshold_px);

// Least squares on the points, then inliers and refit again, optionally with
// Cauchy weights (scale = threshold) so that points near the threshold count less.
// Returns false when the fit fails.
bool refitPlane(cv::Matx33d& H, std::vector<int>& inliers, const std::vector<cv::Point2d>& view1,
                const std::vector<cv::Point2d>& view2, const std::vector<bool>& active,
                const PlaneParams& params);

// A plane between two views (paper IV): its homography and the points on it. The other
// plane types: ImagePlane (one image's plane with a stable id, mapping/plane_pipeline.h),
// MapPlane (metric, in the map, mapping/plane_map.h), PlaneFit (a 3D fit,
// geometry/plane_fit.h), ScenePlane and TruthPlane (the simulator's and the judge's).
struct HomographyPlane {
  cv::Matx33d H;              // view 1 pixel -> view 2 pixel
  std::vector<int> inliers;   // indices of the points on the plane, ascending
  double rms_error_px = 0.0;  // transfer error over the inliers
  double noise_px = 0.0;      // this plane's noise scale (planes differ: texture, distance)
  double threshold_px = 0.0;  // a point belongs within this (inlier_threshold_sigma x noise_px)
  double score = 0.0;         // share of all points on this plane
};

struct PlaneSegmentation {
  std::vector<HomographyPlane> planes;                // by support, largest first
  std::vector<int> labels;                  // per point: 0 = no plane, k >= 1 = planes[k-1]
  int groups_built = 0;                     // five-point groups tried (built and tested)
  int groups_coplanar = 0;                  // of those, accepted by the invariant test
  std::vector<PointGroup> accepted_groups;  // those groups (drawn in debug images)
  double noise_px = 0.0;                    // noise scale used (estimated or implied)
  double threshold_px = 0.0;                // inlier threshold used
  int duplicates = 0;                       // repeated correspondences (labelled as their first)
  bool epipolar_checked = false;            // a determined fundamental matrix was used
  int rejected_by_epipolar = 0;             // planes it dropped
  std::string error;                        // why nothing could be done (sizes differ, ...)
};

// Every dominant plane between two views of the same points (view1[i] <-> view2[i]).
// Repeated correspondences are removed first (they would count twice) and get their first
// copy's label. Fewer than 5 points: no plane, all labels 0. Deterministic given
// params.groups.seed.
PlaneSegmentation segmentPlanes(const std::vector<cv::Point2d>& view1,
                                const std::vector<cv::Point2d>& view2,
                                const PlaneParams& params = PlaneParams());

}  // namespace mono_plane_detection
