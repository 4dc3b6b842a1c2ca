#include "mono_plane_detection/tracking/corner_search.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <opencv2/imgproc.hpp>

#include "mono_plane_detection/tracking/feature_tracker.h"

namespace mono_plane_detection {
namespace {

// Sub-pixel refinement of new corners (the same criteria as the tracker's re-anchoring).
const cv::TermCriteria kSubPixCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.01);
const int kMaxSearchLevel = 1;
const double kMinSpacingOnLevel = 4.0;

}  // namespace

int cornerSearchLevel(const cv::Size& image, int levels_built, const TrackerParams& params) {
  const int side = minimumImageSide(params);
  int level = 0;
  while (level < std::min(kMaxSearchLevel, levels_built)) {
    const int next = level + 1;
    const bool big_enough = (image.width >> next) >= side && (image.height >> next) >= side;
    if (!big_enough || params.min_distance_px / (1 << next) < kMinSpacingOnLevel) break;
    level = next;
  }
  return level;
}

int keepApart(std::vector<cv::Point2f>& corners, const std::vector<cv::Point2f>& live,
              double min_distance_px, int wanted) {
  const double min2 = min_distance_px * min_distance_px;
  const size_t before = corners.size();
  size_t kept = 0;
  for (size_t c = 0; c < corners.size() && static_cast<int>(kept) < wanted; ++c) {
    auto far = [&](const cv::Point2f& p) {
      const cv::Point2f d = corners[c] - p;
      return static_cast<double>(d.x) * d.x + static_cast<double>(d.y) * d.y >= min2;
    };
    if (!std::all_of(corners.begin(), corners.begin() + kept, far)) continue;
    if (!std::all_of(live.begin(), live.end(), far)) continue;
    corners[kept++] = corners[c];
  }
  corners.resize(kept);
  return static_cast<int>(before - kept);
}

namespace {

// No new corner within min_distance (on this level) of a live point: a mask of the level's
// size drawn into `buffer` (kept across searches); empty when there is no live point.
cv::Mat liveMask(const cv::Size& size, const std::vector<cv::Point2f>& live, float scale,
                 double min_distance, cv::Mat& buffer) {
  if (live.empty()) return cv::Mat();
  buffer.create(size, CV_8UC1);
  buffer.setTo(cv::Scalar(255));
  const int radius = static_cast<int>(std::ceil(min_distance));
  for (const auto& p : live) cv::circle(buffer, p / scale, radius, cv::Scalar(0), cv::FILLED);
  return buffer;
}

// The grouped median of |r| for integer values held in `histogram` (bin v: |r| == v),
// interpolated within its bin, so that a low noise level is not rounded to a grey level.
double groupedMedian(const int* histogram, int bins, int total) {
  const double half = 0.5 * total;
  int below = 0;
  for (int v = 0; v < bins; ++v) {
    if (below + histogram[v] >= half && histogram[v] > 0)
      return v - 0.5 + (half - below) / histogram[v];
    below += histogram[v];
  }
  return bins;
}

// The strongest Shi-Tomasi response (cornerMinEigenVal, block_size, Sobel 3) of white
// noise shrunk `level` times by pyrDown, per squared unit of noiseLevel: the same
// estimator on the same processing, so that the ratio holds for any noise level. Measured
// once per (level, block size) on a fixed 512 x 512 noise image (a 640 x 480 image's
// pixels at full resolution).
double noiseResponsePerLevel2(int level, int block_size) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, double> measured;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_pair(level, block_size);
  const auto it = measured.find(key);
  if (it != measured.end()) return it->second;
  cv::Mat noise(512, 512, CV_8UC1);
  cv::RNG rng(12345);
  rng.fill(noise, cv::RNG::NORMAL, 128, 8);  // 8 grey levels: quantization plays no part
  for (int l = 0; l < level; ++l) cv::pyrDown(noise, noise);
  cv::Mat eig;
  cv::cornerMinEigenVal(noise, eig, block_size, 3);
  double strongest = 0;
  cv::minMaxLoc(eig, nullptr, &strongest);
  const double level_of_noise = noiseLevel(noise, 0, nullptr);
  return measured[key] = strongest / (level_of_noise * level_of_noise);
}

}  // namespace

