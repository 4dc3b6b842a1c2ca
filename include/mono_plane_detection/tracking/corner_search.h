// The tracker's corner search (paper II-B: Shi-Tomasi, at most max_features corners at
// least min_distance_px apart) made cheap: it runs on a coarser level of the pyramid the
// tracker has already built for Lucas-Kanade, and each corner is then refined on the
// full-resolution image. A quarter of the pixels per level, so the image that searches
// costs little more than the others. ROS-free.
#pragma once

#include <utility>
#include <vector>
#include <opencv2/core.hpp>

namespace mono_plane_detection {

struct TrackerParams;  // feature_tracker.h

// The pyramid level to search on: the coarsest one at most 1 whose image is at least
// minimumImageSide per side and where min_distance_px is still >= 4 px (so the spacing
// rule keeps its meaning), capped by the levels that were built. 0 means full resolution.
int cornerSearchLevel(const cv::Size& image, int levels_built, const TrackerParams& params);

// Keeps, in order, the corners that are at least min_distance_px from every corner kept
// before them and from every point of `live`; at most `wanted`. Returns how many were
// dropped. (The spacing rule at full resolution, after refinement moved the corners.)
int keepApart(std::vector<cv::Point2f>& corners, const std::vector<cv::Point2f>& live,
              double min_distance_px, int wanted);

// The side of spreadOverCells' squares for an image: `columns` across its width, so the
// spread is the same at any resolution; 0 when columns is 0 (no spread).
double spreadCellPx(const cv::Size& image, int columns);

// Keeps at most `keep` of `corners` (strongest first), taking each next one from the
// cell of a grid of cell_px squares over `image` that holds the fewest points so far
// (live points and corners taken), the strongest there first: a weakly textured surface
// next to a richly textured one still gets corners (strongest-first alone spends every
// corner on the rich one). cell_px <= 0: the first `keep`, unchanged; cells are at least 8 px.
void spreadOverCells(std::vector<cv::Point2f>& corners, const std::vector<cv::Point2f>& live,
                     const cv::Size& image, double cell_px, size_t keep);

// Work buffers of noiseLevel (kept across searches).
struct NoiseLevelBuffers {
  cv::Mat response;
  std::vector<int> histograms, column_cell;
};

// The image's noise level, as the median |response| of Immerkaer's noise kernel (1996,
// "Fast noise variance estimation": the difference of two Laplacians, blind to planar
// shading, 6 sigma for white noise) in the flattest cell of a grid of cell_px squares
// (<= 0: the whole image), cells whose responses are mostly exactly 0 (clipped, or drawn
// without noise) left out; 0 when every cell is such. CV_8UC1.
double noiseLevel(const cv::Mat& image, double cell_px, NoiseLevelBuffers* buffers = nullptr);

// The Shi-Tomasi response (cornerMinEigenVal, block_size, Sobel 3) that the noise of
// `image` (noiseLevel over cell_px cells, at least half a grey level) does not exceed:
// the strongest response of white noise of that level over 512 x 512 pixels, shrunk
// `level` times by pyrDown as `image` was (0: image is full resolution).
double noiseCornerFloor(const cv::Mat& image, int level, int block_size, double cell_px,
                        NoiseLevelBuffers* buffers = nullptr);

// The cells of a grid over a searched image whose quality bar the per-cell rule lowered
// below the image's: their corners were taken relative to the cell's own strongest.
struct RelaxedCells {
  std::vector<uchar> relaxed;  // row-major, `cols` per row; empty: none
  int cols = 0;
  double cell_px = 0;  // on the searched image
  int level = 0;       // the searched image is this pyramid level
  // True when p (full-resolution pixels) lies in a relaxed cell.
  bool contains(const cv::Point2f& p) const;
};

// Work buffers of shiTomasiCandidates.
struct ShiTomasiBuffers {
  cv::Mat eig, dilated;
  std::vector<float> bar;
  std::vector<int> column_edge, row_edge;  // where each cell begins, and the image's end
  std::vector<std::pair<float, int>> candidates;
  std::vector<std::vector<cv::Point2f>> grid;
};

// goodFeaturesToTrack (minimum eigenvalue, Sobel 3) with a quality bar per cell of
// cell_px squares: a pixel is a corner when it is a 3 x 3 local maximum of the response,
// not masked, and above the lower of the image's bar (quality_level x the strongest
// unmasked response, the paper's) and its cell's own (quality_level x the cell's
// strongest, but at least noise_floor). noise_floor <= 0 or cell_px <= 0: the image's bar
// alone, as goodFeaturesToTrack. Strongest first, each at least min_distance from those
// before, at most max_corners (0: all). `relaxed` gets the cells whose bar was lowered.
// `response`, when given and of the image's size (CV_32FC1), is the image's response
// computed beforehand: used (and thresholded in place) instead of computing it.
void shiTomasiCandidates(const cv::Mat& image, const cv::Mat& mask, double quality_level,
                         double noise_floor, double cell_px, double min_distance, int block_size,
                         size_t max_corners, ShiTomasiBuffers& buffers,
                         std::vector<cv::Point2f>& corners, std::vector<uchar>& relaxed,
                         cv::Mat* response = nullptr);

// Buffers kept across searches so that a search allocates nothing they can hold.
struct CornerSearchBuffers {
  ShiTomasiBuffers shi_tomasi;
  NoiseLevelBuffers noise;
  RelaxedCells relaxed;  // of the last search (the fill's when it ran)
  cv::Mat mask;
  std::vector<cv::Point2f> corners;
  std::vector<std::pair<double, cv::Point2f>> scored;
  std::vector<cv::Point2f> taken;
  int from_full_resolution = 0;  // of the last search's corners, found by the fill
};

// The first row of band b of a spread search over n bands of `rows` rows (band b holds
// the rows bandTop(b) <= y < bandTop(b + 1)): the tracker's cut.
inline int bandTop(int b, int rows, int n) { return b * rows / n; }

// Rows first_row <= y < end_row of `image`'s Shi-Tomasi response (cornerMinEigenVal,
// block_size, Sobel 3) into `response` (made the image's size, CV_32FC1; its other rows
// are left as they are), bit for bit those of the whole image's response: a spread search
// computes its search image's response a band of rows per image. `work`: a kept buffer.
void cornerResponseRows(const cv::Mat& image, int block_size, int first_row, int end_row,
                        cv::Mat& response, cv::Mat& work);

// Shi-Tomasi's corner score (the smaller eigenvalue of the gradient matrix summed over a
// block_size square) at the pixel nearest p, from x and y derivatives (CV_16SC2, as
// cv::buildOpticalFlowPyramid stores them next to each level); pixels outside are left out.
double shiTomasiScore(const cv::Mat& derivatives, const cv::Point2f& p, int block_size);

// Shi-Tomasi corners of `full`, found on `level_image` (level `level` of its pyramid, 0:
// full itself) and refined on `full` with cornerSubPix, strongest first, inside the
// image, spaced by params.min_distance_px from each other and (when `live` is not empty)
// from the live points, which also mask the search. At most `wanted`. On a coarse level,
// three times as many candidates are ranked again by shiTomasiScore on `derivatives`
// (full resolution's, CV_16SC2) when given, and the best refined. When the coarse level
// holds fewer than `wanted`, full resolution gives the rest. `response`, when given, is
// level_image's Shi-Tomasi response computed beforehand (cornerResponseRows; it is
// thresholded in place), used instead of computing it (not by the full-resolution rest
// of a coarse search, which computes its own). With
// params.corner_noise_margin > 0 and a spread grid, each cell of the grid also has its own
// bar (shiTomasiCandidates), above the noise floor times that margin.
const std::vector<cv::Point2f>& findCorners(const cv::Mat& full, const cv::Mat& level_image,
                                            int level, const std::vector<cv::Point2f>& live,
                                            int wanted, const TrackerParams& params,
                                            CornerSearchBuffers& buffers,
                                            const cv::Mat* derivatives = nullptr,
                                            cv::Mat* response = nullptr);

}  // namespace mono_plane_detection
