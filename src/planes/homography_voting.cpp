#include "mono_plane_detection/planes/homography_voting.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <tuple>
#include <unordered_set>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/geometry/homography_four.h"
#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/planes/epipolar_check.h"

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

// Cauchy weight 1 / (1 + (r / scale)^2) of a point's transfer error r (0 at infinity).
double cauchyWeight(const cv::Matx33d& H, const cv::Point2d& a, const cv::Point2d& b,
                    double scale) {
  const double u2 = transferErrorSquaredOneDivision(H, a, b) / (scale * scale);
  return std::isfinite(u2) ? 1.0 / (1.0 + u2) : 0.0;
}

// Points' coordinates in separate arrays, for counting votes in vector instructions.
struct PointArrays {
  std::vector<double> ax, ay, bx, by;
  void reserve(size_t n) {
    ax.reserve(n);
    ay.reserve(n);
    bx.reserve(n);
    by.reserve(n);
  }
  void add(const cv::Point2d& a, const cv::Point2d& b) {
    ax.push_back(a.x);
    ay.push_back(a.y);
    bx.push_back(b.x);
    by.push_back(b.y);
  }
  size_t size() const { return ax.size(); }
};

constexpr size_t kVoteBlock = 32;
// The vote's bail-out: a candidate this many binomial spreads below the best's share of
// the points counted so far stops (one-sided 0.1 %: about one stop in a thousand wrong
// for a candidate exactly as good as the best).
constexpr double kBailOutSigmas = 3.09;

// How many of the points [b0, b1) (at most kVoteBlock) H transfers within sqrt(t2) pixels:
// transfersWithin's arithmetic, written so that it compiles to vector instructions (its
// coefficients in locals, each point's outcome a 0/1 double summed after; a count in an
// integer kept the compiler from vectorising: the vote's loops ran one point at a time).
int votesInBlock(const cv::Matx33d& H, const PointArrays& p, size_t b0, size_t b1, double t2) {
  const double h0 = H(0, 0), h1 = H(0, 1), h2 = H(0, 2), h3 = H(1, 0), h4 = H(1, 1), h5 = H(1, 2),
               h6 = H(2, 0), h7 = H(2, 1), h8 = H(2, 2);
  const double* ax = p.ax.data() + b0;
  const double* ay = p.ay.data() + b0;
  const double* bx = p.bx.data() + b0;
  const double* by = p.by.data() + b0;
  const size_t n = b1 - b0;
  double in[kVoteBlock];
  for (size_t i = 0; i < n; ++i) {
    const double w = h6 * ax[i] + h7 * ay[i] + h8;
    const double dx = (h0 * ax[i] + h1 * ay[i] + h2) - bx[i] * w;
    const double dy = (h3 * ax[i] + h4 * ay[i] + h5) - by[i] * w;
    in[i] = (std::abs(w) >= 1e-12) & (dx * dx + dy * dy < t2 * (w * w)) ? 1.0 : 0.0;
  }
  // Summed as doubles (0/1: exact in any order), two chains.
  double even = 0.0, odd = 0.0;
  size_t i = 0;
  for (; i + 1 < n; i += 2) {
    even += in[i];
    odd += in[i + 1];
  }
  if (i < n) even += in[i];
  return static_cast<int>(even + odd);
}

// H's count over the points, block by block, stopping after the block where even every
// point left could no longer make it win (`can_win(votes + left)` false): then it is not
// `complete` and `votes` is an upper bound on its count (the vote's early stop).
struct BlockCount {
  int votes = 0;
  bool complete = true;
};
// bail_out(votes, seen) (optional): true when the votes among the first `seen` points
// already show that H will not win (a statistical stop, RepeatedVote).
template <class CanWin>
BlockCount countWhileItCanWin(const cv::Matx33d& H, const PointArrays& p, double t2,
                              CanWin can_win) {
  return countWhileItCanWin(H, p, t2, can_win, [](int, size_t) { return false; });
}
template <class CanWin, class BailOut>
BlockCount countWhileItCanWin(const cv::Matx33d& H, const PointArrays& p, double t2, CanWin can_win,
                              BailOut bail_out) {
  BlockCount count;
  const size_t m = p.size();
  size_t left = m;
  for (size_t b0 = 0; b0 < m; b0 += kVoteBlock) {
    const size_t b1 = std::min(m, b0 + kVoteBlock);
    count.votes += votesInBlock(H, p, b0, b1, t2);
    left -= b1 - b0;
    if (left > 0 && (!can_win(count.votes + static_cast<int>(left)) || bail_out(count.votes, b1))) {
      count.complete = false;
      count.votes += static_cast<int>(left);
      break;
    }
  }
  return count;
}

// votesInBlock over all the points.
int votesAmong(const cv::Matx33d& H, const PointArrays& p, double t2) {
  int votes = 0;
  for (size_t b0 = 0; b0 < p.size(); b0 += kVoteBlock)
    votes += votesInBlock(H, p, b0, std::min(p.size(), b0 + kVoteBlock), t2);
  return votes;
}

// The points with active[i] (all when active is empty), ascending: the moves below work on
// a plane's or two planes' points, and scanning every point for them took most of a
// merge's time at 1000 points.
std::vector<int> activeIndices(const std::vector<bool>& active, size_t n) {
  std::vector<int> idx;
  idx.reserve(n);
  for (size_t i = 0; i < n; ++i)
    if (isActive(active, i)) idx.push_back(static_cast<int>(i));
  return idx;
}

// inliersOf over the points `among` (ascending: the result is then too).
std::vector<int> inliersAmong(const cv::Matx33d& H, const std::vector<cv::Point2d>& view1,
                              const std::vector<cv::Point2d>& view2, const std::vector<int>& among,
                              double threshold_px) {
  // Written without a branch per point (each index stored, kept when within): the refits
  // of the merge and the assignment call this over hundreds of points, half of them in.
  std::vector<int> inliers(among.size());
  size_t kept = 0;
  for (int i : among) {
    inliers[kept] = i;
    kept += transfersWithin(H, view1[i], view2[i], threshold_px);
  }
  inliers.resize(kept);
  return inliers;
}