double noiseLevel(const cv::Mat& image, double cell_px, NoiseLevelBuffers* buffers) {
  CV_Assert(image.type() == CV_8UC1);
  if (image.empty()) return 0;
  NoiseLevelBuffers own;
  NoiseLevelBuffers& b = buffers != nullptr ? *buffers : own;
  static const cv::Matx33f kernel(1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::filter2D(image, b.response, CV_16S, kernel);
  if (cell_px <= 0) cell_px = std::max(image.cols, image.rows);
  const int cols = std::max(1, static_cast<int>(std::ceil(image.cols / cell_px)));
  const int rows = std::max(1, static_cast<int>(std::ceil(image.rows / cell_px)));
  // |r| above the cap is texture, not noise (a median under it is exact: noise of up to
  // 60 grey levels).
  const int bins = 257;
  b.histograms.assign(static_cast<size_t>(cols) * rows * bins, 0);
  b.column_cell.resize(image.cols);
  for (int x = 0; x < image.cols; ++x)
    b.column_cell[x] = std::min(cols - 1, static_cast<int>(x / cell_px)) * bins;
  for (int y = 0; y < image.rows; ++y) {
    const short* row = b.response.ptr<short>(y);
    int* cell_row =
        b.histograms.data() + std::min(rows - 1, static_cast<int>(y / cell_px)) * cols * bins;
    for (int x = 0; x < image.cols; ++x)
      ++cell_row[b.column_cell[x] + std::min(bins - 1, std::abs(static_cast<int>(row[x])))];
  }
  // The flattest cell shows the noise alone (its median ignores a few edges or corners);
  // cells where most responses are exactly 0 hold no noise to measure (clipped, or drawn
  // without noise) and are left out.
  double lowest = -1;
  for (int c = 0; c < cols * rows; ++c) {
    const int* h = b.histograms.data() + c * bins;
    int total = 0;
    for (int v = 0; v < bins; ++v) total += h[v];
    if (total == 0 || 2 * h[0] >= total) continue;
    const double median = groupedMedian(h, bins, total);
    if (lowest < 0 || median < lowest) lowest = median;
  }
  return std::max(0.0, lowest);
}

double noiseCornerFloor(const cv::Mat& image, int level, int block_size, double cell_px,
                        NoiseLevelBuffers* buffers) {
  // At least the response of half a grey level (below it the image holds no noise to
  // measure: the floor of 8-bit quantization).
  const double noise = std::max(0.5, noiseLevel(image, cell_px, buffers));
  return noiseResponsePerLevel2(level, block_size) * noise * noise;
}

void cornerResponseRows(const cv::Mat& image, int block_size, int first_row, int end_row,
                        cv::Mat& response, cv::Mat& work) {
  response.create(image.size(), CV_32FC1);
  first_row = std::max(0, first_row);
  end_row = std::min(image.rows, end_row);
  if (end_row <= first_row) return;
  // Sobel 3 reads a row each way, the block sum block_size / 2 more: with the rows
  // beyond them the band's edge rows are those of the whole image, bit for bit.
  const int margin = block_size / 2 + 2;
  const int a = std::max(0, first_row - margin), z = std::min(image.rows, end_row + margin);
  // (A kept buffer of the largest band's size so far: bands differ by a row or two.)
  if (work.rows < z - a || work.cols != image.cols || work.type() != CV_32FC1)
    work.create(z - a, image.cols, CV_32FC1);
  cv::Mat rows = work.rowRange(0, z - a);
  cv::cornerMinEigenVal(image.rowRange(a, z), rows, block_size, 3);
  rows.rowRange(first_row - a, end_row - a).copyTo(response.rowRange(first_row, end_row));
}

void shiTomasiCandidates(const cv::Mat& image, const cv::Mat& mask, double quality_level,
                         double noise_floor, double cell_px, double min_distance, int block_size,
                         size_t max_corners, ShiTomasiBuffers& buffers,
                         std::vector<cv::Point2f>& corners, std::vector<uchar>& relaxed_cells,
                         cv::Mat* response) {
  corners.clear();
  relaxed_cells.clear();
  if (image.empty()) return;
  const bool given = response != nullptr && response->size() == image.size() &&
                     response->type() == CV_32FC1;
  cv::Mat& eig = given ? *response : buffers.eig;
  if (!given) cv::cornerMinEigenVal(image, eig, block_size, 3);
  double strongest = 0;
  cv::minMaxLoc(eig, nullptr, &strongest, nullptr, nullptr, mask);
  const float global_bar = static_cast<float>(quality_level * strongest);
  // Per cell: the bar is the lower of the image's and the cell's own (quality_level of its
  // strongest response, masked or not, so that it does not change with the live points),
  // never under the noise floor. No floor: the image's bar alone (the paper).
  const bool per_cell = noise_floor > 0 && cell_px > 0;
  const int cols = per_cell ? std::max(1, static_cast<int>(std::ceil(image.cols / cell_px))) : 1;
  const int rows = per_cell ? std::max(1, static_cast<int>(std::ceil(image.rows / cell_px))) : 1;
  std::vector<float>& bar = buffers.bar;
  bar.assign(static_cast<size_t>(cols * rows), 0.f);
  // Cell c holds the columns x with min(cols - 1, x / cell_px) == c (rows alike): whole
  // cells are rectangles, for OpenCV's vectorised minMaxLoc and threshold.
  auto edges = [&](int length, int cells, std::vector<int>& edge) {
    edge.assign(static_cast<size_t>(cells) + 1, length);
    edge[0] = 0;
    for (int x = 0, c = 0; x < length && per_cell; ++x)
      for (const int at = std::min(cells - 1, static_cast<int>(x / cell_px)); c < at;)
        edge[++c] = x;
  };
  edges(image.cols, cols, buffers.column_edge);
  edges(image.rows, rows, buffers.row_edge);
  const std::vector<int>& column_edge = buffers.column_edge;
  const std::vector<int>& row_edge = buffers.row_edge;
  auto cellOf = [&](int r, int c) {
    return cv::Rect(column_edge[c], row_edge[r], column_edge[c + 1] - column_edge[c],
                    row_edge[r + 1] - row_edge[r]);
  };
  if (per_cell) {
    relaxed_cells.resize(bar.size());
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const size_t k = static_cast<size_t>(r * cols + c);
        double strongest_here = 0;
        const cv::Rect cell = cellOf(r, c);
        if (cell.area() > 0) cv::minMaxLoc(eig(cell), nullptr, &strongest_here);
        const float own = std::max(
            static_cast<float>(noise_floor),
            static_cast<float>(quality_level) * std::max(0.f, static_cast<float>(strongest_here)));
        bar[k] = std::min(global_bar, own);
        relaxed_cells[k] = bar[k] < global_bar;
      }
  } else {
    bar[0] = global_bar;
  }
  // As goodFeaturesToTrack: responses at or under the bar are 0 (a NaN too, which a
  // response of an 8-bit image never holds), then the local maxima of a 3 x 3 dilation,
  // strongest first, each at least min_distance from those before.
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const cv::Rect cell = cellOf(r, c);
      if (cell.area() == 0) continue;
      cv::Mat part = eig(cell);
      cv::threshold(part, part, bar[static_cast<size_t>(r * cols + c)], 0, cv::THRESH_TOZERO);
    }
  cv::dilate(eig, buffers.dilated, cv::Mat());
  auto& candidates = buffers.candidates;
  candidates.clear();
  for (int y = 1; y < image.rows - 1; ++y) {
    const float* e = eig.ptr<float>(y);
    const float* d = buffers.dilated.ptr<float>(y);
    const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    for (int x = 1; x < image.cols - 1; ++x)
      if (e[x] != 0.f && e[x] == d[x] && (m == nullptr || m[x] != 0))
        candidates.push_back({e[x], y * image.cols + x});
  }
  // goodFeaturesToTrack's order: strongest first, equal responses the later pixel first
  // (its greaterThanPtr compares addresses; equal responses are common in flat or
  // noise-free regions).
  std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
    return a.first > b.first || (a.first == b.first && a.second > b.second);
  });
  // Spacing on a grid of min_distance cells: only the 3 x 3 cells around a corner can
  // hold one closer than min_distance.
  const double spacing = std::max(1.0, min_distance);
  const int grid_cols = static_cast<int>(std::ceil(image.cols / spacing)) + 1;
  const int grid_rows = static_cast<int>(std::ceil(image.rows / spacing)) + 1;
  auto& grid = buffers.grid;
  grid.resize(static_cast<size_t>(grid_cols * grid_rows));  // (kept capacity: no allocation)
  for (auto& g : grid) g.clear();
  const double min2 = min_distance * min_distance;
  for (const auto& candidate : candidates) {
    if (max_corners > 0 && corners.size() >= max_corners) break;
    const cv::Point2f p(static_cast<float>(candidate.second % image.cols),
                        static_cast<float>(candidate.second / image.cols));
    const int gx = static_cast<int>(p.x / spacing), gy = static_cast<int>(p.y / spacing);
    bool apart = true;
    for (int yy = std::max(0, gy - 1); apart && yy <= std::min(grid_rows - 1, gy + 1); ++yy)
      for (int xx = std::max(0, gx - 1); apart && xx <= std::min(grid_cols - 1, gx + 1); ++xx)
        for (const cv::Point2f& q : grid[yy * grid_cols + xx]) {
          const cv::Point2f d = q - p;
          if (static_cast<double>(d.x) * d.x + static_cast<double>(d.y) * d.y < min2) {
            apart = false;
            break;
          }
        }
    if (!apart) continue;
    grid[gy * grid_cols + gx].push_back(p);
    corners.push_back(p);
  }
}

