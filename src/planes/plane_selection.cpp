#include "plane_selection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <tuple>

#include "mono_plane_detection/geometry/homography_four.h"
#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/planes/epipolar_check.h"
#include "vote_count.h"

namespace mono_plane_detection {
namespace voting {

namespace {

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

}  // namespace

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

namespace {

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
      const bool fails =
          static_cast<int>(members[k].size()) < params.min_plane_support || gain[k] < 0.0;
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

}  // namespace

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
    std::vector<std::vector<int>> next = keepSupportedPlanes(planes, view1, view2, params, energy);
    stable = next == members;
    members = std::move(next);
    if (stable) break;
  }
  for (size_t k = 0; k < planes.size(); ++k) planes[k].inliers = std::move(members[k]);
  return stable;
}

namespace {

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
    const auto Hc =
        fitInducedHomography(A, e, select(view1, plane.inliers), select(view2, plane.inliers), w);
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
  std::optional<cv::Matx33d> F;           // nothing: not estimated or not determined
  std::vector<std::vector<double>> dist;  // per plane
  std::vector<double> pooled;             // of the planes F was fitted to
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
  return epipolarOffsetScore(others.dist[tested], scale) > epipolarOffsetThreshold(planes.size());
}

}  // namespace

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

}  // namespace voting
}  // namespace mono_plane_detection
