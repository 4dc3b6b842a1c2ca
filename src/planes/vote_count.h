// The vote's arithmetic, shared by the segmentation (homography_voting.cpp) and the
// moves on its planes (plane_selection.cpp): counting the points a homography transfers
// within a threshold in blocks (vector instructions, early stops), inliers, refits.
// Internal to src/planes/: inline, so each caller's loops compile as before the split.
#pragma once

#include <algorithm>
#include <cmath>
#include <iterator>
#include <opencv2/core.hpp>
#include <vector>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/planes/homography_voting.h"

namespace mono_plane_detection {
namespace voting {

inline bool isActive(const std::vector<bool>& active, size_t i) {
  return active.empty() || active[i];
}

inline std::vector<cv::Point2d> select(const std::vector<cv::Point2d>& p,
                                       const std::vector<int>& idx) {
  std::vector<cv::Point2d> out;
  out.reserve(idx.size());
  for (int i : idx) out.push_back(p[i]);
  return out;
}

inline bool finite(const cv::Point2d& p) { return std::isfinite(p.x) && std::isfinite(p.y); }

// Cauchy weight 1 / (1 + (r / scale)^2) of a point's transfer error r (0 at infinity).
inline double cauchyWeight(const cv::Matx33d& H, const cv::Point2d& a, const cv::Point2d& b,
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

inline constexpr size_t kVoteBlock = 32;
// The vote's bail-out: a candidate this many binomial spreads below the best's share of
// the points counted so far stops (one-sided 0.1 %: about one stop in a thousand wrong
// for a candidate exactly as good as the best).
inline constexpr double kBailOutSigmas = 3.09;

// How many of the points [b0, b1) (at most kVoteBlock) H transfers within sqrt(t2) pixels:
// transfersWithin's arithmetic, written so that it compiles to vector instructions (its
// coefficients in locals, each point's outcome a 0/1 double summed after; a count in an
// integer kept the compiler from vectorising: the vote's loops ran one point at a time).
inline int votesInBlock(const cv::Matx33d& H, const PointArrays& p, size_t b0, size_t b1,
                        double t2) {
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
inline BlockCount countWhileItCanWin(const cv::Matx33d& H, const PointArrays& p, double t2,
                                     CanWin can_win) {
  return countWhileItCanWin(H, p, t2, can_win, [](int, size_t) { return false; });
}
template <class CanWin, class BailOut>
inline BlockCount countWhileItCanWin(const cv::Matx33d& H, const PointArrays& p, double t2,
                                     CanWin can_win, BailOut bail_out) {
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
inline int votesAmong(const cv::Matx33d& H, const PointArrays& p, double t2) {
  int votes = 0;
  for (size_t b0 = 0; b0 < p.size(); b0 += kVoteBlock)
    votes += votesInBlock(H, p, b0, std::min(p.size(), b0 + kVoteBlock), t2);
  return votes;
}

// The points with active[i] (all when active is empty), ascending: the moves below work on
// a plane's or two planes' points, and scanning every point for them took most of a
// merge's time at 1000 points.
inline std::vector<int> activeIndices(const std::vector<bool>& active, size_t n) {
  std::vector<int> idx;
  idx.reserve(n);
  for (size_t i = 0; i < n; ++i)
    if (isActive(active, i)) idx.push_back(static_cast<int>(i));
  return idx;
}

// inliersOf over the points `among` (ascending: the result is then too).
inline std::vector<int> inliersAmong(const cv::Matx33d& H, const std::vector<cv::Point2d>& view1,
                                     const std::vector<cv::Point2d>& view2,
                                     const std::vector<int>& among, double threshold_px) {
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
inline std::vector<int> ascendingUnion(const std::vector<int>& a, const std::vector<int>& b) {
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
inline bool refitAmong(cv::Matx33d& H, std::vector<int>& inliers,
                       const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2,
                       const std::vector<int>& among, const PlaneParams& params,
                       double threshold_px) {
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

inline double rmsError(const cv::Matx33d& H, const std::vector<int>& idx,
                       const std::vector<cv::Point2d>& view1,
                       const std::vector<cv::Point2d>& view2) {
  double sum = 0.0;
  for (int i : idx) {
    const double e = transferError(H, view1[i], view2[i]);
    sum += e * e;
  }
  return idx.empty() ? 0.0 : std::sqrt(sum / idx.size());
}

inline PointArrays arraysOf(const std::vector<int>& idx, const std::vector<cv::Point2d>& view1,
                            const std::vector<cv::Point2d>& view2) {
  PointArrays p;
  p.reserve(idx.size());
  for (int i : idx) p.add(view1[i], view2[i]);
  return p;
}

}  // namespace voting
}  // namespace mono_plane_detection