bool RelaxedCells::contains(const cv::Point2f& p) const {
  if (relaxed.empty() || cols <= 0 || cell_px <= 0) return false;
  const float scale = static_cast<float>(1 << level);
  const int cx = static_cast<int>(p.x / scale / cell_px);
  const int cy = static_cast<int>(p.y / scale / cell_px);
  const int rows = static_cast<int>(relaxed.size()) / cols;
  if (cx < 0 || cy < 0) return false;
  return relaxed[std::min(rows - 1, cy) * cols + std::min(cols - 1, cx)] != 0;
}

double spreadCellPx(const cv::Size& image, int columns) {
  if (columns <= 0 || image.empty()) return 0;
  return static_cast<double>(image.width) / columns;
}

void spreadOverCells(std::vector<cv::Point2f>& corners, const std::vector<cv::Point2f>& live,
                     const cv::Size& image, double cell_px, size_t keep) {
  if (cell_px <= 0 || image.empty()) {
    if (corners.size() > keep) corners.resize(keep);
    return;
  }
  // Cells under 8 px hold no two corners at any useful spacing (and would be millions).
  cell_px = std::max(cell_px, 8.0);
  const int cols = std::max(1, static_cast<int>(std::ceil(image.width / cell_px)));
  const int rows = std::max(1, static_cast<int>(std::ceil(image.height / cell_px)));
  auto cell = [&](const cv::Point2f& p) {
    const int cx = std::min(cols - 1, std::max(0, static_cast<int>(p.x / cell_px)));
    const int cy = std::min(rows - 1, std::max(0, static_cast<int>(p.y / cell_px)));
    return cy * cols + cx;
  };
  const size_t cells = static_cast<size_t>(cols * rows);
  std::vector<int> count(cells, 0);
  for (const auto& p : live) ++count[cell(p)];
  // The corners' indices grouped by cell (a counting sort keeps each cell's strongest
  // first): cell c holds order[first[c] .. first[c + 1]). A few allocations per search.
  std::vector<int> cell_of(corners.size());
  std::vector<size_t> first(cells + 1, 0), order(corners.size());
  for (size_t i = 0; i < corners.size(); ++i) ++first[(cell_of[i] = cell(corners[i])) + 1];
  for (size_t c = 0; c < cells; ++c) first[c + 1] += first[c];
  std::vector<size_t> next(first.begin(), first.end() - 1);
  for (size_t i = 0; i < corners.size(); ++i) order[next[cell_of[i]]++] = i;
  next.assign(first.begin(), first.end() - 1);
  std::vector<cv::Point2f> out;
  out.reserve(std::min(keep, corners.size()));
  while (out.size() < keep) {
    int best = -1;
    for (size_t c = 0; c < cells; ++c) {
      if (next[c] >= first[c + 1]) continue;
      // Fewest points first; among equals the cell whose next corner is the stronger.
      if (best < 0 || count[c] < count[best] ||
          (count[c] == count[best] && order[next[c]] < order[next[best]]))
        best = static_cast<int>(c);
    }
    if (best < 0) break;
    out.push_back(corners[order[next[best]++]]);
    ++count[best];
  }
  corners = std::move(out);
}

