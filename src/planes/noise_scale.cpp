#include "mono_plane_detection/planes/noise_scale.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>

#include "mono_plane_detection/geometry/homography_fit.h"

namespace mono_plane_detection {

namespace {

// msseScale on squared residuals (the same order and stop, without a square root per
// residual and per inlier count: the pilot runs 55-73 of these per image pair), also
// giving the largest inlier's squared residual (the inlier set's cut).
NoiseScale msseWithCut(std::vector<double> residuals, int min_inliers, int model_dof,
                       double stop_sigmas, double* cut) {
  residuals.erase(std::remove_if(residuals.begin(), residuals.end(),
                                 [](double r) { return !std::isfinite(r); }),
                  residuals.end());
  const int n = static_cast<int>(residuals.size());
  min_inliers = std::max(min_inliers, model_dof / 2 + 1);  // 2k - dof > 0
  if (n < min_inliers) return {};
  // All sorted at once by sortNonNegative (linear but for a few inversions): cheaper than
  // std::sort's half that the stop needed at most, whose branches were most of the time.
  sortNonNegative(residuals);
  const double stop2 = stop_sigmas * stop_sigmas;
  double sum = 0.0;
  for (int k = 1; k <= n; ++k) {
    sum += residuals[k - 1];
    if (k < min_inliers) continue;
    // r_k^2 > stop^2 sigma^2 with sigma^2 = sum / (2k - dof), without the division.
    const double dof = 2.0 * k - model_dof;
    *cut = residuals[k - 1];
    if (k == n) return {std::sqrt(sum / dof), k};
    if (residuals[k] * dof > stop2 * sum) return {std::sqrt(sum / dof), k};
  }
  return {};
}

// Buckets of sortNonNegative and kthNonNegative: the bits of a non-negative double above
// its 6 leading mantissa bits (64 buckets per octave: squared residuals crowd into a few
// octaves, and the insertion within a bucket was most of the time with 8; a stand-alone
// timing of 250-1000 residuals, half exponential, half spread: 8 / 16 / 32 / 64 per octave
// 2.6 / 1.9 / 1.6 / 1.5 us at 250 and 13.7 / 12.9 / 10.6 / 7.8 us at 1000, std::sort 7.2
// and 35 us). At most 40 octaves of buckets below the largest finite value's; smaller
// values share the first bucket, +infinity and NaN the last.
constexpr int kBucketShift = 46;
constexpr uint32_t kMaxBuckets = 40u << (52 - kBucketShift);  // 40 octaves

struct Buckets {
  uint32_t lo = 0, hi = 0;
  explicit Buckets(const std::vector<double>& values) {
    const uint32_t infinity_bucket = bits(std::numeric_limits<double>::infinity());
    const uint32_t max_buckets = kMaxBuckets;
    uint32_t top = 0, bottom = infinity_bucket;
    for (double v : values) {
      const uint32_t b = bits(v);
      if (b >= infinity_bucket) continue;  // not finite: the last bucket
      top = std::max(top, b);
      bottom = std::min(bottom, b);
    }
    bottom = std::min(bottom, top);  // (none finite)
    hi = top;
    lo = std::max(bottom, top >= max_buckets ? top - (max_buckets - 1) : 0u);
  }
  static uint32_t bits(double v) {
    uint64_t b;
    std::memcpy(&b, &v, sizeof b);
    return static_cast<uint32_t>(b >> kBucketShift);
  }
  uint32_t size() const { return std::min(hi - lo + 1, kMaxBuckets); }  // (never more)
  // Monotone in the value: the order of the buckets is the order of the values.
  uint32_t operator()(double v) const { return std::clamp(bits(v), lo, hi) - lo; }
};

}  // namespace

void sortNonNegative(std::vector<double>& values) {
  const size_t n = values.size();
  if (n < 32) {
    std::sort(values.begin(), values.end());
    return;
  }
  const Buckets bucket(values);
  std::array<uint32_t, kMaxBuckets + 1> start;
  std::fill(start.begin(), start.begin() + bucket.size() + 1, 0u);
  for (double v : values) ++start[bucket(v) + 1];
  for (uint32_t b = 1; b <= bucket.size(); ++b) start[b] += start[b - 1];
  std::vector<double> out(n);
  for (double v : values) out[start[bucket(v)]++] = v;
  // In bucket order: only values within a bucket are out of order.
  for (size_t i = 1; i < n; ++i) {
    const double v = out[i];
    size_t j = i;
    for (; j > 0 && v < out[j - 1]; --j) out[j] = out[j - 1];
    out[j] = v;
  }
  values.swap(out);
}

double kthNonNegative(std::vector<double>& values, size_t k) {
  if (k >= values.size()) return std::numeric_limits<double>::infinity();
  if (values.size() < 64) {
    std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
    return values[k];
  }
  const Buckets bucket(values);
  std::array<uint32_t, kMaxBuckets> count;
  std::fill(count.begin(), count.begin() + bucket.size(), 0u);
  for (double v : values) ++count[bucket(v)];
  uint32_t b = 0;
  size_t before = 0;
  while (before + count[b] <= k) before += count[b++];
  // Only the values of the k-th's bucket, moved to the front, are selected among.
  size_t m = 0;
  for (size_t i = 0; i < values.size(); ++i)
    if (bucket(values[i]) == b) std::swap(values[m++], values[i]);
  std::nth_element(values.begin(), values.begin() + static_cast<long>(k - before),
                   values.begin() + static_cast<long>(m));
  return values[k - before];
}

NoiseScale msseScale(std::vector<double> residuals, int min_inliers, int model_dof,
                     double stop_sigmas) {
  for (double& r : residuals) r *= r;
  double cut = 0.0;
  return msseWithCut(std::move(residuals), min_inliers, model_dof, stop_sigmas, &cut);
}

namespace {

// Squared transfer residuals (infinity where H sends a point to infinity): what MSSE
// sorts and cuts.
std::vector<double> squaredResiduals(const cv::Matx33d& H, const std::vector<cv::Point2d>& view1,
                                     const std::vector<cv::Point2d>& view2) {
  std::vector<double> r(view1.size());
  for (size_t i = 0; i < view1.size(); ++i)
    r[i] = transferErrorSquaredOneDivision(H, view1[i], view2[i]);
  return r;
}

}  // namespace

std::vector<double> transferResiduals(const cv::Matx33d& H, const std::vector<cv::Point2d>& view1,
                                      const std::vector<cv::Point2d>& view2) {
  std::vector<double> r(view1.size());
  for (size_t i = 0; i < view1.size(); ++i) {
    // transferError without std::hypot (overflow-safe but slow; pixels do not overflow).
    const cv::Point2d& a = view1[i];
    const double w = H(2, 0) * a.x + H(2, 1) * a.y + H(2, 2);
    if (std::abs(w) < 1e-12) {
      r[i] = std::numeric_limits<double>::infinity();
      continue;
    }
    // |H a - w b| / |w|: one division instead of two (this runs ~70 times per image
    // pair in the noise-scale estimate).
    const double dx = (H(0, 0) * a.x + H(0, 1) * a.y + H(0, 2)) - view2[i].x * w;
    const double dy = (H(1, 0) * a.x + H(1, 1) * a.y + H(1, 2)) - view2[i].y * w;
    r[i] = std::sqrt(dx * dx + dy * dy) / std::abs(w);
  }
  return r;
}

NoiseScale medianScale(const std::vector<double>& residuals, double sigma0, double cut_sigmas,
                       int iterations) {
  std::vector<double> squared;
  squared.reserve(residuals.size());
  for (double r : residuals) squared.push_back(r * r);
  return medianScaleSquared(squared, sigma0, cut_sigmas, iterations);
}

NoiseScale medianScaleSquared(const std::vector<double>& residuals, double sigma0,
                              double cut_sigmas, int iterations) {
  if (!(sigma0 > 0) || !(cut_sigmas > 0)) return {};
  // The median of Rayleigh(sigma) residuals below c sigma is sigma sqrt(-2 ln(1 - F/2)),
  // F = 1 - exp(-c^2 / 2) the share below the cut (1.1774 sigma for a wide cut).
  const double share = 1.0 - std::exp(-0.5 * cut_sigmas * cut_sigmas);
  const double median_in_sigmas = std::sqrt(-2.0 * std::log(1.0 - 0.5 * share));
  // The residuals under the largest cut so far sorted (the rest kept apart, unsorted):
  // each round's set under its cut is a prefix, its median and 90th percentile two
  // look-ups, the same order statistics as selecting them in every round (two selections
  // per round of up to 30). The cut mostly shrinks, so most residuals are never sorted.
  std::vector<double> sorted, rest;
  sorted.reserve(residuals.size());
  rest.reserve(residuals.size());
  // (Squared residuals throughout: cut and bound squared, the order statistics' roots.)
  double bound = -std::numeric_limits<double>::infinity();  // sorted: every finite r < bound
  for (double r : residuals)
    if (std::isfinite(r)) rest.push_back(r);
  NoiseScale s{sigma0, 0};
  for (int it = 0; it < iterations; ++it) {
    const double cut = cut_sigmas * s.sigma_px * cut_sigmas * s.sigma_px;
    if (cut > bound) {  // the residuals in [bound, cut) join the sorted ones, after them
      const auto mid =
          std::partition(rest.begin(), rest.end(), [cut](double r) { return r < cut; });
      std::vector<double> joining(rest.begin(), mid);
      sortNonNegative(joining);  // (squared: non-negative)
      sorted.insert(sorted.end(), joining.begin(), joining.end());
      rest.erase(rest.begin(), mid);
      bound = cut;
    }
    const size_t in = static_cast<size_t>(std::lower_bound(sorted.begin(), sorted.end(), cut) -
                                          sorted.begin());  // r < cut
    if (in == 0) return {};
    const double median = std::sqrt(sorted[in / 2]);
    const double next = median / median_in_sigmas;
    const bool converged = std::abs(next - s.sigma_px) < 1e-3 * s.sigma_px;
    const double q90 = std::sqrt(sorted[(in * 9) / 10]);
    s = {next, static_cast<int>(in), median > 0 ? q90 / median : 0.0};
    if (converged || !(next > 0)) break;
  }
  return s;
}

namespace {

double asscScore(const NoiseScale& s) {
  return s.inliers > 0 ? s.inliers / (s.sigma_px * s.sigma_px) : 0.0;
}

// One refit step of refine: the homography least squares gives on an inlier set, its
// squared residuals, and their MSSE scale and (squared) cut. It depends on the inlier set only, and
// the candidates of one image pair mostly converge to the same few sets (the dominant plane's), so
// each set's step is computed once per estimate and looked up after.
struct RefitStep {
  std::vector<char> in;
  bool fitted = false;
  cv::Matx33d H;
  std::vector<double> r;
  NoiseScale scale;
  double cut = 0.0;
};

const RefitStep& refitStep(const std::vector<char>& in, const std::vector<cv::Point2d>& view1,
                           const std::vector<cv::Point2d>& view2, const NoiseScaleParams& params,
                           std::vector<RefitStep>& memo) {
  for (const RefitStep& step : memo)
    if (step.in == in) return step;
  RefitStep step;
  step.in = in;
  std::vector<cv::Point2d> a, b;
  for (size_t i = 0; i < in.size(); ++i) {
    if (in[i]) {
      a.push_back(view1[i]);
      b.push_back(view2[i]);
    }
  }
  if (const auto refit = fitHomography(a, b)) {
    step.fitted = true;
    step.H = *refit;
    step.r = squaredResiduals(*refit, view1, view2);
    step.scale = msseWithCut(step.r, params.min_inliers, 8, params.stop_sigmas, &step.cut);
  }
  memo.push_back(std::move(step));
  return memo.back();
}

// Refits H on the inlier set of `scale` (squared residuals r under H, cut: its largest
// inlier's) and estimates again while ASSC's score improves. Each round's residuals and
// cut come from the previous one (recomputing them took a third of the estimate).
NoiseScale refine(cv::Matx33d& H, NoiseScale scale, std::vector<double> r, double cut,
                  const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2,
                  const NoiseScaleParams& params, std::vector<RefitStep>& memo) {
  std::vector<char> in(r.size()), was;
  for (int round = 0; round < 3; ++round) {
    for (size_t i = 0; i < r.size(); ++i) in[i] = r[i] <= cut;
    // The same inlier set as the last refit's: it would give the same homography and
    // score, which does not improve on itself (converged).
    if (in == was) break;
    was = in;
    const RefitStep& step = refitStep(in, view1, view2, params, memo);
    if (!step.fitted) break;
    if (asscScore(step.scale) <= asscScore(scale)) break;
    H = step.H;
    scale = step.scale;
    r = step.r;
    cut = step.cut;
  }
  return scale;
}

}  // namespace

NoiseScale estimateNoiseScale(const std::vector<cv::Matx33d>& candidates,
                              const std::vector<cv::Point2d>& view1,
                              const std::vector<cv::Point2d>& view2,
                              const NoiseScaleParams& params) {
  // Score: inliers per squared scale (ASSC's inliers per scale, Wang and Suter 2004,
  // squared: a homography bridging two planes has about twice the points at twice the
  // scale). The largest inlier set alone would pick a bad candidate whose residuals grow
  // smoothly and never stop MSSE.
  // Each candidate came from 4-5 points; refitted on its inlier set its residuals are
  // those of the plane, not of the sample's own noise.
  NoiseScale best;
  std::optional<cv::Matx33d> best_h;
  std::vector<RefitStep> memo;
  for (cv::Matx33d H : candidates) {
    std::vector<double> r = squaredResiduals(H, view1, view2);
    double cut = 0.0;
    NoiseScale s = msseWithCut(r, params.min_inliers, 8, params.stop_sigmas, &cut);
    if (s.inliers == 0 || !(s.sigma_px > 0)) continue;
    s = refine(H, s, std::move(r), cut, view1, view2, params, memo);
    if (asscScore(s) > asscScore(best)) {
      best = s;
      best_h = H;
    }
  }
  if (best.inliers == 0) return {};
  // MSSE stops at the first gap, which heavy-tailed noise puts inside the inliers: the
  // best plane's residuals under a truncated Rayleigh model (medianScale, cut at
  // tail_sigmas) take the tail in as far as it is continuous.
  const NoiseScale t = medianScaleSquared(squaredResiduals(*best_h, view1, view2), best.sigma_px,
                                          params.tail_sigmas, 30);
  if (t.inliers >= params.min_inliers) best = t;
  best.sigma_px = std::clamp(best.sigma_px, params.min_sigma_px, params.max_sigma_px);
  return best;
}

}  // namespace mono_plane_detection
