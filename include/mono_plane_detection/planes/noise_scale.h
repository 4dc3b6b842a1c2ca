// The noise scale of one image pair, estimated from the data, so that every threshold of
// the plane core is a number of noise scales and one default serves tracked points
// (about 0.2 px), photographs (1-3 px) and SIFT matches alike.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

namespace mono_plane_detection {

// sigma: the noise scale per image coordinate of a transfer residual, pixels (a true
// inlier's transfer error is about Rayleigh(sigma)); inliers: how many residuals the
// estimate rests on (0 when nothing could be estimated).
struct NoiseScale {
  double sigma_px = 0.0;
  int inliers = 0;
  // 90th over 50th percentile of the residuals under the scale's cut: 1.82 for Rayleigh
  // (Gaussian noise), 2.5-4 for the heavy tails of real matches (AdelaideRMF); 0 unknown.
  double tail_ratio = 0.0;
};

// MSSE (Bab-Hadiashar and Suter 1999) on transfer residuals of one model: residuals in
// ascending order join the inlier set while the next one is within stop_sigmas of the
// scale of those already in (sigma^2 = sum r^2 / (2k - model_dof)), from min_inliers on.
// Outliers never enter (a gap stops the growth); a heavy tail of the inliers enters as far
// as it is continuous with them. Non-finite residuals are ignored; fewer finite residuals
// than min_inliers gives {0, 0}.
NoiseScale msseScale(std::vector<double> residuals, int min_inliers, int model_dof = 8,
                     double stop_sigmas = 3.0);

// Fixed point of sigma = median of the residuals below cut_sigmas * sigma over the
// median of a Rayleigh(sigma) truncated there, from sigma0: the median ignores how long
// a heavy tail is, the wide cut lets the tail in. inliers: residuals under the final
// cut. {0, 0} when sigma0 or cut_sigmas is not positive or no residual is under the cut.
NoiseScale medianScale(const std::vector<double>& residuals, double sigma0, double cut_sigmas,
                       int iterations = 30);
// medianScale on squared residuals (the same order statistics without a square root per
// residual: each plane's scale is measured several times per image pair).
NoiseScale medianScaleSquared(const std::vector<double>& squared_residuals, double sigma0,
                              double cut_sigmas, int iterations = 30);

// Sorts non-negative doubles (squared residuals; +inf allowed, -0 and negatives not)
// ascending: a counting sort on their bit patterns' exponent and 6 leading mantissa bits
// (64 buckets per octave; such
// doubles order as their bits do), then insertion within those buckets. The same result
// as std::sort with few mispredicted branches: the order statistics of the noise scale's
// estimates were a sixth of the plane core, most of it std::sort's and nth_element's
// branches.
void sortNonNegative(std::vector<double>& values);
// The k-th smallest (0-based; +inf when k >= size) of such doubles, by the same
// buckets: the bucket holding it found by counting, only that bucket selected in. The
// same value as std::nth_element; the order of `values` is left unspecified.
double kthNonNegative(std::vector<double>& values, size_t k);

// The noise scale of an image pair from candidate homographies (view 1 -> view 2): each
// candidate's residuals get msseScale, refitted on its inlier set while that improves the
// score; the candidate with the most inliers per squared scale (after ASSC's score; the
// best first plane) is kept; medianScale on its residuals gives the scale. The result
// is clamped to [min_sigma_px, max_sigma_px]; {0, 0} when no candidate gives an estimate.
struct NoiseScaleParams {
  int min_inliers = 8;         // a scale rests on at least this many points
  double stop_sigmas = 3.0;    // MSSE's stop: the next residual beyond this many scales
  double tail_sigmas = 5.0;    // medianScale's cut: heavy tails reach this far
  double min_sigma_px = 0.05;  // tracks can agree better than the pixel grid, not better than this
  double max_sigma_px = 20.0;  // beyond this no plane is usable anyway
};
NoiseScale estimateNoiseScale(const std::vector<cv::Matx33d>& candidates,
                              const std::vector<cv::Point2d>& view1,
                              const std::vector<cv::Point2d>& view2,
                              const NoiseScaleParams& params = NoiseScaleParams());

// Transfer residuals of every correspondence under H (infinity where H sends a point to
// infinity).
std::vector<double> transferResiduals(const cv::Matx33d& H, const std::vector<cv::Point2d>& view1,
                                      const std::vector<cv::Point2d>& view2);

}  // namespace mono_plane_detection