// The points of a and b, ascending, each once: a merge of the two lists when both are
// ascending (a plane's points are; sorting the pair's points was a tenth of the merge
// move's time at 1000 points), else a sort.
std::vector<int> ascendingUnion(const std::vector<int>& a, const std::vector<int>& b) {
  std::vector<int> out;
  out.reserve(a.size() + b.size());
  if (std::is_sorted(a.begin(), a.end()) && std::is_sorted(b.begin(), b.end())) {
    std::merge(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
  } else {
    out = a;
    out.insert(out.end(), b.begin(), b.end());
    std::sort(out.begin(), out.end());
  }
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

// refitPlane over the points `among` (ascending), at threshold_px (instead of
// params.vote_threshold_px: no copy of the params, whose string the moves copied per call).
bool refitAmong(cv::Matx33d& H, std::vector<int>& inliers, const std::vector<cv::Point2d>& view1,
                const std::vector<cv::Point2d>& view2, const std::vector<int>& among,
                const PlaneParams& params, double threshold_px) {
  for (int round = 0; round < params.refit_iterations; ++round) {
    std::vector<double> weights;
    if (params.robust_refit) {
      weights.reserve(inliers.size());
      for (int i : inliers) weights.push_back(cauchyWeight(H, view1[i], view2[i], threshold_px));
    }
    const auto fitted = fitHomography(select(view1, inliers), select(view2, inliers), weights);
    if (!fitted) return false;
    H = *fitted;
    std::vector<int> next = inliersAmong(H, view1, view2, among, threshold_px);
    if (next.size() < 4) return false;
    if (next == inliers) break;
    inliers = std::move(next);
  }
  return true;
}

double rmsError(const cv::Matx33d& H, const std::vector<int>& idx,
                const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2) {
  double sum = 0.0;
  for (int i : idx) {
    const double e = transferError(H, view1[i], view2[i]);
    sum += e * e;
  }
  return idx.empty() ? 0.0 : std::sqrt(sum / idx.size());
}

// The model-selection criterion (PlaneParams), -2 log-likelihood up to a constant: a
// point on plane p costs r^2 / sigma_p^2 + 4 ln(sigma_p / sigma) (a Gaussian of the
// plane's own scale, so that a plane made broad by points of two planes pays for its
// width), truncated at k^2, an outlier's cost.
struct Energy {
  double k2;          // (membership threshold in noise scales)^2: an outlier's cost
  double sigma;       // the image pair's noise scale
  double plane_cost;  // label cost of one plane
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
  double sum(const HomographyPlane& p, const std::vector<int>& idx, const std::vector<cv::Point2d>& view1,
             const std::vector<cv::Point2d>& view2) const {
    double e = 0.0;
    const double width = widthCost(p);
    for (int i : idx) e += point(p, view1[i], view2[i], width);
    return e;
  }
};

// Energy::point for every point of p (the same values), written so that it compiles to
// vector instructions: the conditions joined by & and one select (as in votesInBlock;
// with branches GCC keeps the loop scalar). |w| < 1e-12 is transferErrorSquaredOneDivision's
// infinity, a non-finite point's NaN fails e2 < t2: both cost k^2, as in Energy::point.
void pointCosts(const Energy& energy, const HomographyPlane& plane, double width,
                const PointArrays& p, std::vector<double>& out) {
  const size_t n = p.size();
  out.resize(n);
  const cv::Matx33d& H = plane.H;
  const double h0 = H(0, 0), h1 = H(0, 1), h2 = H(0, 2), h3 = H(1, 0), h4 = H(1, 1), h5 = H(1, 2),
               h6 = H(2, 0), h7 = H(2, 1), h8 = H(2, 2);
  const double k2 = energy.k2;
  const double noise2 = plane.noise_px * plane.noise_px;
  const double t2 = plane.threshold_px * plane.threshold_px;
  const double* ax = p.ax.data();
  const double* ay = p.ay.data();
  const double* bx = p.bx.data();
  const double* by = p.by.data();
  double* row = out.data();
  for (size_t i = 0; i < n; ++i) {
    const double w = h6 * ax[i] + h7 * ay[i] + h8;
    const double dx = (h0 * ax[i] + h1 * ay[i] + h2) - bx[i] * w;
    const double dy = (h3 * ax[i] + h4 * ay[i] + h5) - by[i] * w;
    const double e2 = (dx * dx + dy * dy) / (w * w);
    const double c = e2 / noise2 + width;
    const double inside = k2 < c ? k2 : c;  // std::min(c, k2)
    row[i] = (std::abs(w) >= 1e-12) & (e2 < t2) ? inside : k2;
  }
}

PointArrays arraysOf(const std::vector<int>& idx, const std::vector<cv::Point2d>& view1,
                     const std::vector<cv::Point2d>& view2) {
  PointArrays p;
  p.reserve(idx.size());
  for (int i : idx) p.add(view1[i], view2[i]);
  return p;
}

// The plane's noise scale from its residuals over the points (medianScale from the
// image pair's scale, kept within a factor 4 of it), and its threshold.
void setPlaneNoise(HomographyPlane& plane, const std::vector<cv::Point2d>& view1,
                   const std::vector<cv::Point2d>& view2, const std::vector<int>& among,
                   const Energy& energy, const PlaneParams& params) {
  std::vector<double> r2;  // squared residuals: the same order statistics
  r2.reserve(among.size());
  for (int i : among) r2.push_back(transferErrorSquaredOneDivision(plane.H, view1[i], view2[i]));
  const double sigma = energy.sigma;
  const NoiseScale s = medianScaleSquared(r2, sigma, params.noise.tail_sigmas);
  plane.noise_px = s.inliers > 0 ? std::clamp(s.sigma_px, sigma, 4.0 * sigma) : sigma;
  // A fixed threshold stays every plane's; the scale still counts the plane's cost in its
  // own units (an implied scale smaller than the data's would make splitting pay).
  plane.threshold_px = energy.fixed_threshold_px > 0.0
                           ? energy.fixed_threshold_px
                           : params.inlier_threshold_sigma * plane.noise_px;
}

// Planes found one after another can be the same physical plane (split by noise):
// two are merged when the criterion says so: one homography refitted on both costs less
// than the two, one plane's label cost included. Best merge first, until none pays.
// Returns whether any two were merged.
bool mergeSamePlanes(std::vector<HomographyPlane>& planes, const std::vector<cv::Point2d>& view1,
                     const std::vector<cv::Point2d>& view2, const PlaneParams& params,
                     const Energy& energy) {
  bool merged_any = false;
  for (;;) {
    double best_gain = 0.0;
    size_t bi = 0, bj = 0;
    HomographyPlane best_plane;
    std::vector<double> widths;  // each plane's width term, once
    for (const HomographyPlane& plane : planes) widths.push_back(energy.widthCost(plane));
    for (size_t i = 0; i < planes.size(); ++i) {
      for (size_t j = i + 1; j < planes.size(); ++j) {
        std::vector<int> both = planes[i].inliers;
        both.insert(both.end(), planes[j].inliers.begin(), planes[j].inliers.end());
        std::vector<int> in_union = ascendingUnion(planes[i].inliers, planes[j].inliers);
        const double union_px = std::max(planes[i].threshold_px, planes[j].threshold_px);
        // Every point of the two keeps its cheapest label either way (a point the merged
        // plane does not explain may go to a third plane or become an outlier).
        // (Each plane's costs over the two's points by pointCosts, then combined in the
        // same order as point by point.)
        const PointArrays both_points = arraysOf(both, view1, view2);
        std::vector<double> others(both.size(), energy.k2), ci, cj, cm;
        for (size_t m = 0; m < planes.size(); ++m) {
          if (m == i || m == j) continue;
          pointCosts(energy, planes[m], widths[m], both_points, cm);
          for (size_t q = 0; q < both.size(); ++q) others[q] = std::min(others[q], cm[q]);
        }
        pointCosts(energy, planes[i], widths[i], both_points, ci);
        pointCosts(energy, planes[j], widths[j], both_points, cj);
        double separate = 0.0;
        for (size_t q = 0; q < both.size(); ++q) separate += std::min({others[q], ci[q], cj[q]});
        // The merged plane refitted robustly on the union from three starts (either
        // plane's homography, least squares on the union), the cheapest kept: one start
        // alone can stay with its own piece.
        HomographyPlane merged;
        double together = std::numeric_limits<double>::infinity();
        const auto union_fit = fitHomography(select(view1, both), select(view2, both));
        for (const std::optional<cv::Matx33d>& start :
             {std::optional<cv::Matx33d>(planes[i].H), std::optional<cv::Matx33d>(planes[j].H),
              union_fit}) {
          if (!start) continue;
          HomographyPlane m;
          m.H = *start;
          std::vector<int> union_inliers = inliersAmong(m.H, view1, view2, in_union, union_px);
          if (union_inliers.size() < 4 ||
              !refitAmong(m.H, union_inliers, view1, view2, in_union, params, union_px))
            continue;
          m.noise_px = std::max(planes[i].noise_px, planes[j].noise_px);
          m.threshold_px = union_px;
          setPlaneNoise(m, view1, view2, in_union, energy, params);
          double cost = 0.0;
          pointCosts(energy, m, energy.widthCost(m), both_points, cm);
          for (size_t q = 0; q < both.size(); ++q) cost += std::min(others[q], cm[q]);
          if (cost < together) {
            together = cost;
            merged = m;
          }
        }
        const double gain = separate + energy.plane_cost - together;
        if (gain > best_gain) {
          best_gain = gain;
          bi = i;
          bj = j;
          best_plane = merged;
        }
      }
    }
    if (best_gain <= 0.0) return merged_any;
    merged_any = true;
    planes[bi].H = best_plane.H;
    planes[bi].noise_px = best_plane.noise_px;
    planes[bi].threshold_px = best_plane.threshold_px;
    planes[bi].inliers.insert(planes[bi].inliers.end(), planes[bj].inliers.begin(),
                              planes[bj].inliers.end());
    std::sort(planes[bi].inliers.begin(), planes[bi].inliers.end());
    planes.erase(planes.begin() + static_cast<long>(bj));
  }
}

// A plane found by the vote can hold two physical planes whose homographies agree within
// the vote's threshold. Split move under the same criterion: the candidate with most votes
// among the plane's points that does not explain nearly all of them, and the best
// candidate on the rest, each refitted with its own scale; the plane is replaced by the
// two when their cost plus one more label cost is below its cost. Returns whether any
// plane was split.
bool splitPlanes(std::vector<HomographyPlane>& planes, const std::vector<cv::Matx33d>& candidates,
                 const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2,
                 const PlaneParams& params, const Energy& energy, double vote_px) {
  const size_t count = planes.size();
  bool split_any = false;
  for (size_t p = 0; p < count; ++p) {
    // A split adds a plane: never beyond max_planes (the caller's cap, e.g. 1).
    if (static_cast<int>(planes.size()) >= params.max_planes) return split_any;
    const std::vector<int> members = planes[p].inliers;
    if (static_cast<int>(members.size()) < 2 * params.min_plane_support) continue;
    std::vector<bool> mine(view1.size(), false);
    for (int i : members) mine[i] = true;
    auto among = [&members](const std::vector<bool>& active) {
      std::vector<int> idx;
      for (int i : members)
        if (active[i]) idx.push_back(i);
      return idx;
    };
    auto best_candidate = [&](const std::vector<bool>& active, size_t max_votes) {
      int best = -1;
      size_t best_votes = 0;
      // The voters' coordinates in separate arrays, counted in blocks as in voteDominant
      // (vector instructions; the split's count cost more than the votes at 1000 points).
      PointArrays voters;
      for (int i : members)
        if (active[i]) voters.add(view1[i], view2[i]);
      const size_t m = voters.size();
      const double t2 = vote_px * vote_px;
      for (size_t c = 0; c < candidates.size(); ++c) {
        // Counting stops once the candidate is over max_votes or cannot beat the best
        // (checked after each block): the same choice for a fraction of the work.
        size_t votes = 0, left = m;
        for (size_t b0 = 0; b0 < m; b0 += kVoteBlock) {
          const size_t b1 = std::min(m, b0 + kVoteBlock);
          votes += static_cast<size_t>(votesInBlock(candidates[c], voters, b0, b1, t2));
          left -= b1 - b0;
          if (votes > max_votes || votes + left <= best_votes) break;
        }
        if (votes > best_votes && votes <= max_votes) {
          best_votes = votes;
          best = static_cast<int>(c);
        }
      }
      return best;
    };
    auto make = [&](int c, const std::vector<bool>& active, HomographyPlane& out) {
      out.H = candidates[c];
      const std::vector<int> idx = among(active);  // active is a subset of the members
      out.inliers = inliersAmong(out.H, view1, view2, idx, vote_px);
      if (static_cast<int>(out.inliers.size()) < params.min_plane_support ||
          !refitAmong(out.H, out.inliers, view1, view2, idx, params, vote_px))
        return false;
      out.noise_px = planes[p].noise_px;
      out.threshold_px = planes[p].threshold_px;
      setPlaneNoise(out, view1, view2, idx, energy, params);
      return static_cast<int>(out.inliers.size()) >= params.min_plane_support;
    };
    const int a = best_candidate(mine, static_cast<size_t>(0.8 * members.size()));
    HomographyPlane A, B;
    if (a < 0 || !make(a, mine, A)) continue;
    std::vector<bool> rest = mine;
    for (int i : A.inliers) rest[i] = false;
    const int b = best_candidate(rest, members.size());
    if (b < 0 || !make(b, rest, B)) continue;
    double split_cost = 2.0 * energy.plane_cost, whole_cost = energy.plane_cost;
    const PointArrays member_points = arraysOf(members, view1, view2);
    std::vector<double> ca, cb, cw;
    pointCosts(energy, A, energy.widthCost(A), member_points, ca);
    pointCosts(energy, B, energy.widthCost(B), member_points, cb);
    pointCosts(energy, planes[p], energy.widthCost(planes[p]), member_points, cw);
    for (size_t q = 0; q < members.size(); ++q) {
      split_cost += std::min(ca[q], cb[q]);
      whole_cost += cw[q];
    }
    if (split_cost >= whole_cost) continue;
    planes[p] = A;
    planes.push_back(B);
    split_any = true;
  }
  return split_any;
}

// assignPoints, then drops the plane that pays least for itself while one does not pay
// (its points cost less than its label cost more under the other planes or as outliers)
// or has fewer than min_plane_support points, assigning again each time. Returns each
// plane's points. Every point goes to the plane that explains it at least cost (the
// first on ties), or to none.
std::vector<std::vector<int>> keepSupportedPlanes(std::vector<HomographyPlane>& planes,
                                                  const std::vector<cv::Point2d>& view1,
                                                  const std::vector<cv::Point2d>& view2,
                                                  const PlaneParams& params, const Energy& energy) {
  if (planes.empty()) return {};  // (the cost table below would be empty)
  // Each point's cost under each plane once (a plane's costs do not change when another
  // is dropped): cost[i * P + k].
  const size_t n = view1.size();
  std::vector<size_t> alive(planes.size());
  std::iota(alive.begin(), alive.end(), 0);
  // pointCosts a plane at a time (non-finite points cost k^2).
  const size_t stride = planes.size();
  std::vector<double> cost(n * stride);
  PointArrays p;
  p.reserve(n);
  std::vector<char> usable(n);
  for (size_t i = 0; i < n; ++i) {
    usable[i] = finite(view1[i]) && finite(view2[i]);
    p.add(usable[i] ? view1[i] : cv::Point2d(), usable[i] ? view2[i] : cv::Point2d());
  }
  std::vector<double> row(n);
  for (size_t k = 0; k < stride; ++k) {
    pointCosts(energy, planes[k], energy.widthCost(planes[k]), p, row);
    for (size_t i = 0; i < n; ++i) cost[i * stride + k] = usable[i] ? row[i] : energy.k2;
  }
  for (;;) {
    std::vector<std::vector<int>> members(alive.size());
    std::vector<double> gain(alive.size(), -energy.plane_cost);
    for (size_t i = 0; i < n; ++i) {
      if (!finite(view1[i]) || !finite(view2[i])) continue;
      const double* c = &cost[i * stride];
      double best = energy.k2, second = energy.k2;
      long label = -1;
      for (size_t k = 0; k < alive.size(); ++k) {
        // The two least costs and the first least's plane, as selects (no branch).
        const double e = c[alive[k]];
        label = e < best ? static_cast<long>(k) : label;
        second = std::min(second, std::max(best, e));
        best = std::min(best, e);
      }
      if (label < 0) continue;
      members[static_cast<size_t>(label)].push_back(static_cast<int>(i));
      // Without the plane: the next best plane, or an outlier.
      gain[static_cast<size_t>(label)] += second - best;
    }
    long worst = -1;
    for (size_t k = 0; k < alive.size(); ++k) {
      const bool fails = static_cast<int>(members[k].size()) < params.min_plane_support ||
                         gain[k] < 0.0;
      if (fails && (worst < 0 || gain[k] < gain[static_cast<size_t>(worst)]))
        worst = static_cast<long>(k);
    }
    if (worst < 0) {
      std::vector<HomographyPlane> kept;
      for (size_t k : alive) kept.push_back(std::move(planes[k]));
      planes = std::move(kept);
      return members;
    }
    alive.erase(alive.begin() + worst);
  }
}

// Alternates assigning every point to its best plane and refitting each plane on its
// points until the labels stop changing: pieces found early, which hold a few points of
// a neighbouring plane, give those points back. Leaves planes[k].inliers set. Returns
// whether the labels settled (a refit changed none) within refit_iterations rounds.
bool refineAssignment(std::vector<HomographyPlane>& planes, const std::vector<cv::Point2d>& view1,
                      const std::vector<cv::Point2d>& view2, const PlaneParams& params,
                      const Energy& energy) {
  std::vector<std::vector<int>> members = keepSupportedPlanes(planes, view1, view2, params, energy);
  bool stable = false;
  for (int round = 0; round < params.refit_iterations; ++round) {
    for (size_t k = 0; k < planes.size(); ++k) {
      // Cauchy weights at the plane's own scale: a heavy tail does not pull the fit.
      std::vector<double> w;
      if (params.robust_refit) {
        for (int i : members[k])
          w.push_back(cauchyWeight(planes[k].H, view1[i], view2[i], 2.0 * planes[k].noise_px));
      }
      if (auto H = fitHomography(select(view1, members[k]), select(view2, members[k]), w))
        planes[k].H = *H;
      setPlaneNoise(planes[k], view1, view2, members[k], energy, params);
    }
    std::vector<std::vector<int>> next =
        keepSupportedPlanes(planes, view1, view2, params, energy);
    stable = next == members;
    members = std::move(next);
    if (stable) break;
  }
  for (size_t k = 0; k < planes.size(); ++k) planes[k].inliers = std::move(members[k]);
  return stable;
}

// Model selection between each plane's own homography (8 parameters) and the best one F
// admits on its points ([e2]x F + e2 v^T, 3 parameters; F refined by least squares on
// RANSAC's inliers): the induced one is taken when it costs no more than the 5 parameters
// it saves, at the label cost's price per parameter (plane_penalty / 8 x ln N). A plane
// on few or nearly collinear points (a strip of tape) has a free homography that fits
// them but is induced by no plane. Points are then assigned again (no refit, which would
// undo it), and a plane that no longer pays is dropped.
void replaceByInduced(std::vector<HomographyPlane>& planes, const std::vector<cv::Point2d>& view1,
                      const std::vector<cv::Point2d>& view2, const cv::Matx33d& F0, double vote_px,
                      const PlaneParams& params, const Energy& energy) {
  std::vector<int> agree;
  for (const HomographyPlane& plane : planes)
    for (int i : plane.inliers)
      if (epipolarLineDistance(F0, view1[i], view2[i]) < vote_px) agree.push_back(i);
  const auto F = refineFundamental(select(view1, agree), select(view2, agree), energy.sigma);
  if (!F) return;
  cv::Matx31d sv;
  cv::Matx33d u, vt;
  cv::SVD::compute(*F, sv, u, vt);
  const cv::Vec3d e(u(0, 2), u(1, 2), u(2, 2));  // F^T e = 0
  const cv::Matx33d A = cv::Matx33d(0, -e[2], e[1], e[2], 0, -e[0], -e[1], e[0], 0) * *F;
  const double price =
      5.0 * params.plane_penalty / 8.0 * std::log(static_cast<double>(view1.size()));
  bool replaced = false;
  for (HomographyPlane& plane : planes) {
    std::vector<double> w;
    for (int i : plane.inliers)
      w.push_back(cauchyWeight(plane.H, view1[i], view2[i], 2.0 * plane.noise_px));
    const auto Hc = fitInducedHomography(A, e, select(view1, plane.inliers),
                                         select(view2, plane.inliers), w);
    if (!Hc) continue;
    HomographyPlane induced = plane;
    induced.H = *Hc;
    const double extra = energy.sum(induced, plane.inliers, view1, view2) -
                         energy.sum(plane, plane.inliers, view1, view2);
    if (extra <= price) {
      plane.H = *Hc;
      replaced = true;
    }
  }
  auto assign = [&](std::vector<HomographyPlane>& ps) {
    std::vector<std::vector<int>> members = keepSupportedPlanes(ps, view1, view2, params, energy);
    for (size_t k = 0; k < ps.size(); ++k) ps[k].inliers = std::move(members[k]);
  };
  if (replaced) assign(planes);
  // Pieces of one 3D plane, each at its own measured scale (a fixed threshold keeps the
  // old behaviour): planes/epipolar_check.h.
  if (energy.fixed_threshold_px > 0.0) return;
  const PlaneCriterion criterion{[&](const HomographyPlane& p, const std::vector<int>& idx) {
                                   std::vector<double> c;
                                   pointCosts(energy, p, energy.widthCost(p),
                                              arraysOf(idx, view1, view2), c);
                                   return c;
                                 },
                                 [&](HomographyPlane& p, const std::vector<int>& idx) {
                                   setPlaneNoise(p, view1, view2, idx, energy, params);
                                 },
                                 assign, energy.k2, energy.plane_cost};
  mergeInducedPieces(planes, A, e, view1, view2, criterion);
}

// F from the points of the planes (all but `skip`), when they determine it: its inliers
// hold at least a plane's worth off the plane holding most of them (points of one plane
// and a few others leave a family of F). Every plane's distances to its epipolar lines
// under it (the skipped one's too), and those of the planes it was fitted to, pooled.
struct PlanesF {
  std::optional<cv::Matx33d> F;            // nothing: not estimated or not determined
  std::vector<std::vector<double>> dist;   // per plane
  std::vector<double> pooled;              // of the planes F was fitted to
};

PlanesF fundamentalOfPlanes(const std::vector<HomographyPlane>& planes,
                            const std::vector<cv::Point2d>& view1,
                            const std::vector<cv::Point2d>& view2, const PlaneParams& params,
                            double vote_px, size_t skip = std::numeric_limits<size_t>::max()) {
  PlanesF out;
  std::vector<int> on_planes;
  for (size_t p = 0; p < planes.size(); ++p)
    if (p != skip)
      on_planes.insert(on_planes.end(), planes[p].inliers.begin(), planes[p].inliers.end());
  const auto F = estimateFundamental(select(view1, on_planes), select(view2, on_planes), vote_px,
                                     0.5, params.groups.seed);
  if (!F) return out;
  out.dist.resize(planes.size());
  int total = 0, most = 0;
  for (size_t p = 0; p < planes.size(); ++p) {
    int agree = 0;
    for (int i : planes[p].inliers) {
      out.dist[p].push_back(epipolarLineDistance(*F, view1[i], view2[i]));
      agree += out.dist[p].back() < vote_px;
    }
    if (p == skip) continue;
    out.pooled.insert(out.pooled.end(), out.dist[p].begin(), out.dist[p].end());
    total += agree;
    most = std::max(most, agree);
  }
  if (total - most >= params.min_plane_support) out.F = F;
  return out;
}

// Whether plane `tested` is still beyond chance against the F of the other planes and
// their epipolar scale, when those determine one on their own; true when they do not
// (then the F of all planes is the only evidence).
bool offAgainstTheOthers(const std::vector<HomographyPlane>& planes, size_t tested,
                         const std::vector<cv::Point2d>& view1,
                         const std::vector<cv::Point2d>& view2, const PlaneParams& params,
                         double vote_px) {
  const PlanesF others = fundamentalOfPlanes(planes, view1, view2, params, vote_px, tested);
  if (!others.F) return true;
  const double scale = std::max(planes[tested].noise_px, epipolarScale(others.pooled));
  return epipolarOffsetScore(others.dist[tested], scale) >
         epipolarOffsetThreshold(planes.size());
}

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
                    const Energy& energy, double vote_px, PlaneSegmentation& out) {
  std::optional<cv::Matx33d> checked;  // F determined by the planes as they are now
  while (planes.size() >= 2) {
    const PlanesF all = fundamentalOfPlanes(planes, view1, view2, params, vote_px);
    if (!all.F) break;
    checked = all.F;
    out.epipolar_checked = true;
    const double pair_scale = epipolarScale(all.pooled);
    std::vector<char> off(planes.size(), 0);
    size_t worst = planes.size();
    double worst_score = epipolarOffsetThreshold(planes.size());
    for (size_t p = 0; p < planes.size(); ++p) {
      if (all.dist[p].empty()) continue;
      off[p] = median(all.dist[p]) > vote_px;
      const double score =
          epipolarOffsetScore(all.dist[p], std::max(planes[p].noise_px, pair_scale));
      if (score > worst_score) {
        worst_score = score;
        worst = p;
      }
    }
    // Those beyond the threshold all at once, else the one farthest off beyond chance,
    // confirmed against an F of the other planes when they determine one (the F above
    // holds the tested plane too: it may have pulled F, and its own distances the pooled
    // scale, towards itself; review).
    if (std::find(off.begin(), off.end(), 1) == off.end()) {
      if (worst == planes.size()) break;
      if (!offAgainstTheOthers(planes, worst, view1, view2, params, vote_px)) break;
      off[worst] = 1;
    }
    for (size_t p = planes.size(); p-- > 0;) {
      if (!off[p]) continue;
      planes.erase(planes.begin() + static_cast<long>(p));
      ++out.rejected_by_epipolar;
    }
    // That F held the dropped plane: the induced homographies take only an F determined
    // by the planes left (review: none when one is left or F is no longer determined).
    checked.reset();
    refineAssignment(planes, view1, view2, params, energy);
  }
  if (checked) replaceByInduced(planes, view1, view2, *checked, vote_px, params, energy);
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
  // The active points once, coordinates in separate arrays so that the count over a block
  // of points compiles to vector instructions (the arithmetic of transfersWithin).
  // The count of a homography stops after the block where the points left can no longer
  // make it beat the best so far (its bound is then what it could still reach).
  PointArrays points;
  for (size_t i = 0; i < view1.size(); ++i)
    if (isActive(active, i)) points.add(view1[i], view2[i]);
  const double t2 = threshold_px * threshold_px;
  for (int h : order) {
    if (vote_bounds && !beats((*vote_bounds)[h], h)) continue;
    const BlockCount count =
        countWhileItCanWin(homographies[h], points, t2, [&](int reach) { return beats(reach, h); });
    if (vote_bounds) (*vote_bounds)[h] = std::min((*vote_bounds)[h], count.votes);
    if (count.complete && beats(count.votes, h)) {
      vote.votes = count.votes;
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
  for (size_t i = 0; i < view1.size(); ++i)
    if (isActive(active, i) && transfersWithin(H, view1[i], view2[i], threshold_px))
      inliers.push_back(static_cast<int>(i));
  return inliers;
}

bool refitPlane(cv::Matx33d& H, std::vector<int>& inliers, const std::vector<cv::Point2d>& view1,
                const std::vector<cv::Point2d>& view2, const std::vector<bool>& active,
                const PlaneParams& params) {
  return refitAmong(H, inliers, view1, view2, activeIndices(active, view1.size()), params,
                    params.vote_threshold_px);
}

Thresholds fixedThresholds(const PlaneParams& params) {
  if (params.vote_threshold_px <= 0.0 || params.vote_threshold_sigma <= 0.0) return {};
  return {params.vote_threshold_px / params.vote_threshold_sigma, params.vote_threshold_px};
}

std::string checkPlaneParams(const PlaneParams& params) {
  if (!knownCoplanarityTest(params.groups.coplanarity_test))
    return "unknown coplanarity_test '" + params.groups.coplanarity_test +
           "' (transfer or cross_ratio)";
  if (!(params.inlier_threshold_sigma > 0.0) || !(params.vote_threshold_sigma > 0.0))
    return "inlier_threshold_sigma and vote_threshold_sigma must be positive";
  return {};
}

namespace {

// The membership threshold in noise scales from how heavy the residuals' tail is: the
// vote's vote_threshold_sigma for Gaussian noise (tail ratio 1.82), inlier_threshold_sigma
// from a tail ratio of 3 on (real matches), linear in between.
double membershipSigmas(double tail_ratio, const PlaneParams& params) {
  const double lo = std::min(params.vote_threshold_sigma, params.inlier_threshold_sigma);
  const double hi = params.inlier_threshold_sigma;
  if (!(tail_ratio > 0.0)) return hi;
  const double t = std::clamp((tail_ratio - 1.82) / (3.0 - 1.82), 0.0, 1.0);
  return lo + t * (hi - lo);
}

// The k-th smallest of H's transfer residuals (threshold-free fit quality), or infinity
// when it is known to be at least `bound` (at most k residuals below it), which skips the
// selection. r: reused buffer.
double kthResidualBelow(const cv::Matx33d& H, const std::vector<cv::Point2d>& view1,
                        const std::vector<cv::Point2d>& view2, size_t kth, double bound,
                        std::vector<double>& r) {
  const size_t n = view1.size();
  r.resize(n);
  size_t below = 0;
  const double bound2 = bound * bound;
  for (size_t b0 = 0; b0 < n; b0 += kVoteBlock) {
    const size_t b1 = std::min(n, b0 + kVoteBlock);
    for (size_t i = b0; i < b1; ++i) {
      // Squared: the same order, one square root at the end.
      r[i] = transferErrorSquared(H, view1[i], view2[i]);
      below += r[i] < bound2;
    }
    // Even every point left below the bound leaves at most k below it: known already.
    if (below + (n - b1) <= kth) return std::numeric_limits<double>::infinity();
  }
  if (below <= kth) return std::numeric_limits<double>::infinity();
  // NaN (non-finite points) has no order: nth_element's answer kept for it.
  if (std::any_of(r.begin(), r.end(), [](double v) { return std::isnan(v); })) {
    std::nth_element(r.begin(), r.begin() + static_cast<long>(kth), r.end());
    return std::sqrt(r[kth]);
  }
  return std::sqrt(kthNonNegative(r, kth));
}

// Groups drawn as findCoplanarGroups draws them (GroupSampler, repeats skipped), each with
// its fifth point's transfer error, so that the noise scale can be estimated from the
// first ones before any is tested.
struct GroupDraw {
  struct Drawn {
    PointGroup group;
    double fifth_error;
  };
  GroupDraw(const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2,
            const GroupParams& params)
      : view1_(view1), view2_(view2), sampler_(view2, params) {
    max_tries_ = triesFor(params, view2.size());
    // Up to 4096 points a sorted group packs into 60 bits: an open-addressing table of
    // those (the set's node allocations took a tenth of the drawing).
    if (view2.size() <= 4096) {
      size_t size = 64;
      while (size < 2 * static_cast<size_t>(max_tries_)) size *= 2;
      packed_.assign(size, 0);
    } else {
      seen_.reserve(static_cast<size_t>(max_tries_));
    }
  }
  bool next(Drawn& d) {
    PointGroup g;
    while (tried < max_tries_ && sampler_.next(g)) {
      ++tried;
      PointGroup key = g;
      // Sorted by a network of 9 compare-exchanges (min and max, no branches: the
      // insertion sort's mispredicted branches were a tenth of the draw).
      auto exchange = [&key](int a, int b) {
        const int lo = std::min(key[a], key[b]), hi = std::max(key[a], key[b]);
        key[a] = lo;
        key[b] = hi;
      };
      exchange(0, 1);
      exchange(3, 4);
      exchange(2, 4);
      exchange(2, 3);
      exchange(0, 3);
      exchange(0, 2);
      exchange(1, 4);
      exchange(1, 3);
      exchange(1, 2);
      if (!firstTime(key)) continue;
      // Groups of one four follow each other (fifth_points > 1): its homography once.
      if (!have_four_ || !std::equal(g.begin(), g.begin() + 4, four_.begin())) {
        cv::Point2d from[4], to[4];
        for (int k = 0; k < 4; ++k) {
          from[k] = view1_[g[k]];
          to[k] = view2_[g[k]];
          four_[k] = g[k];
        }
        four_h_ = homographyFromFour(from, to);
        have_four_ = true;
      }
      d = {g, four_h_ ? transferError(*four_h_, view1_[g[4]], view2_[g[4]])
                      : std::numeric_limits<double>::infinity()};
      return true;
    }
    return false;
  }
  int tried = 0;

 private:
  struct Hash {
    size_t operator()(const PointGroup& g) const {
      size_t h = 0;
      for (int i : g) h = h * 1000003u + static_cast<size_t>(i);
      return h;
    }
  };
  const std::vector<cv::Point2d>& view1_;
  const std::vector<cv::Point2d>& view2_;
  GroupSampler sampler_;
  // True when the sorted group was not drawn before (and remembers it).
  bool firstTime(const PointGroup& key) {
    if (packed_.empty()) return seen_.insert(key).second;
    uint64_t code = 1;  // never 0, the empty slot
    for (int i : key) code = (code << 12) | static_cast<uint64_t>(i);
    const size_t mask = packed_.size() - 1;
    for (size_t slot = (code * 0x9E3779B97F4A7C15ull) >> 20 & mask;; slot = (slot + 1) & mask) {
      if (packed_[slot] == code) return false;
      if (packed_[slot] == 0) {
        packed_[slot] = code;
        return true;
      }
    }
  }
  std::unordered_set<PointGroup, Hash> seen_;
  std::vector<uint64_t> packed_;
  long max_tries_ = 0;
  std::array<int, 4> four_{};  // the last four whose homography was computed
  std::optional<cv::Matx33d> four_h_;
  bool have_four_ = false;
};

// The noise scale from the best first plane among the pilot's groups: those whose fifth
// point transfers best relative to the group's size (scale-free), then among their
// homographies the noise_pilot_groups with the least k-th smallest residual (k = a tenth
// of the points; threshold-free, robust to 90 % of the points off the plane) go to
// estimateNoiseScale.
// fits (out, one per pilot group): the five-point homographies fitted here, for the
// coplanarity test to reuse (fitted[k] = 1: fits[k] holds it; 2: the fit failed).
NoiseScale pilotNoiseScale(const std::vector<GroupDraw::Drawn>& pilot,
                           const std::vector<cv::Point2d>& view1,
                           const std::vector<cv::Point2d>& view2, const PlaneParams& params,
                           std::vector<cv::Matx33d>& fits, std::vector<char>& fitted) {
  fits.resize(pilot.size());
  fitted.assign(pilot.size(), 0);
  NoiseScaleParams np = params.noise;
  np.min_inliers = std::max({np.min_inliers, params.min_plane_support,
                             static_cast<int>(view1.size() / 10)});
  std::vector<std::pair<double, size_t>> relative;
  for (size_t k = 0; k < pilot.size(); ++k) {
    const PointGroup& g = pilot[k].group;
    double spread = 0.0;
    for (int i : g) spread += cv::norm(view2[i] - view2[g[0]]);
    if (std::isfinite(pilot[k].fifth_error) && spread > 0)
      relative.push_back({pilot[k].fifth_error / spread, k});
  }
  const size_t first = std::min(relative.size(), static_cast<size_t>(3 * params.noise_pilot_groups));
  std::partial_sort(relative.begin(), relative.begin() + static_cast<long>(first), relative.end());
  const size_t kth = std::min(view1.size() - 1, static_cast<size_t>(np.min_inliers));
  const size_t wanted = static_cast<size_t>(std::max(0, params.noise_pilot_groups));
  std::vector<std::pair<double, cv::Matx33d>> ranked;
  std::vector<double> r, best;  // best: the least k-th residuals so far, up to `wanted`
  for (size_t k = 0; k < first; ++k) {
    const PointGroup& g = pilot[relative[k].second].group;
    const std::vector<int> idx(g.begin(), g.end());
    const auto H = fitHomography(select(view1, idx), select(view2, idx));
    fitted[relative[k].second] = H ? 1 : 2;
    if (!H) continue;
    fits[relative[k].second] = *H;
    // A candidate with at most k residuals below the wanted-th least k-th residual so
    // far cannot be among the wanted: its order statistic is not needed (same ranking).
    const double bound =
        best.size() == wanted && wanted > 0 ? best.back() : std::numeric_limits<double>::infinity();
    const double kth_r = kthResidualBelow(*H, view1, view2, kth, bound, r);
    ranked.push_back({kth_r, *H});
    if (kth_r < bound && wanted > 0) {
      best.insert(std::upper_bound(best.begin(), best.end(), kth_r), kth_r);
      if (best.size() > wanted) best.pop_back();
    }
  }
  const size_t keep = std::min(ranked.size(), wanted);
  std::partial_sort(ranked.begin(), ranked.begin() + static_cast<long>(keep), ranked.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<cv::Matx33d> candidates;
  for (size_t k = 0; k < keep; ++k) candidates.push_back(ranked[k].second);
  return estimateNoiseScale(candidates, view1, view2, np);
}

// The vote of segmentUnique repeated as planes take their points (paper IV-C among the
// points left: most votes, the first on ties, a used candidate never again). Each
// candidate's count over the active points is kept once known: when a plane's points
// leave, it loses only their votes, counted over those points alone (the vote after the
// first recounted every candidate over every point left, most of them in full, since a
// candidate of another large plane cannot be ruled out early). Candidates whose count is
// not known are counted as voteDominant counts them, stopping once they cannot win or
// the bail-out's test says they will not (so the winners are voteDominant's except, rarely,
// a candidate as good as the best that the bail-out stopped).
class RepeatedVote {
 public:
  RepeatedVote(const std::vector<cv::Matx33d>& candidates, const std::vector<cv::Point2d>& view1,
               const std::vector<cv::Point2d>& view2, double threshold_px, unsigned seed)
      : candidates_(candidates),
        view1_(view1),
        view2_(view2),
        threshold_px_(threshold_px),
        count_(candidates.size(), -1),
        bound_(candidates.size(), std::numeric_limits<int>::max()),
        retired_(candidates.size(), false),
        order_(view1.size()) {
    // The points counted in a random order, so that the first ones counted are a random
    // sample of them (the bail-out's premise; input is often ordered by plane).
    std::iota(order_.begin(), order_.end(), 0);
    std::mt19937 rng(seed);
    std::shuffle(order_.begin(), order_.end(), rng);
  }

  Vote next(const std::vector<bool>& active) {
    Vote vote;
    auto beats = [&vote](int votes, int h) {
      return votes > vote.votes || (votes == vote.votes && votes > 0 && h < vote.winner);
    };
    std::vector<int> unknown;
    for (size_t h = 0; h < candidates_.size(); ++h) {
      if (retired_[h]) continue;
      if (count_[h] < 0) {
        unknown.push_back(static_cast<int>(h));
      } else if (beats(count_[h], static_cast<int>(h))) {
        vote.votes = count_[h];
        vote.winner = static_cast<int>(h);
      }
    }
    // The likeliest winners first, so that the rest stop early or are skipped.
    std::stable_sort(unknown.begin(), unknown.end(),
                     [this](int a, int b) { return bound_[a] > bound_[b]; });
    PointArrays points;
    points.reserve(order_.size());
    for (int i : order_)
      if (active[i]) points.add(view1_[i], view2_[i]);
    const double t2 = threshold_px_ * threshold_px_;
    // Bail-out (Capel 2005, "An effective bail-out test for RANSAC consensus scoring"):
    // the first `seen` points are a random sample, so a candidate as good as the best so
    // far (share e of the points) has about seen x e votes among them, with a binomial
    // spread; one more than kBailOutSigmas spreads below that is stopped (at 1000 points
    // most candidates of the other planes were counted over most points before the exact
    // bound stopped them: that row 1.53x -> 1.40x sequential MAGSAC's time, no winner
    // changed on AdelaideRMF or the synthetic rows). Its bound stays votes + the points
    // left, so it is counted again once it could win.
    auto bail_out = [&](int votes, size_t seen) {
      if (vote.winner < 0) return false;
      const double e = static_cast<double>(vote.votes) / std::max<size_t>(1, points.size());
      const double expected = static_cast<double>(seen) * e;
      return votes < expected - kBailOutSigmas * std::sqrt(expected * (1.0 - e));
    };
    for (int h : unknown) {
      if (!beats(bound_[h], h)) continue;
      const BlockCount count = countWhileItCanWin(
          candidates_[h], points, t2, [&](int reach) { return beats(reach, h); }, bail_out);
      bound_[h] = std::min(bound_[h], count.votes);
      if (!count.complete) continue;
      count_[h] = count.votes;
      if (beats(count.votes, h)) {
        vote.votes = count.votes;
        vote.winner = h;
      }
    }
    if (vote.winner >= 0)
      vote.voters = inliersOf(candidates_[vote.winner], view1_, view2_, active, threshold_px_);
    return vote;
  }

  // Candidate h won (or failed as a plane): it never votes again.
  void retire(int h) { retired_[static_cast<size_t>(h)] = true; }

  // These active points leave the vote: the known counts lose their votes.
  void leave(const std::vector<int>& points) {
    PointArrays leaving;
    for (int i : points) leaving.add(view1_[i], view2_[i]);
    const double t2 = threshold_px_ * threshold_px_;
    for (size_t h = 0; h < candidates_.size(); ++h) {
      if (retired_[h] || count_[h] <= 0) continue;
      const int lost = votesAmong(candidates_[h], leaving, t2);
      count_[h] -= lost;
      bound_[h] = count_[h];
    }
  }

 private:
  const std::vector<cv::Matx33d>& candidates_;
  const std::vector<cv::Point2d>& view1_;
  const std::vector<cv::Point2d>& view2_;
  double threshold_px_;
  std::vector<int> count_;  // votes over the active points, -1 unknown
  std::vector<int> bound_;  // at least its votes over the active points
  std::vector<bool> retired_;
  std::vector<int> order_;  // the order the points are counted in
};

// Indices of the first copy of every correspondence; dup_of[i] = index of i's first copy.
std::vector<int> uniqueCorrespondences(const std::vector<cv::Point2d>& view1,
                                       const std::vector<cv::Point2d>& view2,
                                       std::vector<int>& dup_of) {
  std::vector<int> keep;
  dup_of.assign(view1.size(), -1);
  auto key = [&](size_t i) {
    return std::make_tuple(view1[i].x, view1[i].y, view2[i].x, view2[i].y);
  };
  bool all_finite = true;
  for (size_t i = 0; i < view1.size(); ++i)
    all_finite = all_finite && finite(view1[i]) && finite(view2[i]);
  if (all_finite) {
    // The indices sorted by their four coordinates (ties by index): each run of equal
    // ones starts with its first copy. The same as the map below without a node per point
    // (a tenth of a millisecond at 1000 points); the map stays for non-finite input, whose
    // comparisons are not an order.
    std::vector<int> order(view1.size());
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) {
      const auto ka = key(static_cast<size_t>(a)), kb = key(static_cast<size_t>(b));
      return ka < kb || (!(kb < ka) && a < b);
    });
    for (size_t r = 0; r < order.size(); ++r) {
      const size_t i = static_cast<size_t>(order[r]);
      const bool same = r > 0 && !(key(static_cast<size_t>(order[r - 1])) < key(i));
      dup_of[i] = same ? dup_of[static_cast<size_t>(order[r - 1])] : static_cast<int>(i);
    }
    for (size_t i = 0; i < view1.size(); ++i)
      if (dup_of[i] == static_cast<int>(i)) keep.push_back(static_cast<int>(i));
    return keep;
  }
  std::map<std::tuple<double, double, double, double>, int> first;
  for (size_t i = 0; i < view1.size(); ++i) {
    const auto key = std::make_tuple(view1[i].x, view1[i].y, view2[i].x, view2[i].y);
    const auto it = first.emplace(key, static_cast<int>(i));
    dup_of[i] = it.first->second;
    if (it.second) keep.push_back(static_cast<int>(i));
  }
  return keep;
}

PlaneSegmentation segmentUnique(const std::vector<cv::Point2d>& view1,
                                const std::vector<cv::Point2d>& view2,
                                const PlaneParams& user_params) {
  PlaneSegmentation out;
  out.labels.assign(view1.size(), 0);
  if (view1.size() < 5) return out;

  // Groups: the first drawn (the pilot) give the noise scale unless the user fixed it.
  GroupDraw draw(view1, view2, user_params.groups);
  std::vector<GroupDraw::Drawn> drawn;
  // (Only when the scale is to be estimated: a fixed one needs no pilot.)
  const long pilot_size = fixedThresholds(user_params).sigma_px > 0.0
                              ? 0L
                              : std::max<long>(200, 4L * static_cast<long>(view1.size()));
  for (GroupDraw::Drawn d; static_cast<long>(drawn.size()) < pilot_size && draw.next(d);)
    drawn.push_back(d);
  Thresholds th = fixedThresholds(user_params);
  const bool estimate = th.sigma_px <= 0.0;
  double membership_sigmas = user_params.inlier_threshold_sigma;
  std::vector<cv::Matx33d> pilot_fits;
  std::vector<char> pilot_fitted;  // the pilot's fits of its groups, reused by the test
  if (estimate) {
    const NoiseScale s =
        pilotNoiseScale(drawn, view1, view2, user_params, pilot_fits, pilot_fitted);
    const double sigma = s.inliers > 0 ? s.sigma_px : user_params.noise.max_sigma_px;
    membership_sigmas = membershipSigmas(s.tail_ratio, user_params);
    th = {sigma, sigma * membership_sigmas};
  }
  // With an estimated scale the vote counts the planes' cores (vote_threshold_sigma); each
  // plane then takes its points within inlier_threshold_sigma of its own scale.
  const double vote_px = estimate ? th.sigma_px * user_params.vote_threshold_sigma : th.inlier_px;
  out.noise_px = th.sigma_px;
  out.threshold_px = th.inlier_px;
  PlaneParams params = user_params;
  params.vote_threshold_px = vote_px;
  params.inlier_threshold_sigma = membership_sigmas;
  // An outlier costs (threshold / scale)^2: the membership threshold in noise scales.
  const double k = estimate ? params.inlier_threshold_sigma : params.vote_threshold_sigma;
  const Energy energy{k * k, th.sigma_px,
                      params.plane_penalty * std::log(static_cast<double>(view1.size())),
                      estimate ? 0.0 : th.inlier_px};

  // Paper IV-B with the chosen test, until enough groups pass or the tries run out.
  const GroupParams& gp = params.groups;
  const long wanted =
      std::min<long>(gp.max_groups, static_cast<long>(gp.groups_per_point) * view2.size());
  const bool transfer = gp.coplanarity_test == "transfer";
  std::vector<cv::Matx33d> candidates;
  auto test = [&](const GroupDraw::Drawn& d, long pilot_index) {
    const bool ok = transfer ? d.fifth_error <= gp.transfer_threshold_sigma * th.sigma_px
                             : isCoplanarGroup(d.group, view1, view2, gp, 0.0);
    if (!ok) return;
    std::optional<cv::Matx33d> H;
    const char fitted = pilot_index >= 0 && static_cast<size_t>(pilot_index) < pilot_fitted.size()
                            ? pilot_fitted[static_cast<size_t>(pilot_index)]
                            : 0;
    if (fitted == 1) {
      H = pilot_fits[static_cast<size_t>(pilot_index)];
    } else if (fitted == 0) {
      const std::vector<int> idx(d.group.begin(), d.group.end());
      H = fitHomography(select(view1, idx), select(view2, idx));
    }
    if (H) {
      candidates.push_back(*H);
      out.accepted_groups.push_back(d.group);
    }
  };
  for (size_t i = 0; i < drawn.size() && static_cast<long>(candidates.size()) < wanted; ++i)
    test(drawn[i], static_cast<long>(i));
  for (GroupDraw::Drawn d; static_cast<long>(candidates.size()) < wanted && draw.next(d);)
    test(d, -1);
  out.groups_built = draw.tried;
  out.groups_coplanar = static_cast<int>(out.accepted_groups.size());

  std::vector<bool> active(view1.size());
  for (size_t i = 0; i < view1.size(); ++i) active[i] = finite(view1[i]) && finite(view2[i]);

  // Paper IV-C repeated: the winner becomes a plane, its points leave the vote, while a
  // plane pays its label cost.
  std::vector<HomographyPlane> planes;
  RepeatedVote repeated(candidates, view1, view2, params.vote_threshold_px, gp.seed);
  while (static_cast<int>(planes.size()) < params.max_planes) {
    Vote vote = repeated.next(active);
    if (vote.winner < 0 || vote.votes < std::min(5, params.min_plane_support)) break;
    HomographyPlane plane;
    plane.H = candidates[vote.winner];
    plane.inliers = std::move(vote.voters);
    repeated.retire(vote.winner);  // used: never votes again
    const std::vector<int> left = activeIndices(active, view1.size());
    if (!refitAmong(plane.H, plane.inliers, view1, view2, left, params, params.vote_threshold_px) ||
        static_cast<int>(plane.inliers.size()) < params.min_plane_support) {
      continue;
    }
    // Its own noise scale (estimated ones only; a fixed threshold is every plane's), and
    // its points under its own threshold.
    plane.noise_px = th.sigma_px;
    plane.threshold_px = th.inlier_px;
    setPlaneNoise(plane, view1, view2, left, energy, params);
    if (!refitAmong(plane.H, plane.inliers, view1, view2, left, params, plane.threshold_px) ||
        static_cast<int>(plane.inliers.size()) < params.min_plane_support) {
      continue;
    }
    double gain = -energy.plane_cost;
    const double width = energy.widthCost(plane);
    for (int i : plane.inliers) gain += energy.k2 - energy.point(plane, view1[i], view2[i], width);
    if (gain <= 0.0) break;  // the best left does not pay for itself: neither will the rest
    for (int i : plane.inliers) active[i] = false;
    repeated.leave(plane.inliers);
    planes.push_back(std::move(plane));
  }
  // Each move is followed by the assignment again, unless it changed no plane and the
  // assignment had settled: it would start from the labels it settled on (at 500-1000
  // points, where the moves rarely change anything, the repeats were a sixth of the core).
  bool settled = refineAssignment(planes, view1, view2, params, energy);
  if (splitPlanes(planes, candidates, view1, view2, params, energy, vote_px) || !settled)
    settled = refineAssignment(planes, view1, view2, params, energy);
  if (mergeSamePlanes(planes, view1, view2, params, energy) || !settled)
    refineAssignment(planes, view1, view2, params, energy);
  auto by_support = [](const HomographyPlane& a, const HomographyPlane& b) {
    return a.inliers.size() > b.inliers.size();
  };
  std::stable_sort(planes.begin(), planes.end(), by_support);
  if (params.epipolar_check) {
    dropNonInduced(planes, view1, view2, params, energy, vote_px, out);
    std::stable_sort(planes.begin(), planes.end(), by_support);
  }
  for (size_t p = 0; p < planes.size(); ++p) {
    HomographyPlane& plane = planes[p];
    for (int i : plane.inliers) out.labels[i] = static_cast<int>(p) + 1;
    plane.rms_error_px = rmsError(plane.H, plane.inliers, view1, view2);
    plane.score = static_cast<double>(plane.inliers.size()) / view1.size();
  }
  out.planes = std::move(planes);
  return out;
}

}  // namespace

PlaneSegmentation segmentPlanes(const std::vector<cv::Point2d>& view1,
                                const std::vector<cv::Point2d>& view2, const PlaneParams& params) {
  PlaneSegmentation out;
  if (view1.size() != view2.size()) {
    out.error = "the two views have different numbers of points";
    return out;
  }
  out.error = checkPlaneParams(params);
  if (!out.error.empty()) {
    out.labels.assign(view1.size(), 0);
    return out;
  }
  std::vector<int> dup_of;
  const std::vector<int> keep = uniqueCorrespondences(view1, view2, dup_of);
  if (keep.size() == view1.size()) return segmentUnique(view1, view2, params);
  PlaneSegmentation u = segmentUnique(select(view1, keep), select(view2, keep), params);
  // Back to the caller's indices; a repeat gets its first copy's label.
  std::vector<int> labels(view1.size(), 0), back(view1.size(), -1);
  for (size_t j = 0; j < keep.size(); ++j) back[keep[j]] = static_cast<int>(j);
  for (size_t i = 0; i < view1.size(); ++i) labels[i] = u.labels[back[dup_of[i]]];
  for (HomographyPlane& p : u.planes) {
    std::vector<int> idx;
    for (size_t i = 0; i < view1.size(); ++i)
      if (labels[i] > 0 && &u.planes[labels[i] - 1] == &p) idx.push_back(static_cast<int>(i));
    p.inliers = std::move(idx);
  }
  for (PointGroup& g : u.accepted_groups)
    for (int& i : g) i = keep[i];
  u.labels = std::move(labels);
  u.duplicates = static_cast<int>(view1.size() - keep.size());
  return u;
}

}  // namespace mono_plane_detection
