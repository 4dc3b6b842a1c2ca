#include "mono_plane_detection/planes/coplanar_groups.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <unordered_set>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/geometry/homography_four.h"
#include "mono_plane_detection/planes/cross_ratio.h"

namespace mono_plane_detection {
namespace {

std::array<cv::Point2d, 5> pick(const PointGroup& g, const std::vector<cv::Point2d>& p) {
  return {p[g[0]], p[g[1]], p[g[2]], p[g[3]], p[g[4]]};
}

// Hash of a group's sorted indices, for skipping groups drawn again.
struct GroupHash {
  size_t operator()(const PointGroup& g) const {
    size_t h = 0;
    for (int i : g) h = h * 1000003u + static_cast<size_t>(i);
    return h;
  }
};

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
  // A grid of about 3 points per cell on average for the neighbour search (non-finite
  // points or all on one line: plain scans).
  cv::Point2d lo(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity());
  cv::Point2d hi = -lo;
  for (const auto& q : points) {
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) return;
    lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
    hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
  }
  const double area = (hi.x - lo.x) * (hi.y - lo.y);
  if (!(area > 0.0) || !std::isfinite(area)) return;
  // Cells no larger than the neighbours' minimum distance: points spread thinly around a
  // dense cluster (outliers) would otherwise put the cluster in a few crowded cells. At
  // most 4 N + 64 cells.
  cell_px_ = std::sqrt(3.0 * area / static_cast<double>(points.size()));
  if (params.min_neighbour_distance_px > 0.0)
    cell_px_ = std::min(cell_px_, params.min_neighbour_distance_px);
  const double max_cells = 4.0 * static_cast<double>(points.size()) + 64.0;
  cell_px_ = std::max({cell_px_, std::sqrt(area / max_cells), (hi.x - lo.x) / 1024.0,
                       (hi.y - lo.y) / 1024.0});
  grid_origin_ = lo;
  cols_ = static_cast<int>((hi.x - lo.x) / cell_px_) + 1;
  rows_ = static_cast<int>((hi.y - lo.y) / cell_px_) + 1;
  auto cellOf = [this](const cv::Point2d& q) {
    const int cx = std::min(cols_ - 1, static_cast<int>((q.x - grid_origin_.x) / cell_px_));
    const int cy = std::min(rows_ - 1, static_cast<int>((q.y - grid_origin_.y) / cell_px_));
    return cy * cols_ + cx;
  };
  cell_start_.assign(static_cast<size_t>(cols_) * rows_ + 1, 0);
  for (const auto& q : points) ++cell_start_[cellOf(q) + 1];
  for (size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  cell_points_.resize(points.size());
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t j = 0; j < points.size(); ++j) cell_points_[fill[cellOf(points[j])]++] = static_cast<int>(j);
}

