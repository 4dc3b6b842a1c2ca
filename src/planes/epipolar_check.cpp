#include "mono_plane_detection/planes/epipolar_check.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/calib3d.hpp>

#include "mono_plane_detection/geometry/homography_fit.h"
#include "mono_plane_detection/geometry/opencv_usac.h"
#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/geometry/triangulation.h"

namespace mono_plane_detection {

std::optional<cv::Matx33d> estimateFundamental(const std::vector<cv::Point2d>& view1,
                                               const std::vector<cv::Point2d>& view2,
                                               double threshold_px, double min_inlier_share,
                                               unsigned seed, size_t max_sample) {
  if (view1.size() != view2.size() || view1.size() < 15) return std::nullopt;
  const size_t n = view1.size();
  cv::Mat F;
#if MPD_HAVE_USAC
  // USAC: its local optimisation and final least squares on the inliers give a precise F
  // (the old RANSAC returned its best 7-point F: on EuRoC its planes' median epipolar
  // distances were 1.3-3x those under USAC's), and its time grows with the points each
  // model is scored on. A stride through the list (plane after plane, so each keeps its
  // share) fixes F as well as all of them do: at 1000 points 0.31 -> 0.16 ms per call.
  const size_t m = std::max<size_t>(15, std::min(n, max_sample));
  std::vector<cv::Point2d> a, b;
  a.reserve(m);
  b.reserve(m);
  for (size_t k = 0; k < m; ++k) {
    a.push_back(view1[k * n / m]);
    b.push_back(view2[k * n / m]);
  }
  // Deterministic: USAC seeds its own generator.
  F = cv::findFundamentalMat(a, b, cv::USAC_FAST, threshold_px, 0.999, 1000, cv::noArray());
  (void)seed;
#else
  cv::theRNG().state = seed;  // findFundamentalMat's RANSAC draws from it: repeatable
  std::vector<uchar> mask;
  F = cv::findFundamentalMat(view1, view2, cv::FM_RANSAC, threshold_px, 0.999, mask);
  (void)max_sample;
  // Plain RANSAC returns its best 7-point F: polished by least squares on its inliers
  // (refineFundamental, at a quarter of the threshold: about the noise scale), as USAC's
  // own final fit does, so both paths score distances against a least-squares F.
  if (F.rows == 3 && F.cols == 3 && mask.size() == n) {
    std::vector<cv::Point2d> a, b;
    for (size_t i = 0; i < n; ++i)
      if (mask[i]) {
        a.push_back(view1[i]);
        b.push_back(view2[i]);
      }
    if (const auto refined = refineFundamental(a, b, threshold_px / 4)) F = cv::Mat(*refined);
  }
#endif
  if (F.rows != 3 || F.cols != 3) return std::nullopt;  // none, or several solutions
  // The share over every point, by RANSAC's own test (both points near their lines).
  const cv::Matx33d Fm(F);
  size_t inliers = 0;
  for (size_t i = 0; i < n; ++i) {
    const double d2 = epipolarLineDistance(Fm, view1[i], view2[i]);
    const double d1 = epipolarLineDistance(Fm.t(), view2[i], view1[i]);
    inliers += std::max(d1, d2) <= threshold_px;
  }
  if (static_cast<double>(inliers) < min_inlier_share * static_cast<double>(n)) return std::nullopt;
  return Fm;
}

double epipolarTransferError(const cv::Matx33d& H, const cv::Matx33d& F,
                             const std::vector<cv::Point2d>& probe) {
  std::vector<double> d;
  d.reserve(probe.size());
  for (const cv::Point2d& p : probe) {
    const cv::Vec3d x(p.x, p.y, 1.0);
    const cv::Vec3d y = H * x;
    const cv::Vec3d line = F * x;
    const double n = std::hypot(line[0], line[1]);
    if (std::abs(y[2]) < 1e-12 || n < 1e-15) continue;
    d.push_back(std::abs(line.dot(y / y[2])) / n);
  }
  if (d.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

double epipolarLineDistance(const cv::Matx33d& F, const cv::Point2d& x1, const cv::Point2d& x2) {
  const cv::Vec3d line = F * cv::Vec3d(x1.x, x1.y, 1.0);
  const double n = std::sqrt(line[0] * line[0] + line[1] * line[1]);
  if (!(n > 1e-15)) return std::numeric_limits<double>::infinity();
  return std::abs(line[0] * x2.x + line[1] * x2.y + line[2]) / n;
}

namespace {

// The median of |N(0, 1)|, and the standard error of the median of n such values times
// sqrt(n), widened: 0.787 under the normal model, 1.2533 (sqrt(pi / 2), 1.59 times) for
// the heavier tails of real residuals (epipolar_check.h, docs/plane_core.md item 7).
constexpr double kHalfNormalMedian = 0.6745;
constexpr double kMedianError = 1.2533;

}  // namespace

double epipolarOffsetScore(const std::vector<double>& distances, double scale_px) {
  if (distances.empty() || !(scale_px > 0.0)) return -std::numeric_limits<double>::infinity();
  const double n = static_cast<double>(distances.size());
  return (median(distances) - kHalfNormalMedian * scale_px) * std::sqrt(n) /
         (kMedianError * scale_px);
}

double epipolarOffsetThreshold(size_t planes) {
  // The upper quantile of N(0, 1) at p by bisection on its tail, erfc(z / sqrt 2) / 2.
  const double p = 0.001 / static_cast<double>(std::max<size_t>(1, planes));
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double epipolarScale(const std::vector<double>& distances) {
  if (distances.empty()) return 0.0;
  return median(distances) / kHalfNormalMedian;
}

double skewSymmetryError(const cv::Matx33d& H, const cv::Matx33d& F) {
  const double nh = cv::norm(H), nf = cv::norm(F);
  if (nh <= 0 || nf <= 0) return 1.0;
  const cv::Matx33d S = (H * (1.0 / nh)).t() * (F * (1.0 / nf));
  const double ns = cv::norm(S);
  if (ns <= 0) return 0.0;
  return cv::norm(S + S.t()) / (2.0 * ns);
}

}  // namespace mono_plane_detection

namespace mono_plane_detection {
namespace {

// Moves points to zero mean and mean distance sqrt(2) (Hartley's normalisation).
cv::Matx33d normalising(const std::vector<cv::Point2d>& p) {
  cv::Point2d c(0, 0);
  for (const cv::Point2d& q : p) c += q;
  c *= 1.0 / std::max<size_t>(1, p.size());
  double d = 0.0;
  for (const cv::Point2d& q : p) d += cv::norm(q - c);
  d /= std::max<size_t>(1, p.size());
  const double s = d > 0.0 ? std::sqrt(2.0) / d : 1.0;
  return {s, 0, -s * c.x, 0, s, -s * c.y, 0, 0, 1};
}

cv::Vec3d homogeneous(const cv::Point2d& p) { return {p.x, p.y, 1.0}; }

}  // namespace

std::optional<cv::Matx33d> refineFundamental(const std::vector<cv::Point2d>& view1,
                                             const std::vector<cv::Point2d>& view2,
                                             double scale_px, int rounds) {
  if (view1.size() != view2.size() || view1.size() < 8 || !(scale_px > 0.0)) return std::nullopt;
  const cv::Matx33d T1 = normalising(view1), T2 = normalising(view2);
  std::vector<double> w(view1.size(), 1.0);
  cv::Matx33d F;
  for (int round = 0; round <= rounds; ++round) {
    // The normal matrix's upper triangle summed, then mirrored: the same sums as the
    // full a a^T per point (a product commutes exactly) at half the work.
    cv::Matx<double, 9, 9> M = cv::Matx<double, 9, 9>::zeros();
    for (size_t i = 0; i < view1.size(); ++i) {
      const cv::Vec3d x = T1 * homogeneous(view1[i]), y = T2 * homogeneous(view2[i]);
      double a[9];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) a[3 * r + c] = y[r] * x[c];
      for (int r = 0; r < 9; ++r)
        for (int c = r; c < 9; ++c) M(r, c) += a[r] * a[c] * w[i];
    }
    for (int r = 0; r < 9; ++r)
      for (int c = 0; c < r; ++c) M(r, c) = M(c, r);
    cv::Matx<double, 9, 1> values;
    cv::Matx<double, 9, 9> vectors;
    cv::eigen(M, values, vectors);
    if (!(values(7) > 0.0)) return std::nullopt;  // a family of F fits
    cv::Matx33d Fn;
    for (int k = 0; k < 9; ++k) Fn(k / 3, k % 3) = vectors(8, k);
    cv::Matx31d sv;
    cv::Matx33d u, vt;
    cv::SVD::compute(Fn, sv, u, vt);
    Fn = u * cv::Matx33d(sv(0), 0, 0, 0, sv(1), 0, 0, 0, 0) * vt;
    F = T2.t() * Fn * T1;
    F *= 1.0 / cv::norm(F);
    for (size_t i = 0; i < view1.size(); ++i) {
      const double d = sampsonDistance(F, view1[i], view2[i]);
      w[i] = 1.0 / (1.0 + d * d / (scale_px * scale_px));
    }
  }
  return F;
}

std::optional<cv::Matx33d> fitInducedHomography(const cv::Matx33d& H1, const cv::Vec3d& e2,
                                                const std::vector<cv::Point2d>& from,
                                                const std::vector<cv::Point2d>& to,
                                                const std::vector<double>& weights) {
  if (from.size() != to.size() || from.size() < 3 ||
      (!weights.empty() && weights.size() != from.size()))
    return std::nullopt;
  const cv::Matx33d T1 = normalising(from), T2 = normalising(to);
  const cv::Matx33d H = T2 * H1 * T1.inv();
  const cv::Vec3d e = T2 * e2;
  std::vector<cv::Vec3d> x(from.size()), y(from.size());
  for (size_t i = 0; i < from.size(); ++i) {
    x[i] = T1 * homogeneous(from[i]);
    y[i] = T2 * homogeneous(to[i]);
  }
  // y x ((H + e v^T) x) = 0: two rows per point, linear in v. Each row divided by the
  // image's third coordinate (from the last round) is the transfer error.
  cv::Vec3d v(0, 0, 0);
  bool solved = false;
  for (int round = 0; round < 4; ++round) {
    cv::Matx33d N = cv::Matx33d::zeros();
    cv::Vec3d r(0, 0, 0);
    for (size_t i = 0; i < x.size(); ++i) {
      const cv::Vec3d h = H * x[i];
      const double s = v.dot(x[i]);
      const double z = h[2] + e[2] * s;
      const double w = (weights.empty() ? 1.0 : weights[i]) / std::max(z * z, 1e-12);
      if (!(w > 0.0) || !std::isfinite(w)) continue;
      const double c0 = y[i][1] * e[2] - e[1], r0 = y[i][1] * h[2] - h[1];
      const double c1 = e[0] - y[i][0] * e[2], r1 = h[0] - y[i][0] * h[2];
      N += (x[i] * x[i].t()) * (w * (c0 * c0 + c1 * c1));
      r -= x[i] * (w * (c0 * r0 + c1 * r1));
    }
    cv::Matx31d values;
    cv::Matx33d vectors;
    cv::eigen(N, values, vectors);
    if (!(values(2) > 1e-9 * values(0))) return std::nullopt;  // v not fixed (collinear points)
    v = N.solve(r, cv::DECOMP_CHOLESKY);
    solved = true;
  }
  if (!solved) return std::nullopt;
  cv::Matx33d out = T2.inv() * (H + e * v.t()) * T1;
  const double norm = cv::norm(out);
  if (!(norm > 0.0) || !std::isfinite(norm)) return std::nullopt;
  return out * (1.0 / norm);
}

std::optional<cv::Matx33d> fitInducedRobust(const cv::Matx33d& H1, const cv::Vec3d& e2,
                                            const std::vector<cv::Point2d>& from,
                                            const std::vector<cv::Point2d>& to,
                                            const std::vector<double>& scale_px,
                                            const std::vector<double>& residual_px, int rounds) {
  const size_t n = from.size();
  if (to.size() != n || scale_px.size() != n || residual_px.size() != n) return std::nullopt;
  auto weight = [](double r, double s) {
    const double u = r / (2.0 * s);
    return std::isfinite(u) && s > 0.0 ? 1.0 / ((1.0 + u * u) * s * s) : 0.0;
  };
  std::vector<double> w(n);
  for (size_t i = 0; i < n; ++i) w[i] = weight(residual_px[i], scale_px[i]);
  std::optional<cv::Matx33d> H;
  for (int round = 0; round < std::max(1, rounds); ++round) {
    H = fitInducedHomography(H1, e2, from, to, w);
    if (!H) return std::nullopt;
    for (size_t i = 0; i < n; ++i) w[i] = weight(transferError(*H, from[i], to[i]), scale_px[i]);
  }
  return H;
}

namespace {

std::vector<cv::Point2d> pick(const std::vector<cv::Point2d>& p, const std::vector<int>& idx) {
  std::vector<cv::Point2d> out;
  out.reserve(idx.size());
  for (int i : idx) out.push_back(p[i]);
  return out;
}

}  // namespace

int mergeInducedPieces(std::vector<HomographyPlane>& planes, const cv::Matx33d& H1,
                       const cv::Vec3d& e2, const std::vector<cv::Point2d>& view1,
                       const std::vector<cv::Point2d>& view2, const PlaneCriterion& criterion) {
  int merges = 0;
  while (planes.size() >= 2) {
    const size_t count = planes.size();
    // Each plane's induced fit at its own scale, its points' costs under it, and whether
    // it pays for itself.
    std::vector<HomographyPlane> induced(planes);
    std::vector<std::vector<double>> own(count);
    std::vector<char> pays(count, 0);
    for (size_t k = 0; k < count; ++k) {
      const std::vector<int>& idx = planes[k].inliers;
      std::vector<double> r, s(idx.size(), planes[k].noise_px);
      for (int i : idx) r.push_back(transferError(planes[k].H, view1[i], view2[i]));
      const auto H = fitInducedRobust(H1, e2, pick(view1, idx), pick(view2, idx), s, r, 1);
      if (!H) continue;
      induced[k].H = *H;
      criterion.measure(induced[k], idx);
      own[k] = criterion.costs(induced[k], idx);
      double gain = -criterion.label_cost;
      for (double c : own[k]) gain += criterion.outlier_cost - c;
      pays[k] = gain > 0.0;
    }
    double best_gain = 0.0;
    size_t bi = 0, bj = 0;
    cv::Matx33d best_H;
    for (size_t i = 0; i < count; ++i) {
      for (size_t j = i + 1; j < count; ++j) {
        if (!pays[i] || !pays[j]) continue;
        // The two pieces' points; every point keeps its cheapest label either way (another
        // plane, or none).
        const size_t of[2] = {i, j};
        std::vector<int> both = planes[i].inliers;
        both.insert(both.end(), planes[j].inliers.begin(), planes[j].inliers.end());
        const size_t ni = planes[i].inliers.size();
        std::vector<double> others(both.size(), criterion.outlier_cost), scale, residual;
        for (size_t m = 0; m < count; ++m) {
          if (m == i || m == j) continue;
          const std::vector<double> c = criterion.costs(planes[m], both);
          for (size_t q = 0; q < both.size(); ++q) others[q] = std::min(others[q], c[q]);
        }
        double separate = criterion.label_cost;
        for (size_t q = 0; q < both.size(); ++q) {
          const size_t p = of[q < ni ? 0 : 1];
          separate += std::min(others[q], own[p][q < ni ? q : q - ni]);
          scale.push_back(induced[p].noise_px);
          residual.push_back(transferError(induced[p].H, view1[both[q]], view2[both[q]]));
        }
        const auto H =
            fitInducedRobust(H1, e2, pick(view1, both), pick(view2, both), scale, residual);
        if (!H) continue;
        // The union's homography, each piece's points at that piece's own scale.
        double together = 0.0;
        for (int k = 0; k < 2; ++k) {
          HomographyPlane piece = induced[of[k]];
          piece.H = *H;
          const std::vector<double> c = criterion.costs(piece, planes[of[k]].inliers);
          for (size_t q = 0; q < c.size(); ++q)
            together += std::min(others[k == 0 ? q : ni + q], c[q]);
        }
        if (separate - together > best_gain) {
          best_gain = separate - together;
          bi = i;
          bj = j;
          best_H = *H;
        }
      }
    }
    if (best_gain <= 0.0) break;
    HomographyPlane& merged = planes[bi];
    merged.H = best_H;
    merged.inliers.insert(merged.inliers.end(), planes[bj].inliers.begin(),
                          planes[bj].inliers.end());
    std::sort(merged.inliers.begin(), merged.inliers.end());
    criterion.measure(merged, merged.inliers);
    planes.erase(planes.begin() + static_cast<long>(bj));
    criterion.assign(planes);
    ++merges;
  }
  return merges;
}

}  // namespace mono_plane_detection