const std::vector<cv::Point2f>& findCorners(const cv::Mat& full, const cv::Mat& level_image,
                                            int level, const std::vector<cv::Point2f>& live,
                                            int wanted, const TrackerParams& params,
                                            CornerSearchBuffers& buffers,
                                            const cv::Mat* derivatives, cv::Mat* response) {
  std::vector<cv::Point2f>& corners = buffers.corners;
  corners.clear();
  buffers.from_full_resolution = 0;
  buffers.relaxed.relaxed.clear();
  if (wanted <= 0) return corners;
  const float scale = static_cast<float>(1 << level);
  const double min_distance = params.min_distance_px / scale;
  const cv::Mat mask = liveMask(level_image.size(), live, scale, min_distance, buffers.mask);
  // On a coarse level, three times as many as wanted: they are ranked again at full
  // resolution. A coarse level ranks corners by their coarse structure, which changes
  // more from image to image than the full-resolution score; ranked by the latter, the
  // search finds the same corners again (paper II-D keeps ids by finding them again).
  const bool rank = level > 0 && derivatives != nullptr;
  const int ask = rank ? 3 * wanted + 8 : wanted;
  // Spread over cells: the candidates come from the whole image (every corner above the
  // quality bar, up to 4 x max_features), then `ask` of them spread over the cells.
  const double cell_px = spreadCellPx(full.size(), params.spread_grid_columns);
  const bool spread = cell_px > 0;
  const int pool = spread ? std::max(ask, 4 * params.max_features) : ask;
  // Per-cell bars (the grid's cells on this level) above the noise floor: then every
  // candidate goes to the spread, or the strong cells' corners would fill the pool.
  RelaxedCells& relaxed = buffers.relaxed;
  relaxed.cell_px = cell_px / scale;
  relaxed.level = level;
  const double noise_floor =
      spread && params.corner_noise_margin > 0
          ? params.corner_noise_margin * noiseCornerFloor(level_image, level, params.block_size,
                                                          relaxed.cell_px, &buffers.noise)
          : 0.0;
  shiTomasiCandidates(level_image, mask, params.quality_level, noise_floor, relaxed.cell_px,
                      min_distance, params.block_size,
                      noise_floor > 0 ? 0 : static_cast<size_t>(pool), buffers.shi_tomasi, corners,
                      relaxed.relaxed, response);
  relaxed.cols =
      relaxed.relaxed.empty() ? 0 : static_cast<int>(std::ceil(level_image.cols / relaxed.cell_px));
  if (corners.empty()) return corners;
  for (auto& c : corners) c *= scale;  // pyrDown keeps pixel 2i of level i-1 at i
  if (spread) spreadOverCells(corners, live, full.size(), cell_px, ask);
  // Score: the best of the pixel nearest the corner and its 8 neighbours (a corner found
  // by goodFeaturesToTrack is its neighbourhood's maximum).
  auto score = [&](const cv::Point2f& c, int block) {
    double best = 0;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        best = std::max(best, shiTomasiScore(*derivatives, c + cv::Point2f(dx, dy), block));
    return best;
  };
  auto rankBy = [&](int block, size_t keep) {
    auto& scored = buffers.scored;
    scored.clear();
    for (const auto& c : corners) scored.push_back({-score(c, block), c});
    std::stable_sort(scored.begin(), scored.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    corners.resize(std::min(corners.size(), keep));
    for (size_t i = 0; i < corners.size(); ++i) corners[i] = scored[i].second;
  };
  // First by a block that covers the coarse position's uncertainty (a coarse pixel each
  // way), to refine only the likely ones.
  // (With cells' own bars, spread again after ranking: the strongest alone would drop
  // the weak cells' corners.)
  if (rank) {
    const size_t likely = static_cast<size_t>(2 * wanted + 8);
    rankBy(params.block_size + 2 * (1 << level), noise_floor > 0 ? corners.size() : likely);
    if (noise_floor > 0) spreadOverCells(corners, live, full.size(), cell_px, likely);
  }
  // A coarse corner is within a coarse pixel of the true one: the 7x7 window reaches it.
  cv::cornerSubPix(full, corners, cv::Size(3, 3), cv::Size(-1, -1), kSubPixCriteria);
  // Refinement can push a border corner just outside the image.
  corners.erase(std::remove_if(corners.begin(), corners.end(),
                               [&](const cv::Point2f& c) {
                                 return !(c.x >= 0.f && c.y >= 0.f && c.x <= full.cols - 1.f &&
                                          c.y <= full.rows - 1.f);
                               }),
                corners.end());
  // Then by the score where the corner really is, as a full-resolution search would.
  if (rank) rankBy(params.block_size, corners.size());
  // goodFeaturesToTrack's quality_level is relative to the best corner it sees: at full
  // resolution under the mask of the live points, the best unmasked one (their corners,
  // the strongest, hidden: each search lowered the bar). The bar of a search is set by
  // the best corner found or live instead (a cell's own bar does not depend on it).
  // (Coarse searches keep their level's bar: with the full-resolution one the furnished
  // room's humanoid floor moved 0.019 -> 0.037 m, docs/benchmarks.md.)
  if (derivatives != nullptr && level == 0) {
    double best = 0;
    for (const auto& c : corners) best = std::max(best, score(c, params.block_size));
    for (const auto& c : live) best = std::max(best, score(c, params.block_size));
    corners.erase(std::remove_if(corners.begin(), corners.end(),
                                 [&](const cv::Point2f& c) {
                                   return !relaxed.contains(c) &&
                                          score(c, params.block_size) < params.quality_level * best;
                                 }),
                  corners.end());
  }
  // Ranked by score again above: spread again before the first `wanted` are kept.
  if (spread) spreadOverCells(corners, live, full.size(), cell_px, corners.size());
  keepApart(corners, live, params.min_distance_px, wanted);
  if (rank && static_cast<int>(corners.size()) < wanted) {
    // The coarse level holds fewer corners than wanted (fine texture fades there): the
    // rest comes from full resolution, away from the live points and the corners found.
    // goodFeaturesToTrack's quality_level is relative to the best corner it sees, and
    // the masks hide the best ones: the bar is set by the best found or live instead,
    // as a search of the whole image would.
    double best = 0;
    for (const auto& c : corners) best = std::max(best, score(c, params.block_size));
    for (const auto& c : live) best = std::max(best, score(c, params.block_size));
    std::vector<cv::Point2f>& taken = buffers.taken;
    taken = live;
    taken.insert(taken.end(), corners.begin(), corners.end());
    std::vector<cv::Point2f> found = std::move(corners);
    findCorners(full, full, 0, taken, wanted - static_cast<int>(found.size()), params, buffers);
    const size_t coarse = found.size();
    for (const auto& c : buffers.corners)
      if (buffers.relaxed.contains(c) || score(c, params.block_size) >= params.quality_level * best)
        found.push_back(c);
    corners = std::move(found);
    buffers.from_full_resolution = static_cast<int>(corners.size() - coarse);
  }
  return corners;
}

double shiTomasiScore(const cv::Mat& derivatives, const cv::Point2f& p, int block_size) {
  CV_Assert(derivatives.type() == CV_16SC2);
  const int half = std::max(0, block_size / 2);
  const int cx = cvRound(p.x), cy = cvRound(p.y);
  double a = 0, b = 0, c = 0;
  for (int y = cy - half; y <= cy + half; ++y) {
    if (y < 0 || y >= derivatives.rows) continue;
    const cv::Vec2s* row = derivatives.ptr<cv::Vec2s>(y);
    for (int x = cx - half; x <= cx + half; ++x) {
      if (x < 0 || x >= derivatives.cols) continue;
      const double dx = row[x][0], dy = row[x][1];
      a += dx * dx;
      b += dx * dy;
      c += dy * dy;
    }
  }
  // Smaller eigenvalue of [a b; b c].
  return 0.5 * (a + c) - std::sqrt(0.25 * (a - c) * (a - c) + b * b);
}

}  // namespace mono_plane_detection