std::vector<int>& GroupSampler::neighboursOf(size_t slot) {
  std::vector<int>& near = near_[slot];
  if (!near.empty()) return near;
  const int n = static_cast<int>(points_.size());
  const size_t k = static_cast<size_t>(std::min(std::max(params_.neighbours, 4), n - 1));
  const int seed = seeds_[slot];
  const cv::Point2d& a = points_[seed];
  // The k nearest at the floor distance or more (squared distances: same order; ties by
  // index) in a short sorted list, searched on the grid: the same list as one scan of
  // the seed's row of the distance matrix, which took up to a quarter of the plane stage.
  std::vector<std::pair<double, int>>& best = nearest_;  // (reused: no allocation per seed)
  auto nearest = [&](double floor2) {
    best.clear();
    best.reserve(k + 1);
    // worst2: the k-th distance so far (infinity until k are in), a single comparison
    // rejecting most points once the list is full.
    double worst2 = std::numeric_limits<double>::infinity();
    auto consider = [&](int j) {
      const double dx = points_[j].x - a.x, dy = points_[j].y - a.y;
      const double d2 = dx * dx + dy * dy;
      if (d2 > worst2 || d2 < floor2 || j == seed) return;
      const std::pair<double, int> key(d2, j);
      if (best.size() == k && !(key < best.back())) return;
      // Insertion from the back (the list is short and sorted).
      if (best.size() == k) best.pop_back();
      best.push_back(key);
      for (size_t m = best.size() - 1; m > 0 && key < best[m - 1]; --m)
        std::swap(best[m], best[m - 1]);
      if (best.size() == k) worst2 = best.back().first;
    };
    if (cell_start_.empty()) {
      for (int j = 0; j < n; ++j) consider(j);
      return;
    }
    // Rings of cells around the seed's cell: after ring q every point nearer than q
    // cells is considered, so the search stops once the k-th distance is below that.
    const int cx = std::min(cols_ - 1, static_cast<int>((a.x - grid_origin_.x) / cell_px_));
    const int cy = std::min(rows_ - 1, static_cast<int>((a.y - grid_origin_.y) / cell_px_));
    const int max_ring = std::max({cx, cols_ - 1 - cx, cy, rows_ - 1 - cy});  // whole grid
    for (int q = 0; q <= max_ring; ++q) {
      auto visit = [&](int x, int y) {
        if (x < 0 || x >= cols_ || y < 0 || y >= rows_) return;
        const int c = y * cols_ + x;
        for (int m = cell_start_[c]; m < cell_start_[c + 1]; ++m) consider(cell_points_[m]);
      };
      const int x0 = std::max(0, cx - q), x1 = std::min(cols_ - 1, cx + q);
      for (int x = x0; x <= x1; ++x) {  // top and bottom rows of the ring
        visit(x, cy - q);
        if (q > 0) visit(x, cy + q);
      }
      for (int y = std::max(0, cy - q + 1); y <= std::min(rows_ - 1, cy + q - 1); ++y) {
        visit(cx - q, y);  // its left and right columns
        if (q > 0) visit(cx + q, y);
      }
      const double reach = q * cell_px_;
      if (best.size() == k && best.back().first <= reach * reach) break;
    }
  };
  const double min_distance = params_.min_neighbour_distance_px;
  nearest(min_distance * min_distance);
  if (best.size() < 4) nearest(-1.0);
  near.reserve(best.size());
  for (const auto& b : best) near.push_back(b.second);
  return near;
}

namespace {

bool finitePoint(const cv::Point2d& q) { return std::isfinite(q.x) && std::isfinite(q.y); }

}  // namespace

bool GroupSampler::nextFifth(PointGroup& group) {
  if (next_fifth_ >= end_fifth_) return false;
  const std::vector<int>& near = near_[four_slot_];
  const cv::Point2d* four[4] = {&points_[seeds_[four_slot_]], &points_[near[0]], &points_[near[1]],
                                &points_[near[2]]};
  while (next_fifth_ < end_fifth_) {
    const int f = near[static_cast<size_t>(next_fifth_++)];
    const cv::Point2d& q = points_[f];
    if (!finitePoint(q)) continue;
    // The four were tested when drawn: only the 6 triples with the fifth are left
    // (wellSpread's arithmetic; the four's edges measured once).
    double to_q[4];
    for (int i = 0; i < 4; ++i) to_q[i] = (*four[i] - q).dot(*four[i] - q);
    bool ok = true;
    for (int i = 0; ok && i < 4; ++i)
      for (int j = i + 1; ok && j < 4; ++j)
        ok = spreadTriple(*four[i], *four[j], q, four_edge2_[i][j], to_q[j], to_q[i],
                          params_.min_shape);
    if (!ok) continue;
    group = {seeds_[four_slot_], near[0], near[1], near[2], f};
    return true;
  }
  return false;
}

