#include "mono_plane_detection/coplanar_groups.h"

#include <algorithm>
#include <numeric>
#include <random>
#include <set>

#include "mono_plane_detection/cross_ratio.h"

namespace mono_plane_detection {
namespace {

std::array<cv::Point2d, 5> pick(const PointGroup& g, const std::vector<cv::Point2d>& p) {
  return {p[g[0]], p[g[1]], p[g[2]], p[g[3]], p[g[4]]};
}

}  // namespace

cv::Mat distanceRows(const std::vector<cv::Point2d>& points, const std::vector<int>& seeds) {
  cv::Mat rows(static_cast<int>(seeds.size()), static_cast<int>(points.size()), CV_64F);
  for (size_t s = 0; s < seeds.size(); ++s) {
    double* row = rows.ptr<double>(static_cast<int>(s));
    const cv::Point2d& a = points[seeds[s]];
    for (size_t j = 0; j < points.size(); ++j) {
      const double dx = points[j].x - a.x, dy = points[j].y - a.y;
      row[j] = std::sqrt(dx * dx + dy * dy);
    }
  }
  return rows;
}

GroupSampler::GroupSampler(const std::vector<cv::Point2d>& points, const GroupParams& params)
    : points_(points), params_(params), rng_(params.seed) {
  if (points.size() < 5) return;
  seeds_.resize(points.size());
  std::iota(seeds_.begin(), seeds_.end(), 0);
  std::shuffle(seeds_.begin(), seeds_.end(), rng_);
  seeds_.resize(std::min(seeds_.size(), static_cast<size_t>(std::max(1, params.max_seeds))));
  near_.resize(seeds_.size());
}

const std::vector<int>& GroupSampler::neighboursOf(size_t slot) {
  std::vector<int>& near = near_[slot];
  if (!near.empty()) return near;
  const int n = static_cast<int>(points_.size());
  const int k = std::min(std::max(params_.neighbours, 4), n - 1);
  // Squared distances: the same order as the distance matrix row, without sqrt.
  const cv::Point2d& a = points_[seeds_[slot]];
  std::vector<double> d(n);
  for (int j = 0; j < n; ++j) {
    const double dx = points_[j].x - a.x, dy = points_[j].y - a.y;
    d[j] = dx * dx + dy * dy;
  }
  const double min2 = params_.min_neighbour_distance_px * params_.min_neighbour_distance_px;
  auto candidatesFarther = [&](double floor2) {
    std::vector<int> out;
    for (int j = 0; j < n; ++j) {
      if (j != seeds_[slot] && d[j] >= floor2) out.push_back(j);
    }
    return out;
  };
  std::vector<int> order = candidatesFarther(min2);
  if (order.size() < 4) order = candidatesFarther(-1.0);
  const int count = std::min(k, static_cast<int>(order.size()));
  std::nth_element(order.begin(), order.begin() + (count - 1), order.end(),
                   [&d](int i, int j) { return d[i] < d[j]; });
  near.assign(order.begin(), order.begin() + count);
  return near;
}

bool GroupSampler::next(PointGroup& group) {
  if (seeds_.empty()) return false;
  // Round-robin over the seeds; a run of degenerate draws this long means the points
  // are (nearly) all collinear, and drawing on would never end.
  const long give_up = 4L * static_cast<long>(seeds_.size()) + 64;
  while (failures_in_a_row_ < give_up) {
    const size_t slot = static_cast<size_t>(draws_++ % static_cast<long>(seeds_.size()));
    std::vector<int> candidates = neighboursOf(slot);
    for (int k = 0; k < 4; ++k) {  // partial Fisher-Yates: 4 distinct neighbours
      std::uniform_int_distribution<int> pick_one(k, static_cast<int>(candidates.size()) - 1);
      std::swap(candidates[k], candidates[pick_one(rng_)]);
    }
    group = {seeds_[slot], candidates[0], candidates[1], candidates[2], candidates[3]};
    if (wellSpread(pick(group, points_), params_.min_shape)) {
      failures_in_a_row_ = 0;
      return true;
    }
    ++failures_in_a_row_;
  }
  return false;
}

std::vector<PointGroup> buildGroups(const std::vector<cv::Point2d>& points,
                                    const GroupParams& params, int count) {
  std::vector<PointGroup> groups;
  GroupSampler sampler(points, params);
  for (PointGroup g; static_cast<int>(groups.size()) < count && sampler.next(g);) groups.push_back(g);
  return groups;
}

CoplanarGroups findCoplanarGroups(const std::vector<cv::Point2d>& view1,
                                  const std::vector<cv::Point2d>& view2, const GroupParams& params) {
  CoplanarGroups out;
  const long wanted = std::min<long>(params.max_groups,
                                     static_cast<long>(params.groups_per_point) * view2.size());
  const long max_tries = std::min<long>(params.max_tries,
                                        static_cast<long>(params.tries_per_point) * view2.size());
  GroupSampler sampler(view2, params);
  std::set<PointGroup> seen;
  PointGroup g;
  while (static_cast<long>(out.groups.size()) < wanted && out.tried < max_tries && sampler.next(g)) {
    ++out.tried;
    PointGroup key = g;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) continue;
    if (isCoplanarGroup(g, view1, view2, params)) out.groups.push_back(g);
  }
  return out;
}

bool isCoplanarGroup(const PointGroup& group, const std::vector<cv::Point2d>& view1,
                     const std::vector<cv::Point2d>& view2, const GroupParams& params) {
  const auto a = fivePointInvariants(pick(group, view1), params.min_shape);
  const auto b = fivePointInvariants(pick(group, view2), params.min_shape);
  return a && b && invariantDistance(*a, *b) <= params.invariant_threshold;
}

}  // namespace mono_plane_detection
