#include "mono_plane_detection/planes/noise_scale.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "mono_plane_detection/geometry/homography_fit.h"

namespace mono_plane_detection {

namespace {

// msseScale, also giving the largest inlier residual (the inlier set's cut).
NoiseScale msseWithCut(std::vector<double> residuals, int min_inliers, int model_dof,
                       double stop_sigmas, double* cut) {
  residuals.erase(std::remove_if(residuals.begin(), residuals.end(),
                                 [](double r) { return !std::isfinite(r); }),
                  residuals.end());
  const int n = static_cast<int>(residuals.size());
  min_inliers = std::max(min_inliers, model_dof / 2 + 1);  // 2k - dof > 0
  if (n < min_inliers) return {};
  // Sorted lazily: the smallest part first, the rest only when the inliers reach into it
  // (a good candidate stops early; this runs for every pilot candidate).
  size_t sorted = std::min<size_t>(n, std::max<size_t>(2 * min_inliers, n / 2));
  std::nth_element(residuals.begin(), residuals.begin() + static_cast<long>(sorted) - 1,
                   residuals.end());
  std::sort(residuals.begin(), residuals.begin() + static_cast<long>(sorted));
  auto ensure = [&](int k) {
    if (static_cast<size_t>(k) >= sorted) {
      std::sort(residuals.begin() + static_cast<long>(sorted), residuals.end());
      sorted = residuals.size();
    }
  };
  double sum = 0.0;
  for (int k = 1; k <= n; ++k) {
    ensure(k - 1);
    sum += residuals[k - 1] * residuals[k - 1];
    if (k < min_inliers) continue;
    const double sigma = std::sqrt(sum / (2.0 * k - model_dof));
    *cut = residuals[k - 1];
    if (k == n) return {sigma, k};
    ensure(k);
    if (residuals[k] > stop_sigmas * sigma) return {sigma, k};
  }
  return {};
}

}  // namespace

NoiseScale msseScale(std::vector<double> residuals, int min_inliers, int model_dof,
                     double stop_sigmas) {
  double cut = 0.0;
  return msseWithCut(std::move(residuals), min_inliers, model_dof, stop_sigmas, &cut);
}

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
  if (!(sigma0 > 0) || !(cut_sigmas > 0)) return {};
  // The median of Rayleigh(sigma) residuals below c sigma is sigma sqrt(-2 ln(1 - F/2)),
  // F = 1 - exp(-c^2 / 2) the share below the cut (1.1774 sigma for a wide cut).
  const double share = 1.0 - std::exp(-0.5 * cut_sigmas * cut_sigmas);
  const double median_in_sigmas = std::sqrt(-2.0 * std::log(1.0 - 0.5 * share));
  NoiseScale s{sigma0, 0};
  std::vector<double> in;
  for (int it = 0; it < iterations; ++it) {
    const double cut = cut_sigmas * s.sigma_px;
    in.clear();
    for (double r : residuals)
      if (std::isfinite(r) && r < cut) in.push_back(r);
    if (in.empty()) return {};
    std::nth_element(in.begin(), in.begin() + in.size() / 2, in.end());
    const double next = in[in.size() / 2] / median_in_sigmas;
    const bool converged = std::abs(next - s.sigma_px) < 1e-3 * s.sigma_px;
    const double median = in[in.size() / 2];
    std::nth_element(in.begin(), in.begin() + (in.size() * 9) / 10, in.end());
    const double q90 = in[(in.size() * 9) / 10];
    s = {next, static_cast<int>(in.size()), median > 0 ? q90 / median : 0.0};
    if (converged || !(next > 0)) break;
  }
  return s;
}

namespace {

double asscScore(const NoiseScale& s) {
  return s.inliers > 0 ? s.inliers / (s.sigma_px * s.sigma_px) : 0.0;
}

// Refits H on the inlier set of `scale` (residuals r under H, cut: its largest inlier
// residual) and estimates again while ASSC's score improves. Each round's residuals and
// cut come from the previous one (recomputing them took a third of the estimate).
NoiseScale refine(cv::Matx33d& H, NoiseScale scale, std::vector<double> r, double cut,
                  const std::vector<cv::Point2d>& view1, const std::vector<cv::Point2d>& view2,
                  const NoiseScaleParams& params) {
  std::vector<cv::Point2d> a, b;
  std::vector<char> in(r.size()), was;
  for (int round = 0; round < 3; ++round) {
    a.clear();
    b.clear();
    for (size_t i = 0; i < r.size(); ++i) {
      in[i] = r[i] <= cut;
      if (in[i]) {
        a.push_back(view1[i]);
        b.push_back(view2[i]);
      }
    }
    // The same inlier set as the last refit's: it would give the same homography and
    // score, which does not improve on itself (converged).
    if (in == was) break;
    was = in;
    const auto refit = fitHomography(a, b);
    if (!refit) break;
    std::vector<double> next_r = transferResiduals(*refit, view1, view2);
    double next_cut = 0.0;
    const NoiseScale next =
        msseWithCut(next_r, params.min_inliers, 8, params.stop_sigmas, &next_cut);
    if (asscScore(next) <= asscScore(scale)) break;
    H = *refit;
    scale = next;
    r = std::move(next_r);
    cut = next_cut;
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
  for (cv::Matx33d H : candidates) {
    std::vector<double> r = transferResiduals(H, view1, view2);
    double cut = 0.0;
    NoiseScale s = msseWithCut(r, params.min_inliers, 8, params.stop_sigmas, &cut);
    if (s.inliers == 0 || !(s.sigma_px > 0)) continue;
    s = refine(H, s, std::move(r), cut, view1, view2, params);
    if (asscScore(s) > asscScore(best)) {
      best = s;
      best_h = H;
    }
  }
  if (best.inliers == 0) return {};
  // MSSE stops at the first gap, which heavy-tailed noise puts inside the inliers: the
  // best plane's residuals under a truncated Rayleigh model (medianScale, cut at
  // tail_sigmas) take the tail in as far as it is continuous.
  const NoiseScale t = medianScale(transferResiduals(*best_h, view1, view2), best.sigma_px,
                                   params.tail_sigmas, 30);
  if (t.inliers >= params.min_inliers) best = t;
  best.sigma_px = std::clamp(best.sigma_px, params.min_sigma_px, params.max_sigma_px);
  return best;
}

}  // namespace mono_plane_detection