bool GroupSampler::next(PointGroup& group) {
  if (seeds_.empty()) return false;
  const bool bundle = params_.fifth_points > 1;
  if (bundle && nextFifth(group)) return true;
  // Round-robin over the seeds; a run of degenerate draws this long means the points
  // are (nearly) all collinear, and drawing on would never end.
  const long give_up = 4L * static_cast<long>(seeds_.size()) + 64;
  while (failures_in_a_row_ < give_up) {
    const size_t slot = static_cast<size_t>(draws_++ % static_cast<long>(seeds_.size()));
    // Shuffled in place: any order of the list is as good for the next draw.
    std::vector<int>& candidates = neighboursOf(slot);
    const int size = static_cast<int>(candidates.size());
    // Partial Fisher-Yates: the 3 neighbours of the four and the fifth points, distinct.
    const int drawn = bundle ? std::min(size, 3 + params_.fifth_points) : 4;
    for (int k = 0; k < drawn; ++k) {
      std::uniform_int_distribution<int> pick_one(k, size - 1);
      std::swap(candidates[k], candidates[pick_one(rng_)]);
    }
    if (!bundle) {
      group = {seeds_[slot], candidates[0], candidates[1], candidates[2], candidates[3]};
      if (wellSpread(pick(group, points_), params_.min_shape)) {
        failures_in_a_row_ = 0;
        return true;
      }
      ++failures_in_a_row_;
      continue;
    }
    const cv::Point2d* four[4] = {&points_[seeds_[slot]], &points_[candidates[0]],
                                  &points_[candidates[1]], &points_[candidates[2]]};
    bool ok = true;
    for (int i = 0; ok && i < 4; ++i) ok = finitePoint(*four[i]);
    if (ok)  // the four's sides, kept for its fifth points' triples
      for (int i = 0; i < 4; ++i)
        for (int j = i + 1; j < 4; ++j)
          four_edge2_[i][j] = (*four[i] - *four[j]).dot(*four[i] - *four[j]);
    for (int i = 0; ok && i < 4; ++i)
      for (int j = i + 1; ok && j < 4; ++j)
        for (int k = j + 1; ok && k < 4; ++k)
          ok = spreadTriple(*four[i], *four[j], *four[k], four_edge2_[i][j], four_edge2_[j][k],
                            four_edge2_[i][k], params_.min_shape);
    if (ok) {
      four_slot_ = slot;
      next_fifth_ = 3;
      end_fifth_ = drawn;
      if (nextFifth(group)) {
        failures_in_a_row_ = 0;
        return true;
      }
    }
    ++failures_in_a_row_;
  }
  return false;
}

std::vector<PointGroup> buildGroups(const std::vector<cv::Point2d>& points,
                                    const GroupParams& params, int count) {
  std::vector<PointGroup> groups;
  GroupSampler sampler(points, params);
  for (PointGroup g; static_cast<int>(groups.size()) < count && sampler.next(g);)
    groups.push_back(g);
  return groups;
}

CoplanarGroups findCoplanarGroups(const std::vector<cv::Point2d>& view1,
                                  const std::vector<cv::Point2d>& view2,
                                  const GroupParams& params, double sigma_px) {
  CoplanarGroups out;
  const long wanted =
      std::min<long>(params.max_groups, static_cast<long>(params.groups_per_point) * view2.size());
  const long max_tries =
      triesFor(params, view2.size());
  GroupSampler sampler(view2, params);
  std::unordered_set<PointGroup, GroupHash> seen;
  seen.reserve(static_cast<size_t>(max_tries));
  PointGroup g;
  while (static_cast<long>(out.groups.size()) < wanted && out.tried < max_tries &&
         sampler.next(g)) {
    ++out.tried;
    PointGroup key = g;
    std::sort(key.begin(), key.end());
    if (!seen.insert(key).second) continue;
    if (isCoplanarGroup(g, view1, view2, params, sigma_px)) out.groups.push_back(g);
  }
  return out;
}

long triesFor(const GroupParams& params, size_t points) {
  const long scaled = static_cast<long>(params.tries_per_point) * static_cast<long>(points);
  return std::min<long>(params.max_tries, std::max<long>(params.min_tries, scaled));
}

bool knownCoplanarityTest(const std::string& name) {
  return name == "transfer" || name == "cross_ratio";
}

double fifthPointError(const PointGroup& group, const std::vector<cv::Point2d>& view1,
                       const std::vector<cv::Point2d>& view2) {
  cv::Point2d from[4], to[4];
  for (int k = 0; k < 4; ++k) {
    from[k] = view1[group[k]];
    to[k] = view2[group[k]];
  }
  const auto H = homographyFromFour(from, to);
  if (!H) return std::numeric_limits<double>::infinity();
  return transferError(*H, view1[group[4]], view2[group[4]]);
}

bool isCoplanarGroup(const PointGroup& group, const std::vector<cv::Point2d>& view1,
                     const std::vector<cv::Point2d>& view2, const GroupParams& params,
                     double sigma_px) {
  if (params.coplanarity_test == "transfer" && sigma_px > 0.0)
    return fifthPointError(group, view1, view2) <= params.transfer_threshold_sigma * sigma_px;
  const auto a = fivePointInvariants(pick(group, view1), params.min_shape);
  const auto b = fivePointInvariants(pick(group, view2), params.min_shape);
  return a && b && invariantDistance(*a, *b) <= params.invariant_threshold;
}

}  // namespace mono_plane_detection
