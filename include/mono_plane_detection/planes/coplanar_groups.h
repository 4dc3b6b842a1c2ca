// Groups of five points for the coplanarity test (paper IV-A, IV-B): chosen among near
// neighbours with a matrix of Euclidean distances, no three collinear, and accepted
// when their five-point invariants agree between the two images.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace mono_plane_detection {

using PointGroup = std::array<int, 5>;  // indices into the point arrays

struct GroupParams {
  int max_groups = 300;      // coplanar groups kept per image, so the cost stays bounded
  int groups_per_point = 4;  // fewer points -> fewer groups (max_groups still caps)
  int max_tries = 6000;      // groups tried at most: with many outliers few pass
  int tries_per_point = 15;  // fewer points -> fewer tries (max_tries still caps) ...
  int min_tries = 2000;      // ... but few points need as many tries as the paper's 40 / point
  int max_seeds = 2000;      // seed points with a neighbour list (bounds memory)
  int neighbours = 10;       // a group is a seed and 4 of its nearest neighbours
  // Groups drawn per four points: the seed and 3 neighbours, each with this many of the
  // seed's other neighbours as the fifth point (1: the paper's one group per draw). Every
  // group is still a five-point group and counts as one try; the four's homography and
  // spread test are shared, so a try costs a fraction of a draw.
  int fifth_points = 7;
  // Neighbours closer than this to the seed are passed over: the invariants' relative
  // error grows as pixel noise / group spread, and tight groups fail the test by noise.
  double min_neighbour_distance_px = 30.0;
  double min_shape = 0.05;           // triangleShape below this is "collinear" (paper IV-A)
  // "transfer": the fifth point's transfer error under the homography of the other four
  // is at most transfer_threshold_sigma noise scales; "cross_ratio": the paper's test,
  // the invariants agree within invariant_threshold (relative, blind to the noise).
  std::string coplanarity_test = "transfer";
  double transfer_threshold_sigma = 10.0;  // a 4-point homography amplifies the noise
  double invariant_threshold = 0.1;  // invariantDistance at most this is "coplanar"
  unsigned seed = 1;                 // random choices are deterministic given the seed
};

// Distances from each seed to every point: the rows of the paper's distance matrix
// that the groups need (all rows would be N x N memory for nothing).
cv::Mat distanceRows(const std::vector<cv::Point2d>& points, const std::vector<int>& seeds);

// Draws groups on demand: a seed (seeds visited in a random order, round after round)
// with 4 random points among its `neighbours` nearest at min_neighbour_distance_px or
// more (the nearest of all when fewer than 4 are that far), every triple well spread.
// With fifth_points > 1 the seed and 3 random neighbours are drawn once and up to
// fifth_points random others of its neighbours complete them, one group each (the
// groups of one four follow each other; group[0..3] is the four, group[4] the fifth). A
// seed's row of the distance matrix is computed on its first visit only, so the cost
// follows the groups drawn, not N x N. Deterministic given params.seed.
class GroupSampler {
 public:
  GroupSampler(const std::vector<cv::Point2d>& points, const GroupParams& params);
  // The next well-spread group; false when none is left to draw (fewer than 5
  // points, or 4 draws per requested group failed in a row of degenerate neighbours).
  bool next(PointGroup& group);

 private:
  std::vector<int>& neighboursOf(size_t seed_slot);
  // The next fifth point of the last four drawn that keeps the five well spread.
  bool nextFifth(PointGroup& group);

  const std::vector<cv::Point2d>& points_;
  GroupParams params_;
  std::mt19937 rng_;
  std::vector<int> seeds_;
  std::vector<std::vector<int>> near_;  // per seed slot, empty until visited
  std::vector<std::pair<double, int>> nearest_;  // neighboursOf's list, reused across seeds
  // A uniform grid of the points for the neighbour search (no cells: scan all points).
  cv::Point2d grid_origin_;
  double cell_px_ = 0.0;
  int cols_ = 0, rows_ = 0;
  std::vector<int> cell_start_;   // cell c holds cell_points_[cell_start_[c] .. cell_start_[c+1])
  std::vector<int> cell_points_;  // point indices, cell by cell
  long draws_ = 0;
  long failures_in_a_row_ = 0;
  // The last four drawn (seed slot, its neighbour list's first 3) and its fifth points
  // still to give: near_[four_slot_][next_fifth_ .. end_fifth_).
  size_t four_slot_ = 0;
  int next_fifth_ = 0, end_fifth_ = 0;
  double four_edge2_[4][4] = {};  // its squared edges, [i][j] for i < j
};

// Up to `count` groups from a GroupSampler.
std::vector<PointGroup> buildGroups(const std::vector<cv::Point2d>& points,
                                    const GroupParams& params, int count);

// Paper IV-A + IV-B: groups tried in GroupSampler's order until min(max_groups,
// groups_per_point * N) pass isCoplanarGroup or triesFor(params, N) were tried. A group drawn again is skipped (it would give the same homography).
struct CoplanarGroups {
  std::vector<PointGroup> groups;  // the accepted ones
  int tried = 0;
};
// sigma_px: the noise scale the transfer test counts in (segmentPlanes estimates it);
// 0 or less falls back to the cross-ratio test.
CoplanarGroups findCoplanarGroups(const std::vector<cv::Point2d>& view1,
                                  const std::vector<cv::Point2d>& view2, const GroupParams& params,
                                  double sigma_px = 0.0);

// The coplanarity test params.coplanarity_test names (see GroupParams). Cross ratio
// (paper IV-B): the group's invariants in view 1 equal those in view 2 within the
// threshold; false when either view is degenerate. Transfer: fifthPointError is at most
// transfer_threshold_sigma * sigma_px (cross ratio when sigma_px <= 0).
bool isCoplanarGroup(const PointGroup& group, const std::vector<cv::Point2d>& view1,
                     const std::vector<cv::Point2d>& view2, const GroupParams& params,
                     double sigma_px = 0.0);

// Transfer error (pixels, in view 2) of the group's fifth point under the homography the
// first four define; infinity when those four are degenerate in either view.
double fifthPointError(const PointGroup& group, const std::vector<cv::Point2d>& view1,
                       const std::vector<cv::Point2d>& view2);

// Groups tried at most for this many points: tries_per_point per point, at least
// min_tries, at most max_tries.
long triesFor(const GroupParams& params, size_t points);

// True for the two test names GroupParams::coplanarity_test accepts.
bool knownCoplanarityTest(const std::string& name);

}  // namespace mono_plane_detection
