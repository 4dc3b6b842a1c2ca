#include "mono_plane_detection/planes/homography_voting.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "mono_plane_detection/geometry/homography_fit.h"

namespace mono_plane_detection {
namespace {

bool isActive(const std::vector<bool>& active, size_t i) { return active.empty() || active[i]; }

std::vector<cv::Point2d> select(const std::vector<cv::Point2d>& p, const std::vector<int>& idx) {
  std::vector<cv::Point2d> out;
  out.reserve(idx.size());
  for (int i : idx) out.push_back(p[i]);
  return out;
}

bool finite(const cv::Point2d& p) { return std::isfinite(p.x) && std::isfinite(p.y); }

double rmsError(const cv::Matx33d& H, const std::vector<int>& idx,
                const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2) {
  double sum = 0.0;
  for (int i : idx) {
    const double e = transferError(H, view1[i], view2[i]);
    sum += e * e;
  }
  return idx.empty() ? 0.0 : std::sqrt(sum / idx.size());
}

// One homography per group that passes the invariant test (paper IV-B, IV-C).
std::vector<cv::Matx33d> coplanarGroupHomographies(const std::vector<cv::Point2d>& view1,
                                                   const std::vector<cv::Point2d>& view2,
                                                   const GroupParams& params,
                                                   PlaneSegmentation& out) {
  const CoplanarGroups found = findCoplanarGroups(view1, view2, params);
  out.groups_built = found.tried;
  out.groups_coplanar = static_cast<int>(found.groups.size());
  out.accepted_groups = found.groups;
  std::vector<cv::Matx33d> homographies;
  for (const PointGroup& g : found.groups) {
    const std::vector<int> idx(g.begin(), g.end());
    if (auto H = fitHomography(select(view1, idx), select(view2, idx))) homographies.push_back(*H);
  }
  return homographies;
}

// Planes found one after another can be the same physical plane (split by noise):
// merge two when one homography fitted on both explains most of each.
void mergeSamePlanes(std::vector<Plane>& planes, const std::vector<cv::Point2d>& view1,
                     const std::vector<cv::Point2d>& view2, const PlaneParams& params) {
  for (bool merged = true; merged;) {
    merged = false;
    for (size_t i = 0; i < planes.size() && !merged; ++i) {
      for (size_t j = i + 1; j < planes.size() && !merged; ++j) {
        std::vector<int> both = planes[i].inliers;
        both.insert(both.end(), planes[j].inliers.begin(), planes[j].inliers.end());
        // Judged after the same robust refit a plane gets, on the union's points only.
        auto H = fitHomography(select(view1, both), select(view2, both));
        if (!H) continue;
        std::vector<bool> in_union(view1.size(), false);
        for (int k : both) in_union[k] = true;
        std::vector<int> union_inliers = both;
        if (!refitPlane(*H, union_inliers, view1, view2, in_union, params)) continue;
        auto explained = [&](const std::vector<int>& idx) {
          int n = 0;
          for (int k : idx) n += transfersWithin(*H, view1[k], view2[k], params.vote_threshold_px);
          return static_cast<double>(n) / std::max<size_t>(1, idx.size());
        };
        if (explained(planes[i].inliers) >= params.merge_fraction &&
            explained(planes[j].inliers) >= params.merge_fraction) {
          std::sort(both.begin(), both.end());
          planes[i].H = *H;
          planes[i].inliers = both;
          planes.erase(planes.begin() + j);
          merged = true;
        }
      }
    }
  }
}

// Every point goes to the plane that explains it best, or to none.
std::vector<int> assignPoints(const std::vector<Plane>& planes,
                              const std::vector<cv::Point2d>& view1,
                              const std::vector<cv::Point2d>& view2, double threshold_px) {
  std::vector<int> labels(view1.size(), 0);
  for (size_t i = 0; i < view1.size(); ++i) {
    if (!finite(view1[i]) || !finite(view2[i])) continue;
    double best = threshold_px;
    for (size_t k = 0; k < planes.size(); ++k) {
      const double e = transferError(planes[k].H, view1[i], view2[i]);
      if (e < best) {
        best = e;
        labels[i] = static_cast<int>(k) + 1;
      }
    }
  }
  return labels;
}

// assignPoints, then drops the least supported plane while it has fewer than
// min_plane_support points, assigning again each time. Returns each plane's points.
std::vector<std::vector<int>> keepSupportedPlanes(std::vector<Plane>& planes,
                                                  const std::vector<cv::Point2d>& view1,
                                                  const std::vector<cv::Point2d>& view2,
                                                  const PlaneParams& params) {
  for (;;) {
    const std::vector<int> labels = assignPoints(planes, view1, view2, params.vote_threshold_px);
    std::vector<std::vector<int>> members(planes.size());
    for (size_t i = 0; i < labels.size(); ++i) {
      if (labels[i] > 0) members[labels[i] - 1].push_back(static_cast<int>(i));
    }
    const auto smallest = std::min_element(
        members.begin(), members.end(),
        [](const std::vector<int>& a, const std::vector<int>& b) { return a.size() < b.size(); });
    if (smallest == members.end() ||
        static_cast<int>(smallest->size()) >= params.min_plane_support) {
      return members;
    }
    planes.erase(planes.begin() + (smallest - members.begin()));
  }
}

// Alternates assigning every point to its best plane and refitting each plane on its
// points until the labels stop changing: pieces found early, which hold a few points of
// a neighbouring plane, give those points back. Leaves planes[k].inliers set.
void refineAssignment(std::vector<Plane>& planes, const std::vector<cv::Point2d>& view1,
                      const std::vector<cv::Point2d>& view2, const PlaneParams& params) {
  std::vector<std::vector<int>> members = keepSupportedPlanes(planes, view1, view2, params);
  for (int round = 0; round < params.refit_iterations; ++round) {
    for (size_t k = 0; k < planes.size(); ++k) {
      if (auto H = fitHomography(select(view1, members[k]), select(view2, members[k])))
        planes[k].H = *H;
    }
    std::vector<std::vector<int>> next = keepSupportedPlanes(planes, view1, view2, params);
    const bool stable = next == members;
    members = std::move(next);
    if (stable) break;
  }
  for (size_t k = 0; k < planes.size(); ++k) planes[k].inliers = std::move(members[k]);
}

}  // namespace

Vote voteDominant(const std::vector<cv::Matx33d>& homographies,
                  const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2,
                  const std::vector<bool>& active, double threshold_px,
                  std::vector<int>* vote_bounds) {
  // With bounds, the likeliest winners are counted first so that the rest can be
  // skipped; the paper's rule (most votes, the first index on ties) is kept exactly.
  std::vector<int> order(homographies.size());
  std::iota(order.begin(), order.end(), 0);
  if (vote_bounds) {
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return (*vote_bounds)[a] > (*vote_bounds)[b]; });
  }
  Vote vote;
  auto beats = [&vote](int votes, int h) {
    return votes > vote.votes || (votes == vote.votes && votes > 0 && h < vote.winner);
  };
  for (int h : order) {
    if (vote_bounds && !beats((*vote_bounds)[h], h)) continue;
    int votes = 0;
    for (size_t i = 0; i < view1.size(); ++i) {
      if (isActive(active, i) && transfersWithin(homographies[h], view1[i], view2[i], threshold_px))
        ++votes;
    }
    if (vote_bounds) (*vote_bounds)[h] = votes;
    if (beats(votes, h)) {
      vote.votes = votes;
      vote.winner = h;
    }
  }
  if (vote.winner >= 0) {
    vote.voters = inliersOf(homographies[vote.winner], view1, view2, active, threshold_px);
  }
  return vote;
}

