#include "mono_plane_detection/tracking/target_detector.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/tracking/marker_target.h"

namespace mono_plane_detection {
namespace {

using Quad = std::array<cv::Point2f, 4>;

// Orders a quadrilateral as the map frame's corners: the two opposite sides that are the
// target's width; of those, the lower one in the image (an upright camera) joins
// corners 0 and 1, left to right.
Quad orderCorners(const Quad& q, bool side0_is_width) {
  // Sides i -> i+1; pair (0, 2) or (1, 3) is the width (decided after rectification: in
  // an oblique view the image lengths can say otherwise).
  const int first = side0_is_width ? 0 : 1;
  const int other = first + 2;
  auto midY = [&](int i) { return (q[i].y + q[(i + 1) % 4].y) / 2; };
  const int bottom = midY(first) > midY(other) ? first : other;
  cv::Point2f b0 = q[bottom], b1 = q[(bottom + 1) % 4];
  cv::Point2f t0 = q[(bottom + 3) % 4], t1 = q[(bottom + 2) % 4];  // above b0, above b1
  if (b0.x > b1.x) {
    std::swap(b0, b1);
    std::swap(t0, t1);
  }
  return {b0, b1, t1, t0};
}

// Noise standard deviation of an image (Immerkaer 1996): the mean absolute response to
// a mask that cancels planes and ramps. Texture raises it a little: a conservative scale.
double noiseSigma(const cv::Mat& gray) {
  if (gray.cols < 3 || gray.rows < 3) return 1.0;
  const cv::Matx33f mask(1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(gray, response, CV_32F, mask);
  const cv::Rect inner(1, 1, gray.cols - 2, gray.rows - 2);
  const double sum = cv::norm(response(inner), cv::NORM_L1);
  const double sigma =
      std::sqrt(CV_PI / 2) * sum / (6.0 * static_cast<double>(inner.width) * inner.height);
  return std::max(sigma, 0.5);  // a rendered image without noise: quantisation
}

// Sub-pixel position, along the normal through p, where the profile crosses halfway
// between its dark and bright levels: the edge between the sheet and its surround. (Not
// the gradient maximum: a magnified, bilinearly sampled edge is a ramp whose gradient is
// flat across it.) Nothing when the step is under min_step.
std::optional<cv::Point2f> edgePoint(const cv::Mat& gray, const cv::Point2f& p,
                                     const cv::Point2f& normal, int reach, double min_step) {
  // The profile stops at the image border: a sheet close to it keeps its edge if a few
  // pixels of surround are in view.
  std::vector<float> profile;
  int first = -reach;
  for (int k = -reach; k <= reach; ++k) {
    const cv::Point2f q = p + static_cast<float>(k) * normal;
    if (q.x < 0 || q.y < 0 || q.x > gray.cols - 1 || q.y > gray.rows - 1) {
      if (k < -1) {
        first = k + 1;
        continue;
      }
      if (k <= 1) return std::nullopt;
      break;
    }
    cv::Mat v;
    cv::getRectSubPix(gray, {1, 1}, q, v, CV_32F);
    profile.push_back(v.at<float>(0, 0));
  }
  if (first > -2 || profile.size() < 5) return std::nullopt;
  reach = -first;
  const auto [lo, hi] = std::minmax_element(profile.begin(), profile.end());
  if (*hi - *lo < min_step) return std::nullopt;
  const float mid = (*lo + *hi) / 2;
  double best = std::numeric_limits<double>::max();
  for (int k = 0; k + 1 < static_cast<int>(profile.size()); ++k) {
    const float a = profile[k] - mid, b = profile[k + 1] - mid;
    if ((a < 0) == (b < 0) || a == b) continue;
    const double at = k - reach + a / (a - b);
    if (std::abs(at) < std::abs(best)) best = at;
  }
  if (best == std::numeric_limits<double>::max()) return std::nullopt;
  return p + static_cast<float>(best) * normal;
}

// Corners as intersections of lines fitted (cv::fitLine, Huber) to sub-pixel edge points
// along the middle 76 % of each side: the whole side rather than a window at the corner,
// which a curled or rounded paper corner would pull. Nothing when a side has too few
// edge points or a corner moves further than the search reached.
std::optional<Quad> refineByEdgeLines(const cv::Mat& gray, const Quad& c, int reach,
                                      double min_step) {
  std::array<cv::Vec4f, 4> lines;
  for (int i = 0; i < 4; ++i) {
    const cv::Point2f a = c[i], b = c[(i + 1) % 4];
    const double length = cv::norm(b - a);
    if (length < 8) return std::nullopt;
    const cv::Point2f along = (b - a) / static_cast<float>(length);
    const cv::Point2f normal(-along.y, along.x);
    std::vector<cv::Point2f> points;
    const int samples = std::min(400, static_cast<int>(length));
    for (int s = 0; s <= samples; ++s) {
      const double f = 0.12 + 0.76 * s / samples;
      if (auto e = edgePoint(gray, a + static_cast<float>(f * length) * along, normal, reach,
                             min_step))
        points.push_back(*e);
    }
    if (points.size() < std::max<size_t>(6, samples / 3)) return std::nullopt;
    cv::fitLine(points, lines[i], cv::DIST_HUBER, 0, 0.01, 0.01);
  }
  Quad out;
  for (int i = 0; i < 4; ++i) {
    const cv::Vec4f& l1 = lines[(i + 3) % 4];
    const cv::Vec4f& l2 = lines[i];
    const double det = l1[0] * l2[1] - l1[1] * l2[0];
    if (std::abs(det) < 1e-6) return std::nullopt;
    const double t = ((l2[2] - l1[2]) * l2[1] - (l2[3] - l1[3]) * l2[0]) / det;
    out[i] =
        cv::Point2f(static_cast<float>(l1[2] + t * l1[0]), static_cast<float>(l1[3] + t * l1[1]));
    if (cv::norm(out[i] - c[i]) > 2.0 * reach) return std::nullopt;
  }
  return out;
}

struct Candidate {
  Quad quad;  // in the working image, counter-clockwise on screen not assumed
  double area = 0;
};

// Convex quadrilaterals among the contours of a binary image.
// Also collects the straight stretches (longer than min_stretch px) of the outlines of
// regions larger than min_area, for addStretchQuads.
void addQuads(const cv::Mat& binary, double min_area, std::vector<Candidate>& out,
              std::vector<cv::Vec4f>& stretches, double min_stretch) {
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(binary, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
  for (const auto& contour : contours) {
    if (contour.size() < 4) continue;
    const double area = std::abs(cv::contourArea(contour));
    if (area < min_area) continue;
    std::vector<cv::Point> fine;
    cv::approxPolyDP(contour, fine, 1.5, true);
    for (size_t i = 0; i < fine.size(); ++i) {
      const cv::Point a = fine[i], b = fine[(i + 1) % fine.size()];
      if (cv::norm(b - a) >= min_stretch) stretches.emplace_back(a.x, a.y, b.x, b.y);
    }
    const double perimeter = cv::arcLength(contour, true);
    // A curled corner or a bump adds vertices at 2 %; 4 % still keeps a sheet's corners.
    for (const double eps : {0.02, 0.04}) {
      std::vector<cv::Point> poly;
      cv::approxPolyDP(contour, poly, eps * perimeter, true);
      if (poly.size() != 4 || !cv::isContourConvex(poly)) continue;
      Candidate c;
      for (int i = 0; i < 4; ++i) c.quad[i] = poly[i];
      c.area = std::abs(cv::contourArea(poly));
      // The same quadrilateral from another threshold: keep one.
      const double tolerance = std::max(3.0, 0.03 * std::sqrt(c.area));
      const bool duplicate = std::any_of(out.begin(), out.end(), [&](const Candidate& o) {
        for (int i = 0; i < 4; ++i) {
          double nearest = std::numeric_limits<double>::max();
          for (int j = 0; j < 4; ++j) nearest = std::min(nearest, cv::norm(c.quad[i] - o.quad[j]));
          if (nearest > tolerance) return false;
        }
        return true;
      });
      if (!duplicate) out.push_back(c);
      break;
    }
  }
}

// A straight stretch of outline: a line (unit direction, a point) and the parts of it
// that edges cover, as intervals of the position along it.
struct Stretch {
  cv::Point2f dir, point;
  std::vector<std::pair<float, float>> covered;
  double support = 0;  // covered length, px
};

double coverage(const Stretch& s, float from, float to) {
  if (to < from) std::swap(from, to);
  std::vector<std::pair<float, float>> parts;
  for (auto [a, b] : s.covered) {
    a = std::max(a, from);
    b = std::min(b, to);
    if (b > a) parts.emplace_back(a, b);
  }
  std::sort(parts.begin(), parts.end());
  double total = 0, end = from;
  for (const auto& [a, b] : parts) {
    const double start = std::max<double>(a, end);
    if (b > start) total += b - start;
    end = std::max<double>(end, b);
  }
  return total / std::max(1e-6f, to - from);
}

// Quadrilaterals bounded by four straight outline stretches: where light or shadow falls
// across the sheet and the surround (sunlight through a window), no threshold cuts the
// sheet out, but its four sides are still straight stretches of some threshold's
// outlines. Stretches are merged into lines (support: their summed length); four of the strongest lines, two roughly opposite pairs, whose sides are
// mostly covered by edges, make a candidate.
void addStretchQuads(const std::vector<cv::Vec4f>& segments, cv::Size image, double min_area,
                     std::vector<Candidate>& out) {
  // A sheet's side is not quite straight (paper bends): stretches within 1 % of the
  // image size and 4 deg are one side.
  const float near = std::max(3.0f, 0.01f * std::max(image.width, image.height));
  std::vector<Stretch> lines;
  for (const cv::Vec4f& v : segments) {
    const cv::Point2f a(v[0], v[1]), b(v[2], v[3]);
    const float length = static_cast<float>(cv::norm(b - a));
    if (length < 1) continue;
    const cv::Point2f dir = (b - a) / length;
    bool merged = false;
    for (Stretch& l : lines) {
      const cv::Point2f n(-l.dir.y, l.dir.x);
      if (std::abs(dir.dot(l.dir)) < std::cos(4 * CV_PI / 180)) continue;
      if (std::abs((a - l.point).dot(n)) > near || std::abs((b - l.point).dot(n)) > near) continue;
      l.covered.emplace_back(std::min((a - l.point).dot(l.dir), (b - l.point).dot(l.dir)),
                             std::max((a - l.point).dot(l.dir), (b - l.point).dot(l.dir)));
      l.support += length;
      merged = true;
      break;
    }
    if (!merged) lines.push_back({dir, a, {{0.f, length}}, length});
  }
  std::sort(lines.begin(), lines.end(),
            [](const Stretch& x, const Stretch& y) { return x.support > y.support; });
  if (lines.size() > 12) lines.resize(12);
  auto meet = [](const Stretch& p, const Stretch& q) -> std::optional<cv::Point2f> {
    const double det = p.dir.x * q.dir.y - p.dir.y * q.dir.x;
    if (std::abs(det) < 0.3) return std::nullopt;  // under ~17 deg apart
    const cv::Point2f d = q.point - p.point;
    const double t = (d.x * q.dir.y - d.y * q.dir.x) / det;
    return p.point + static_cast<float>(t) * p.dir;
  };
  const int n = static_cast<int>(lines.size());
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k)
        for (int m = k + 1; m < n; ++m) {
          const int idx[4] = {i, j, k, m};
          // The three ways to pair four lines as opposite sides.
          for (const auto& pairing : {std::array<int, 4>{0, 2, 1, 3}, std::array<int, 4>{0, 1, 2, 3},
                                      std::array<int, 4>{0, 1, 3, 2}}) {
            // Around the quadrilateral: side a, side c, side b, side d.
            const Stretch* side[4] = {&lines[idx[pairing[0]]], &lines[idx[pairing[2]]],
                                      &lines[idx[pairing[1]]], &lines[idx[pairing[3]]]};
            Quad q;
            bool ok = true;
            for (int s = 0; s < 4 && ok; ++s) {
              const auto corner = meet(*side[s], *side[(s + 1) % 4]);
              ok = corner && corner->x > -1 && corner->y > -1 && corner->x < image.width &&
                   corner->y < image.height;
              if (ok) q[s] = *corner;
            }
            if (!ok) continue;
            const std::vector<cv::Point2f> poly(q.begin(), q.end());
            if (!cv::isContourConvex(poly)) continue;
            const double area = std::abs(cv::contourArea(poly));
            if (area < min_area) continue;
            // Side s runs from corner s-1 to corner s along line s.
            for (int s = 0; s < 4 && ok; ++s) {
              const Stretch& l = *side[s];
              const cv::Point2f from = q[(s + 3) % 4], to = q[s];
              ok = coverage(l, (from - l.point).dot(l.dir), (to - l.point).dot(l.dir)) > 0.5;
            }
            if (!ok) continue;
            Candidate c;
            for (int s = 0; s < 4; ++s) c.quad[s] = q[s];
            c.area = area;
            out.push_back(c);
          }
        }
}

std::vector<Candidate> candidateQuads(const cv::Mat& gray, double sigma, double min_area) {
  std::vector<Candidate> out;
  std::vector<cv::Vec4f> stretches;
  const double min_stretch = std::max(12, std::min(gray.cols, gray.rows) / 16);
  cv::Mat smooth;
  cv::GaussianBlur(gray, smooth, {5, 5}, 1.0);
  cv::Mat binary;
  const double otsu = cv::threshold(smooth, binary, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
  addQuads(binary, min_area, out, stretches, min_stretch);
  // More global levels: Otsu's splits the image's two largest populations, which in a
  // real room need not be sheet and background (a bright wall, a dark floor).
  std::vector<double> hist(256, 0);
  for (int y = 0; y < smooth.rows; ++y)
    for (int x = 0; x < smooth.cols; ++x) ++hist[smooth.at<uint8_t>(y, x)];
  auto percentile = [&](double p) {
    double seen = 0;
    const double want = p * smooth.total();
    for (int v = 0; v < 256; ++v)
      if ((seen += hist[v]) >= want) return static_cast<double>(v);
    return 255.0;
  };
  const double lo = percentile(0.02), hi = percentile(0.995);
  for (const double f : {0.2, 0.35, 0.5, 0.65, 0.8}) {
    const double level = lo + f * (hi - lo);
    if (std::abs(level - otsu) < 6) continue;
    cv::threshold(smooth, binary, level, 255, cv::THRESH_BINARY);
    addQuads(binary, min_area, out, stretches, min_stretch);
  }
  // Adaptive: bright relative to the neighbourhood, for light that falls off across the
  // image. The block is large (a quarter of the image) so a sheet's inside stays whole.
  int block = std::max(15, std::min(gray.cols, gray.rows) / 4) | 1;
  cv::adaptiveThreshold(smooth, binary, 255, cv::ADAPTIVE_THRESH_MEAN_C, cv::THRESH_BINARY, block,
                        -std::max(4.0, 3 * sigma));
  addQuads(binary, min_area, out, stretches, min_stretch);
  // Outlines: edges closed into curves, whatever the levels on both sides.
  cv::Mat edges;
  cv::Canny(smooth, edges, std::max(10.0, 3 * sigma), std::max(30.0, 9 * sigma));
  cv::dilate(edges, edges, cv::Mat());
  addQuads(edges, min_area, out, stretches, min_stretch);
  addStretchQuads(stretches, gray.size(), min_area, out);
  return out;
}

struct SideCheck {
  TargetRejection rejection = TargetRejection::kNone;
  std::string reason;
  double inside = 0, outside = 0;  // mean grey levels over all sides
  double ratio = 0;                 // surround over sheet, median along the outline
};

// Brightness just inside and just outside each side, sampled along the normals: every
// side must step down to the surround by min_edge_snr noise sigmas on most of its
// length (a stripe on a pole or a shadow's edge has sides that do not), and the surround
// must be dark compared to the sheet.
SideCheck checkSides(const cv::Mat& gray, const Quad& q, double area, double sigma,
                     const TargetParams& params) {
  SideCheck out;
  cv::Point2f centre(0, 0);
  for (const auto& p : q) centre += p * 0.25f;
  const int depth = std::max(3, static_cast<int>(0.06 * std::sqrt(area)));
  double sum_in = 0, sum_out = 0;
  int n_in = 0, n_out = 0;
  std::vector<double> ratios;
  for (int i = 0; i < 4; ++i) {
    const cv::Point2f a = q[i], b = q[(i + 1) % 4];
    const double length = cv::norm(b - a);
    const cv::Point2f along = (b - a) / static_cast<float>(length);
    cv::Point2f normal(-along.y, along.x);
    if (normal.dot((a + b) * 0.5f - centre) < 0) normal = -normal;  // outwards
    const int samples = std::clamp(static_cast<int>(length / 2), 8, 60);
    std::vector<double> steps;
    double side_in = 0, side_out = 0;
    int usable = 0;
    for (int s = 0; s < samples; ++s) {
      const cv::Point2f p = a + static_cast<float>((0.1 + 0.8 * (s + 0.5) / samples) * length) * along;
      double in = 0, out_v = 0;
      int ni = 0, no = 0;
      for (int d = 2; d <= depth; ++d) {
        const cv::Point pi = p - static_cast<float>(d) * normal, po = p + static_cast<float>(d) * normal;
        if (pi.x >= 0 && pi.y >= 0 && pi.x < gray.cols && pi.y < gray.rows) {
          in += gray.at<uint8_t>(pi);
          ++ni;
        }
        if (po.x >= 0 && po.y >= 0 && po.x < gray.cols && po.y < gray.rows) {
          out_v += gray.at<uint8_t>(po);
          ++no;
        }
      }
      if (ni == 0 || no == 0) continue;
      ++usable;
      in /= ni;
      out_v /= no;
      steps.push_back(in - out_v);
      ratios.push_back(out_v / std::max(1.0, in));
      side_in += in;
      side_out += out_v;
    }
    if (usable < samples / 2) {
      out.rejection = TargetRejection::kAtImageEdge;
      out.reason = "a side runs along the image border (no surround to see)";
      return out;
    }
    side_in /= usable;
    side_out /= usable;
    const double step = side_in - side_out;
    const double snr = step / sigma;
    // Most of the side, not its mean: a side half along a dark stripe and half along a
    // bright wall has a fair mean and no edge.
    const double each = std::max(3 * sigma, 0.3 * step);
    const double share = static_cast<double>(std::count_if(
                             steps.begin(), steps.end(), [&](double v) { return v > each; })) /
                         steps.size();
    if (snr < params.min_edge_snr || share < 0.8) {
      std::ostringstream why;
      why.precision(2);
      why << "side " << i << " has a step of " << std::fixed << snr
          << " noise sigmas (needs " << params.min_edge_snr << ") on " << share * 100
          << " % of its length (needs 80 %)";
      out.rejection = TargetRejection::kWeakEdge;
      out.reason = why.str();
      return out;
    }
    sum_in += side_in * usable;
    sum_out += side_out * usable;
    n_in += usable;
    n_out += usable;
  }
  out.inside = sum_in / n_in;
  out.outside = sum_out / n_out;
  // The median along the outline: sunlight or a shadow over part of the surround
  // moves the mean, not the median.
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  const double ratio = ratios[ratios.size() / 2];
  out.ratio = ratio;
  if (ratio > params.max_surround_ratio) {
    std::ostringstream why;
    why.precision(2);
    why << "surround/sheet brightness " << std::fixed << ratio << " > "
        << params.max_surround_ratio << " (background too light or sheet in shadow)";
    out.rejection = TargetRejection::kBrightSurround;
    out.reason = why.str();
  }
  return out;
}

// A sheet's side ends at its corners: past them, both sides of the side's line are the
// surround. A stripe of a striped pole, a box's face, a desk top are bright
// quadrilaterals with a step all round too, but their sides go on as the edges of the
// larger thing they belong to. Past each corner, over a quarter of the side's length
// (clear of the corner and of the next side's surround), the step across the side's
// line (median) must stay under a quarter of the step across the side itself, and
// within the noise: 3 sigmas. Measured on the development photos: sheets 0.00-0.05 of
// their side's step, the TUM office impostors 0.3-2.6. Ends out of the image are not
// judged (a sheet that fills the view has none to show). Returns the corner past which
// an edge goes on (-1: none) and that continuation's step over its side's.
std::pair<int, double> continuingSide(const cv::Mat& gray, const Quad& q, double sigma) {
  cv::Point2f centre(0, 0);
  for (const auto& p : q) centre += p * 0.25f;
  const double area = std::abs(cv::contourArea(std::vector<cv::Point2f>(q.begin(), q.end())));
  const int depth = std::max(3, static_cast<int>(0.06 * std::sqrt(area)));
  // Mean over the band 2..depth px from p along n; nothing when it leaves the image.
  auto bandMean = [&](const cv::Point2f& p, const cv::Point2f& n) -> std::optional<double> {
    double sum = 0;
    for (int d = 2; d <= depth; ++d) {
      const cv::Point x = p + static_cast<float>(d) * n;
      if (x.x < 0 || x.y < 0 || x.x >= gray.cols || x.y >= gray.rows) return std::nullopt;
      sum += gray.at<uint8_t>(x);
    }
    return sum / (depth - 1);
  };
  std::pair<int, double> worst{-1, 0};
  for (int i = 0; i < 4; ++i) {
    const cv::Point2f a = q[i], b = q[(i + 1) % 4];
    const float length = static_cast<float>(cv::norm(b - a));
    const cv::Point2f along = (b - a) / length;
    cv::Point2f normal(-along.y, along.x);
    if (normal.dot((a + b) * 0.5f - centre) < 0) normal = -normal;  // outwards
    const int samples = 20;
    auto stepAt = [&](const cv::Point2f& p) -> std::optional<double> {
      const auto in = bandMean(p, -normal), out = bandMean(p, normal);
      if (!in || !out) return std::nullopt;
      return *in - *out;
    };
    std::vector<double> side;
    for (int s = 0; s < samples; ++s)
      if (auto v =
              stepAt(a + static_cast<float>((0.1 + 0.8 * (s + 0.5) / samples) * length) * along))
        side.push_back(*v);
    if (side.size() < samples / 2) continue;
    const double step = median(side);
    if (step <= 0) continue;
    for (const int end : {0, 1}) {
      const cv::Point2f corner = end ? b : a, away = end ? along : -along;
      std::vector<double> past;
      for (int s = 0; s < samples; ++s) {
        const double t = 2 * depth + (0.1 + 0.25 * (s + 0.5) / samples) * length;
        if (auto v = stepAt(corner + static_cast<float>(t) * away)) past.push_back(*v);
      }
      if (past.size() < samples / 2) continue;
      const double continued = std::abs(median(past));
      if (continued > std::max(0.25 * step, 3 * sigma) && continued / step > worst.second)
        worst = {end ? (i + 1) % 4 : i, continued / step};
    }
  }
  return worst;
}

// Stage reached, to keep the reason of the candidate that came closest.
int stageOf(TargetRejection r) {
  switch (r) {
    case TargetRejection::kTooSmall: return 1;
    case TargetRejection::kAtImageEdge: return 2;
    case TargetRejection::kWeakEdge: return 3;
    case TargetRejection::kBrightSurround: return 4;
    case TargetRejection::kEdgeContinues: return 5;
    case TargetRejection::kAspect: return 6;
    case TargetRejection::kShapeUncertain: return 7;
    default: return 0;
  }
}

}  // namespace

const char* toString(TargetRejection r) {
  switch (r) {
    case TargetRejection::kNone: return "found";
    case TargetRejection::kBadImage: return "bad image";
    case TargetRejection::kNoCandidate: return "no quadrilateral";
    case TargetRejection::kTooSmall: return "too small";
    case TargetRejection::kAtImageEdge: return "at the image edge";
    case TargetRejection::kWeakEdge: return "weak edge";
    case TargetRejection::kBrightSurround: return "bright surround";
    case TargetRejection::kEdgeContinues: return "edge continues";
    case TargetRejection::kAspect: return "aspect ratio";
    case TargetRejection::kShapeUncertain: return "shape uncertain";
    case TargetRejection::kNoMarker: return "no marker";
    case TargetRejection::kCount: break;
  }
  return "?";
}

namespace {

struct Rectified {
  double aspect = 0;     // width/height (side 0-1 over side 1-2)
  double cos_angle = 1;  // between the rectified sides: 0 for a rectangle
};

// The rectangle seen as `quad` by a camera of focal length f (principal point at the
// image centre): the homography from the unit square, K^-1 H's first two columns are the
// rectangle's sides in the camera frame.
std::optional<Rectified> rectify(const cv::Mat& H, double f) {
  const cv::Vec3d r1(H.at<double>(0, 0) / f, H.at<double>(1, 0) / f, H.at<double>(2, 0));
  const cv::Vec3d r2(H.at<double>(0, 1) / f, H.at<double>(1, 1) / f, H.at<double>(2, 1));
  const double n1 = cv::norm(r1), n2 = cv::norm(r2);
  if (!(n1 > 0) || !(n2 > 0) || !std::isfinite(n1 / n2)) return std::nullopt;
  return Rectified{n1 / n2, r1.dot(r2) / (n1 * n2)};
}

// Centred on the principal point (negative: the image centre).
cv::Mat squareToQuad(const Quad& quad, cv::Size image, cv::Point2d principal) {
  const cv::Point2f c = principal.x >= 0 && principal.y >= 0
                            ? cv::Point2f(principal)
                            : cv::Point2f(image.width / 2.0f, image.height / 2.0f);
  std::vector<cv::Point2f> square{{0, 0}, {1, 0}, {1, 1}, {0, 1}}, centred;
  for (const auto& p : quad) centred.push_back(p - c);
  return cv::getPerspectiveTransform(square, centred);
}

}  // namespace

std::optional<double> rectifiedAspect(const Quad& quad, cv::Size image, double focal_px,
                                      cv::Point2d principal_px) {
  const cv::Mat H = squareToQuad(quad, image, principal_px);
  if (H.empty()) return std::nullopt;
  double f = focal_px;
  const double fallback = std::max(image.width, image.height);  // ~53 deg field of view
  if (!(f > 0)) {
    // Zhang & He's whiteboard rectification: the rectangle's sides are orthogonal, which
    // fixes f unless the view is nearly frontal (then f hardly matters).
    f = fallback;
    const double h31 = H.at<double>(2, 0), h32 = H.at<double>(2, 1);
    if (std::abs(h31 * h32) > 1e-12) {
      const double f2 = -(H.at<double>(0, 0) * H.at<double>(0, 1) +
                          H.at<double>(1, 0) * H.at<double>(1, 1)) /
                        (h31 * h32);
      if (f2 > 0 && std::sqrt(f2) > 0.3 * fallback && std::sqrt(f2) < 4 * fallback)
        f = std::sqrt(f2);
    }
  }
  const auto r = rectify(H, f);
  if (!r) return std::nullopt;
  return r->aspect;
}

double rectifiedAspectSigma(const Quad& quad, cv::Size image, double corner_sigma_px,
                            double focal_px, cv::Point2d principal_px) {
  const auto a0 = rectifiedAspect(quad, image, focal_px, principal_px);
  if (!a0) return std::numeric_limits<double>::infinity();
  // Central differences over a step well inside the linear range (the aspect's curvature
  // shows over pixels, not hundredths).
  const float h = 0.05f;
  double sum2 = 0;
  for (int i = 0; i < 4; ++i) {
    for (int axis = 0; axis < 2; ++axis) {
      Quad plus = quad, minus = quad;
      (axis == 0 ? plus[i].x : plus[i].y) += h;
      (axis == 0 ? minus[i].x : minus[i].y) -= h;
      const auto ap = rectifiedAspect(plus, image, focal_px, principal_px);
      const auto am = rectifiedAspect(minus, image, focal_px, principal_px);
      if (!ap || !am) return std::numeric_limits<double>::infinity();
      const double d = (*ap - *am) / (2 * h);
      sum2 += d * d;
    }
  }
  return corner_sigma_px * std::sqrt(sum2) / *a0;
}

namespace {

// The aspect check. With the focal length known (the nodelet: camera_info), the
// rectified width/height must be the sheet's (at a focal length within 5 % of it).
// Unknown (a photo given to detect_target): some focal length from 0.5 to 5 image sizes
// (a cropped photo has a long one) must make the quadrilateral a rectangle (sides within
// 9 deg of square) of the sheet's shape.
// The relative aspect error of the best focal length, its aspect and that focal length.
struct AspectFit {
  double error = std::numeric_limits<double>::infinity();
  double aspect = 0;
  double focal_px = 0;
};
AspectFit aspectError(const Quad& quad, cv::Size image, double focal_px,
                      cv::Point2d principal_px, double expected) {
  const cv::Mat H = squareToQuad(quad, image, focal_px > 0 ? principal_px : cv::Point2d(-1, -1));
  AspectFit best;
  if (H.empty()) return best;
  auto consider = [&](double f, bool need_square) {
    const auto r = rectify(H, f);
    if (!r || (need_square && std::abs(r->cos_angle) > 0.16)) return;
    const double a = std::max(r->aspect, 1 / r->aspect);
    const double error = std::abs(a / expected - 1);
    if (error < best.error) best = {error, a, f};
  };
  if (focal_px > 0) {
    // The aspect follows f about 1:1 in an oblique view, and a camera_info's focal length
    // may be a few percent off (a driver's nominal K, an old calibration): the best one
    // within 5 % of it, in 1 % steps, so a 2 % tolerance does not refuse such a camera.
    for (int step = -5; step <= 5; ++step) consider(focal_px * (1 + 0.01 * step), false);
    return best;
  }
  const double size = std::max(image.width, image.height);
  // Steps of 1 %: the aspect changes with f about as fast, and the tolerance is 2 %.
  for (double f = 0.5 * size; f <= 5.0 * size; f *= 1.01) consider(f, true);
  return best;
}

}  // namespace

std::array<cv::Point3d, 4> targetCornersInMap(const TargetParams& p) {
  const bool marker = p.target_type == "aruco";
  const double w = (marker ? p.marker_size_m : p.width_m) / 2;
  const double h = (marker ? p.marker_size_m : p.height_m) / 2;
  return {cv::Point3d(-w, -h, 0), cv::Point3d(w, -h, 0), cv::Point3d(w, h, 0),
          cv::Point3d(-w, h, 0)};
}

std::string targetParamsError(const TargetParams& p) {
  if (p.target_type != "sheet" && p.target_type != "aruco")
    return "target_type '" + p.target_type + "' is neither sheet nor aruco";
  if (p.target_type == "aruco") return markerParamsError(p);
  return {};
}

TargetDetection detectConfiguredTarget(const cv::Mat& gray, const TargetParams& params,
                                       double focal_px, cv::Point2d principal_px) {
  if (params.target_type == "aruco") return detectMarkerTarget(gray, params);
  return detectTarget(gray, params, focal_px, principal_px);
}

TargetDetection detectTarget(const cv::Mat& gray, const TargetParams& params, double focal_px,
                             cv::Point2d principal_px) {
  TargetDetection out;
  if (gray.empty() || gray.type() != CV_8UC1) {
    out.rejection = TargetRejection::kBadImage;
    out.reason = "needs a non-empty 8-bit grey image";
    return out;
  }
  if (gray.cols < 16 || gray.rows < 16) {
    out.rejection = TargetRejection::kBadImage;
    out.reason = "image too small";
    return out;
  }
  // Candidates and their checks at most ~800 px wide (a 1280 px image costs 2.5x for no
  // better decision); corners are refined at full resolution.
  const double scale = std::min(1.0, 800.0 / std::max(gray.cols, gray.rows));
  cv::Mat work = gray;
  if (scale < 1) cv::resize(gray, work, cv::Size(), scale, scale, cv::INTER_AREA);
  const double min_area = params.min_area_px * scale * scale;
  const double sigma = noiseSigma(work);
  const std::vector<Candidate> candidates = candidateQuads(work, sigma, min_area);
  const double expected = std::max(params.width_m, params.height_m) /
                          std::min(params.width_m, params.height_m);
  const double full_sigma = noiseSigma(gray);
  // The reason reported is that of the candidate that got furthest (the largest of those).
  int reason_stage = -1;
  double reason_area = 0;
  auto reject = [&](TargetRejection r, const std::string& why, double area) {
    ++out.rejected[static_cast<int>(r)];
    const int stage = stageOf(r);
    if (stage > reason_stage || (stage == reason_stage && area > reason_area)) {
      reason_stage = stage;
      reason_area = area;
      out.rejection = r;
      out.reason = why;
    }
  };
  double best_area = 0;
  std::optional<Quad> best;
  bool best_side0_is_width = true;
  double best_contrast = 0, best_ratio = 0, best_aspect_sigma = 0;
  for (const Candidate& c : candidates) {
    if (best && c.area <= best_area) continue;  // the largest sheet wins
    double shortest = std::numeric_limits<double>::max();
    for (int i = 0; i < 4; ++i) shortest = std::min(shortest, cv::norm(c.quad[(i + 1) % 4] - c.quad[i]));
    if (shortest < 10 * scale) {
      reject(TargetRejection::kTooSmall, "the largest candidate has a side under 10 px", c.area);
      continue;
    }
    const float margin = 1.5f;
    if (std::any_of(c.quad.begin(), c.quad.end(), [&](const cv::Point2f& p) {
          return p.x < margin || p.y < margin || p.x > work.cols - 1 - margin ||
                 p.y > work.rows - 1 - margin;
        })) {
      reject(TargetRejection::kAtImageEdge, "the sheet touches the image border (cut off?)",
             c.area);
      continue;
    }
    const SideCheck sides = checkSides(work, c.quad, c.area, sigma, params);
    if (sides.rejection != TargetRejection::kNone) {
      reject(sides.rejection, sides.reason, c.area);
      continue;
    }
    // Corners at full resolution; the search reaches past the contour's rounding.
    Quad full;
    for (int i = 0; i < 4; ++i) full[i] = c.quad[i] / static_cast<float>(scale);
    const int reach = std::max(4, static_cast<int>(std::ceil(2.5 / scale)));
    // A quarter of the mean step: sunlight across part of the surround (test2) halves it there.
    const double min_step = std::max(6 * full_sigma, 0.25 * (sides.inside - sides.outside));
    std::optional<Quad> refined = refineByEdgeLines(gray, full, reach, min_step);
    if (refined) refined = refineByEdgeLines(gray, *refined, 3, min_step);  // converge
    if (!refined) {
      reject(TargetRejection::kWeakEdge, "a side has too few edge points for a straight line",
             c.area);
      continue;
    }
    // The refined corners again (the fitted sides can meet past the border; make fuzz
    // found one 0.3 px outside a 40 px image): a corner the camera cannot see cannot be
    // tracked, and tracks outside the image are refused downstream.
    if (std::any_of(refined->begin(), refined->end(), [&](const cv::Point2f& p) {
          return p.x < margin || p.y < margin || p.x > gray.cols - 1 - margin ||
                 p.y > gray.rows - 1 - margin;
        })) {
      reject(TargetRejection::kAtImageEdge, "the sheet touches the image border (cut off?)",
             c.area);
      continue;
    }
    Quad in_work;
    for (int i = 0; i < 4; ++i) in_work[i] = (*refined)[i] * static_cast<float>(scale);
    if (const auto [corner, fraction] = continuingSide(work, in_work, sigma); corner >= 0) {
      // Where, in the image: a user at the robot sees which corner lines up with what.
      std::ostringstream why;
      why << "an edge goes on past the corner at (" << std::fixed << std::setprecision(0)
          << (*refined)[corner].x << ", " << (*refined)[corner].y << ") px with "
          << std::setprecision(2) << fraction
          << " of its step (part of something larger: a stripe, a box, a table's edge?)";
      reject(TargetRejection::kEdgeContinues, why.str(), c.area);
      continue;
    }
    const AspectFit fit = aspectError(*refined, gray.size(), focal_px, principal_px, expected);
    const double aspect_error = fit.error, a = fit.aspect;
    const auto aspect = rectifiedAspect(*refined, gray.size(), focal_px, principal_px);
    if (!aspect || !(aspect_error <= params.max_aspect_error)) {
      std::ostringstream why;
      why.precision(3);
      if (!(a > 0))  // not the image of a rectangle in front of the camera
        why << (focal_px > 0 ? "not a rectangle in front of the camera"
                             : "not a rectangle seen in perspective (no focal length of 0.5-5 "
                               "image sizes makes its corners square)");
      else
        why << "rectified width/height " << a << ", the sheet's is " << expected
            << (focal_px > 0 ? "" : " (focal length unknown: best over 0.5-5 image sizes)");
      reject(TargetRejection::kAspect, why.str(), c.area);
      continue;
    }
    // On a light surround (a wall, a light table) light rectangles are everywhere, and a
    // small or grazing one passes the shape test by chance: there the corners must fix the
    // shape to within its tolerance. (At the focal length the test chose: with none given,
    // the one estimated from the corners would itself move with them.)
    const double aspect_sigma = rectifiedAspectSigma(*refined, gray.size(), params.corner_sigma_px,
                                                     fit.focal_px, principal_px);
    if (sides.ratio > params.dark_surround_ratio && !(aspect_sigma <= params.max_aspect_error)) {
      std::ostringstream why;
      why.precision(3);
      why << "on a light surround (" << sides.ratio << ") too small or too oblique to tell "
          << "its shape: width/height moves by " << aspect_sigma * 100 << " % for "
          << params.corner_sigma_px << " px at the corners (needs <= "
          << params.max_aspect_error * 100 << " %; closer, more face-on, or a darker surround)";
      reject(TargetRejection::kShapeUncertain, why.str(), c.area);
      continue;
    }
    best = refined;
    best_area = c.area;
    best_aspect_sigma = aspect_sigma;
    best_side0_is_width = *aspect >= 1;
    best_contrast = sides.inside - sides.outside;
    best_ratio = sides.ratio;
  }
  if (!best) {
    if (candidates.empty()) {
      out.rejection = TargetRejection::kNoCandidate;
      out.reason = "no convex quadrilateral (is a sheet in view, all of it?)";
    }
    return out;
  }
  out.corners = orderCorners(*best, best_side0_is_width);
  out.contrast = best_contrast;
  out.surround_ratio = best_ratio;
  out.aspect_sigma = best_aspect_sigma;
  out.found = true;
  out.rejection = TargetRejection::kNone;
  out.reason.clear();
  return out;
}

std::optional<TargetPose> cameraPoseFromTarget(const TargetDetection& detection,
                                               const cv::Matx33d& K, const cv::Mat& distortion,
                                               const TargetParams& params) {
  if (!detection.found) return std::nullopt;
  if (!(K(0, 0) > 0) || !(K(1, 1) > 0) || !std::isfinite(K(0, 0)) || !std::isfinite(K(1, 1)) ||
      !std::isfinite(K(0, 2)) || !std::isfinite(K(1, 2))) {
    return std::nullopt;
  }
  const auto map_corners = targetCornersInMap(params);
  const std::vector<cv::Point3d> object(map_corners.begin(), map_corners.end());
  const std::vector<cv::Point2d> image(detection.corners.begin(), detection.corners.end());
  cv::Vec3d rvec, tvec;
  // IPPE returns NaN for some nearly frontal views with a little corner noise (its
  // rotation takes a square root of a rounding-negative number): solved again by the
  // iterative solver, whose planar start is a homography, rather than refused.
  bool solved = false;
  for (const int method : {cv::SOLVEPNP_IPPE, cv::SOLVEPNP_ITERATIVE}) {
    solved = cv::solvePnP(object, image, cv::Mat(K), distortion, rvec, tvec, false, method) &&
             cv::checkRange(rvec) && cv::checkRange(tvec);
    if (solved) break;
  }
  if (!solved) return std::nullopt;
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  const Pose camera_from_map{R, tvec};
  std::vector<cv::Point2d> reprojected;
  cv::projectPoints(object, rvec, tvec, cv::Mat(K), distortion, reprojected);
  double sum = 0;
  for (int i = 0; i < 4; ++i) sum += std::pow(cv::norm(reprojected[i] - image[i]), 2);
  return TargetPose{camera_from_map.inverse(), std::sqrt(sum / 4)};
}

}  // namespace mono_plane_detection
