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
#include "plane_selection.h"
#include "vote_count.h"

namespace mono_plane_detection {
using namespace voting;  // the vote's arithmetic and the moves on its planes (src/planes/)

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
  np.min_inliers =
      std::max({np.min_inliers, params.min_plane_support, static_cast<int>(view1.size() / 10)});
  std::vector<std::pair<double, size_t>> relative;
  for (size_t k = 0; k < pilot.size(); ++k) {
    const PointGroup& g = pilot[k].group;
    double spread = 0.0;
    for (int i : g) spread += cv::norm(view2[i] - view2[g[0]]);
    if (std::isfinite(pilot[k].fifth_error) && spread > 0)
      relative.push_back({pilot[k].fifth_error / spread, k});
  }
  const size_t first =
      std::min(relative.size(), static_cast<size_t>(3 * params.noise_pilot_groups));
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
