// Paper IV-C: a homography per coplanar group, every point whose transfer error is
// under the threshold votes, the most votes wins (the first on ties). Beyond the paper:
// every dominant plane, by voting again among the points no plane has claimed yet.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/planes/coplanar_groups.h"

namespace mono_plane_detection {

struct PlaneParams {
  GroupParams groups;
  double vote_threshold_px = 2.0;  // transfer error to vote (paper: 2 px)
  int min_plane_support = 8;       // a plane needs at least this many points
  int max_planes = 8;              // stop after this many
  int refit_iterations = 4;        // refit on inliers / recompute inliers rounds
  bool robust_refit = true;        // Cauchy re-weighting in the refit
  double merge_fraction = 0.8;     // merge when one refit on both explains this share of each
};

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

struct Plane {
  cv::Matx33d H;              // view 1 pixel -> view 2 pixel
  std::vector<int> inliers;   // indices of the points on the plane, ascending
  double rms_error_px = 0.0;  // transfer error over the inliers
  double score = 0.0;         // share of all points on this plane
};

struct PlaneSegmentation {
  std::vector<Plane> planes;                // by support, largest first
  std::vector<int> labels;                  // per point: 0 = no plane, k >= 1 = planes[k-1]
  int groups_built = 0;                     // five-point groups tried (built and tested)
  int groups_coplanar = 0;                  // of those, accepted by the invariant test
  std::vector<PointGroup> accepted_groups;  // those groups (drawn in debug images)
  std::string error;                        // why nothing could be done (sizes differ, ...)
};

// Every dominant plane between two views of the same points (view1[i] <-> view2[i]).
// Fewer than 5 points: no plane, all labels 0. Deterministic given params.groups.seed.
PlaneSegmentation segmentPlanes(const std::vector<cv::Point2d>& view1,
                                const std::vector<cv::Point2d>& view2,
                                const PlaneParams& params = PlaneParams());

}  // namespace mono_plane_detection