std::vector<int> inliersOf(const cv::Matx33d& H, const std::vector<cv::Point2d>& view1,
                           const std::vector<cv::Point2d>& view2, const std::vector<bool>& active,
                           double threshold_px) {
  std::vector<int> inliers;
  for (size_t i = 0; i < view1.size(); ++i) {
    if (isActive(active, i) && transfersWithin(H, view1[i], view2[i], threshold_px)) {
      inliers.push_back(static_cast<int>(i));
    }
  }
  return inliers;
}

bool refitPlane(cv::Matx33d& H, std::vector<int>& inliers, const std::vector<cv::Point2d>& view1,
                const std::vector<cv::Point2d>& view2, const std::vector<bool>& active,
                const PlaneParams& params) {
  for (int round = 0; round < params.refit_iterations; ++round) {
    std::vector<double> weights;
    if (params.robust_refit) {
      for (int i : inliers) {
        const double r = transferError(H, view1[i], view2[i]) / params.vote_threshold_px;
        weights.push_back(1.0 / (1.0 + r * r));
      }
    }
    const auto fitted = fitHomography(select(view1, inliers), select(view2, inliers), weights);
    if (!fitted) return false;
    H = *fitted;
    std::vector<int> next = inliersOf(H, view1, view2, active, params.vote_threshold_px);
    if (next.size() < 4) return false;
    if (next == inliers) break;
    inliers = std::move(next);
  }
  return true;
}

PlaneSegmentation segmentPlanes(const std::vector<cv::Point2d>& view1,
                                const std::vector<cv::Point2d>& view2, const PlaneParams& params) {
  PlaneSegmentation out;
  if (view1.size() != view2.size()) {
    out.error = "the two views have different numbers of points";
    return out;
  }
  out.labels.assign(view1.size(), 0);
  if (view1.size() < 5) return out;

  std::vector<cv::Matx33d> candidates = coplanarGroupHomographies(view1, view2, params.groups, out);
  std::vector<bool> active(view1.size());
  for (size_t i = 0; i < view1.size(); ++i) active[i] = finite(view1[i]) && finite(view2[i]);

  // Paper IV-C repeated: the winner becomes a plane, its points leave the vote.
  std::vector<Plane> planes;
  std::vector<int> bounds(candidates.size(), std::numeric_limits<int>::max());
  while (static_cast<int>(planes.size()) < params.max_planes) {
    Vote vote = voteDominant(candidates, view1, view2, active, params.vote_threshold_px, &bounds);
    if (vote.winner < 0 || vote.votes < params.min_plane_support) break;
    Plane plane;
    plane.H = candidates[vote.winner];
    plane.inliers = std::move(vote.voters);
    bounds[vote.winner] = 0;  // used: never votes again
    if (!refitPlane(plane.H, plane.inliers, view1, view2, active, params) ||
        static_cast<int>(plane.inliers.size()) < params.min_plane_support) {
      continue;
    }
    for (int i : plane.inliers) active[i] = false;
    planes.push_back(std::move(plane));
  }
  refineAssignment(planes, view1, view2, params);
  mergeSamePlanes(planes, view1, view2, params);
  refineAssignment(planes, view1, view2, params);
  std::stable_sort(planes.begin(), planes.end(), [](const Plane& a, const Plane& b) {
    return a.inliers.size() > b.inliers.size();
  });
  for (size_t k = 0; k < planes.size(); ++k) {
    Plane& p = planes[k];
    for (int i : p.inliers) out.labels[i] = static_cast<int>(k) + 1;
    p.rms_error_px = rmsError(p.H, p.inliers, view1, view2);
    p.score = static_cast<double>(p.inliers.size()) / view1.size();
  }
  out.planes = std::move(planes);
  return out;
}

}  // namespace mono_plane_detection
