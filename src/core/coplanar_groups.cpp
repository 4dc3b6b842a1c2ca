#include "mono_plane_detection/coplanar_groups.h"

#include <algorithm>
#include <numeric>
#include <random>

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
    for (size_t j = 0; j < points.size(); ++j) row[j] = std::hypot(points[j].x - a.x, points[j].y - a.y);
  }
  return rows;
}

std::vector<PointGroup> buildGroups(const std::vector<cv::Point2d>& points,
                                    const GroupParams& params, int count) {
  const int n = static_cast<int>(points.size());
  std::vector<PointGroup> groups;
  if (n < 5 || count <= 0) return groups;
  const int neighbours = std::min(std::max(params.neighbours, 4), n - 1);

  std::mt19937 rng(params.seed);
  std::vector<int> seeds(n);
  std::iota(seeds.begin(), seeds.end(), 0);
  std::shuffle(seeds.begin(), seeds.end(), rng);
  seeds.resize(std::min(n, std::max(1, params.max_seeds)));

  // Each seed's nearest points, from its row of the distance matrix.
  const cv::Mat distances = distanceRows(points, seeds);
  std::vector<std::vector<int>> near(seeds.size());
  std::vector<int> order(n);
  for (size_t s = 0; s < seeds.size(); ++s) {
    const double* row = distances.ptr<double>(static_cast<int>(s));
    std::iota(order.begin(), order.end(), 0);
    std::nth_element(order.begin(), order.begin() + neighbours, order.end(),
                     [row](int a, int b) { return row[a] < row[b]; });
    for (int k = 0; k <= neighbours; ++k) {
      if (order[k] != seeds[s] && static_cast<int>(near[s].size()) < neighbours) near[s].push_back(order[k]);
    }
  }

  // Round-robin over the seeds; a degenerate draw costs a try, not a group.
  const long max_draws = 4L * count;
  for (long draw = 0; draw < max_draws && static_cast<int>(groups.size()) < count; ++draw) {
    const size_t s = static_cast<size_t>(draw % static_cast<long>(seeds.size()));
    std::vector<int>& candidates = near[s];
    for (int k = 0; k < 4; ++k) {  // partial Fisher-Yates: 4 distinct neighbours
      std::uniform_int_distribution<int> pick_one(k, static_cast<int>(candidates.size()) - 1);
      std::swap(candidates[k], candidates[pick_one(rng)]);
    }
    const PointGroup g{seeds[s], candidates[0], candidates[1], candidates[2], candidates[3]};
    if (wellSpread(pick(g, points), params.min_shape)) groups.push_back(g);
  }
  return groups;
}

CoplanarGroups findCoplanarGroups(const std::vector<cv::Point2d>& view1,
                                  const std::vector<cv::Point2d>& view2, const GroupParams& params) {
  CoplanarGroups out;
  const long wanted = std::min<long>(params.max_groups,
                                     static_cast<long>(params.groups_per_point) * view2.size());
  for (const PointGroup& g : buildGroups(view2, params, params.max_tries)) {
    if (static_cast<long>(out.groups.size()) >= wanted) break;
    ++out.tried;
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
