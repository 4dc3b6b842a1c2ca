// The tracker against the floor cost of tracking, in one run, on generated and on real
// frames: time per image (mean, p95), heap allocations per image in the steady state
// and tracking quality against ground truth. Writes a plot. A measurement, never a test.
//   rosrun mono_plane_detection benchmark_tracker_floor [--frames N] [--euroc F] [--tum F]
//     [--size WxH] [--features N]   (one row, e.g. to profile it)
//     [--spread N]   (the tracker's search_spread_images; default: the tracker's default)
//     [--predict-motion 0|1]   (the tracker's predict_motion; default: the tracker's default)
//     [--noise-seed N]   (another draw of the sensor noise: how much a figure moves by chance)
//     [--phase N]   (the swing starts N images on: the search images meet other motion)
//
// Real frames: a real image (EuRoC, TUM office) moved by known homographies. The data
// sets hold stills (EuRoC: the vehicle stands) or images 1 s apart (TUM), neither a
// video a tracker can follow with truth; the known motion of a real picture gives real
// texture, real noise and blur, and exact ground truth for every point.
#include <malloc.h>
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <set>
#include <string>
#include <vector>

#include "cli_args.h"
#include "thread_cpu_time.h"
#include "mono_plane_detection/eval/track_scorer.h"
#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/sim/synthetic_views.h"
#include "mono_plane_detection/tracking/feature_tracker.h"

#include "allocation_counter.h"

using namespace mono_plane_detection;
using Clock = std::chrono::steady_clock;

namespace {

const int kSteadyFrom = 20;  // images before this one are the start-up, not the steady state

// A camera swinging left-right and bobbing once per 100 images: points leave at the
// borders and come back (re-identification), about 8 px per image at the fastest.
struct Sequence {
  std::vector<cv::Mat> images;
  std::vector<cv::Matx33d> truth;  // texture pixel -> view pixel
};

Sequence makeSequence(const cv::Mat& texture_source, const cv::Size& size, int count,
                      int noise_seed, int phase_images) {
  // The texture covers the view with a margin for the swing.
  cv::Mat texture;
  cv::resize(texture_source, texture, {cvRound(1.6 * size.width), cvRound(1.6 * size.height)}, 0,
             0, cv::INTER_AREA);
  const cv::Point2d centre(size.width / 2.0, size.height / 2.0);
  const cv::Point2d base(-0.3 * size.width, -0.3 * size.height);
  Sequence s;
  cv::RNG rng(noise_seed);
  for (int k = 0; k < count; ++k) {
    const double phase = 2 * CV_PI * (k + phase_images) / 100.0;
    const cv::Point2d swing(0.2 * size.width * std::sin(phase), 0.08 * size.height * std::sin(2 * phase));
    const cv::Matx33d H = similarity(0.03 * std::sin(phase), centre, base + swing);
    cv::Mat view = warpView(texture, H, size);
    cv::Mat noise(view.size(), CV_16SC1), noisy;
    rng.fill(noise, cv::RNG::NORMAL, 0, 3);  // sensor noise, grey levels
    view.convertTo(noisy, CV_16SC1);
    noisy += noise;
    noisy.convertTo(view, CV_8UC1);
    s.images.push_back(view);
    s.truth.push_back(H);
  }
  return s;
}

struct Timing {
  double mean = 0, p95 = 0, max = 0, wall_mean = 0;
  // Steady state (from image kSteadyFrom on): heap allocations and kB per image, on
  // images without and with a corner search.
  double allocations = 0, kbytes = 0, search_allocations = 0, search_kbytes = 0;
  double plain_mean = 0, search_mean = 0;  // ms, images without / with a search (all images)
};

// Per-image records of one tracker.
struct Record {
  std::vector<double> ms, wall_ms;
  long allocations[2] = {0, 0}, bytes[2] = {0, 0};  // [searched]
  int images[2] = {0, 0};
  double split_ms[2] = {0, 0};
  int split_images[2] = {0, 0};

  template <class F>
  void measure(size_t k, F&& work) {
    const bool steady = static_cast<int>(k) >= kSteadyFrom;
    g_allocations = 0;
    g_bytes = 0;
    g_counting = steady;
    const double cpu = threadCpuMs();
    const auto wall = Clock::now();
    const bool searched = work();
    wall_ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - wall).count());
    ms.push_back(threadCpuMs() - cpu);
    g_counting = false;
    split_ms[searched] += ms.back();
    ++split_images[searched];
    if (!steady) return;
    allocations[searched] += g_allocations;
    bytes[searched] += g_bytes;
    ++images[searched];
  }

  Timing timing() const {
    Timing t;
    for (double x : ms) t.mean += x / ms.size();
    for (double x : wall_ms) t.wall_mean += x / wall_ms.size();
    t.p95 = percentile(ms, 0.95);
    t.max = *std::max_element(ms.begin(), ms.end());
    t.allocations = static_cast<double>(allocations[0]) / std::max(1, images[0]);
    t.kbytes = bytes[0] / 1024.0 / std::max(1, images[0]);
    t.search_allocations = static_cast<double>(allocations[1]) / std::max(1, images[1]);
    t.search_kbytes = bytes[1] / 1024.0 / std::max(1, images[1]);
    t.plain_mean = split_ms[0] / std::max(1, split_images[0]);
    t.search_mean = split_ms[1] / std::max(1, split_images[1]);
    return t;
  }
};

struct Quality {
  double mean_error = 0, p95_error = 0;
  double kept_per_image = 0;  // share of the points followed from one image to the next
  int ids_first = 0, ids_kept = 0;  // ids of the first image, and of them still there after 100
  double reid_rate = 0;  // share of new corners (after the first image) that got an old id
  int searches = 0;
  // Points Lucas-Kanade follows per image, ours and the floor's (their work is per point).
  double points_ours = 0, points_floor = 0;
};

struct RowResult {
  Timing ours, floor;
  Quality quality;
  double ratio = 0;  // ours / floor mean time
};

RowResult runRow(const Sequence& seq, int features, const TrackerParams& base) {
  RowResult r;
  TrackerParams params = base;
  params.max_features = features;
  FeatureTracker tracker(params);
  TrackScorer score;
  Record ours, floor;
  std::set<std::uint64_t> first;
  double followed = 0, tracked = 0, floor_followed = 0;
  long reidentified = 0, added = 0;
  // The floor: goodFeaturesToTrack when the tracker's own rule (shouldSearch: every
  // redetect_every images, or 2/3 of the last search's corners lost) says so,
  // calcOpticalFlowPyrLK from the previous image on the others; the tracker's pyramid,
  // window and corner settings; no ids, no checks, no matching. (Its own rule, a third of
  // max_features left, made it search every image wherever an image holds fewer corners
  // than that: 320x240 real frames with 500 features, none tracked.)
  std::vector<cv::Point2f> points, next;
  int found_at_search = 0, since_search = 0;
  std::vector<uchar> status;
  std::vector<float> error;
  // Both on each image in turn, so that a busy machine slows both alike.
  for (size_t k = 0; k < seq.images.size(); ++k) {
    const std::vector<TrackedPoint>* state = nullptr;
    ours.measure(k, [&] {
      state = &tracker.process(seq.images[k]);
      return tracker.lastStats().searched || tracker.lastStats().search_rest;
    });
    floor.measure(k, [&] {
      if (k == 0 || shouldSearch(found_at_search, static_cast<int>(points.size()),
                                 ++since_search, params)) {
        cv::goodFeaturesToTrack(seq.images[k], points, features, params.quality_level,
                                params.min_distance_px, cv::noArray(), params.block_size);
        found_at_search = static_cast<int>(points.size());
        since_search = 0;
        return true;
      }
      floor_followed += static_cast<double>(points.size());
      cv::calcOpticalFlowPyrLK(seq.images[k - 1], seq.images[k], points, next, status, error,
                               cv::Size(params.window_size_px, params.window_size_px),
                               params.pyramid_levels - 1);
      points.clear();
      for (size_t i = 0; i < next.size(); ++i)
        if (status[i]) points.push_back(next[i]);
      return false;
    });
    score.observe(*state, seq.truth[k]);
    followed += tracker.previous().size();
    tracked += tracker.lastStats().tracked;
    r.quality.searches += tracker.lastStats().searched;
    if (k == 0) {
      for (const auto& p : *state) first.insert(p.id);
    } else {
      reidentified += tracker.lastStats().reidentified;
      added += tracker.lastStats().added;
    }
    if (k == 99) {
      for (const auto& p : *state) r.quality.ids_kept += static_cast<int>(first.count(p.id));
    }
  }
  r.ours = ours.timing();
  r.floor = floor.timing();
  r.ratio = r.ours.mean / r.floor.mean;
  r.quality.mean_error = score.meanError();
  r.quality.p95_error = percentile(score.errors(), 0.95);
  r.quality.kept_per_image = followed > 0 ? tracked / followed : 0;
  r.quality.points_ours = followed / std::max<size_t>(1, seq.images.size() - 1);
  r.quality.points_floor = floor_followed / std::max<size_t>(1, seq.images.size() - 1);
  r.quality.ids_first = static_cast<int>(first.size());
  r.quality.reid_rate = reidentified + added > 0
                            ? static_cast<double>(reidentified) / (reidentified + added)
                            : 0;
  return r;
}

// The median of `repeats` runs of a row, figure by figure (the machine is shared: one
// run can be slowed by others).
RowResult medianRow(const Sequence& seq, int features, const TrackerParams& base, int repeats) {
  std::vector<RowResult> runs;
  for (int r = 0; r < repeats; ++r) runs.push_back(runRow(seq, features, base));
  auto median = [&](auto get) {
    std::vector<double> v;
    for (const auto& r : runs) v.push_back(get(r));
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  RowResult m = runs.front();  // quality and allocations are the same in every run
  m.ours.mean = median([](const RowResult& r) { return r.ours.mean; });
  m.ours.p95 = median([](const RowResult& r) { return r.ours.p95; });
  m.ours.max = median([](const RowResult& r) { return r.ours.max; });
  m.ours.wall_mean = median([](const RowResult& r) { return r.ours.wall_mean; });
  m.floor.mean = median([](const RowResult& r) { return r.floor.mean; });
  m.floor.p95 = median([](const RowResult& r) { return r.floor.p95; });
  m.floor.max = median([](const RowResult& r) { return r.floor.max; });
  m.floor.wall_mean = median([](const RowResult& r) { return r.floor.wall_mean; });
  m.ours.plain_mean = median([](const RowResult& r) { return r.ours.plain_mean; });
  m.ours.search_mean = median([](const RowResult& r) { return r.ours.search_mean; });
  m.floor.plain_mean = median([](const RowResult& r) { return r.floor.plain_mean; });
  m.floor.search_mean = median([](const RowResult& r) { return r.floor.search_mean; });
  m.ratio = median([](const RowResult& r) { return r.ours.mean / r.floor.mean; });
  return m;
}

struct Row {
  std::string source;
  cv::Size size;
  int features;
  RowResult result;
};

// One panel per source: ms per image against features, ours solid, the floor dashed,
// mean (thick) and p95 (thin), one colour per image size.
void plot(const std::vector<Row>& rows, const std::string& path) {
  std::vector<std::string> sources;
  for (const auto& r : rows)
    if (std::find(sources.begin(), sources.end(), r.source) == sources.end())
      sources.push_back(r.source);
  const int pw = 330, ph = 300, left = 45, bottom = 40, top = 30, right = 10;
  cv::Mat img(ph + 40, pw * static_cast<int>(sources.size()), CV_8UC3, cv::Scalar::all(255));
  double max_ms = 0.1;
  for (const auto& r : rows) max_ms = std::max({max_ms, r.result.ours.p95, r.result.floor.p95});
  for (size_t s = 0; s < sources.size(); ++s) {
    const int x0 = static_cast<int>(s) * pw;
    auto at = [&](double features, double ms) {
      return cv::Point(cvRound(x0 + left + (pw - left - right) * features / 550.0),
                       cvRound(ph - bottom - (ph - bottom - top) * ms / (1.05 * max_ms)));
    };
    cv::line(img, at(0, 0), at(550, 0), cv::Scalar::all(0));
    cv::line(img, at(0, 0), at(0, 1.05 * max_ms), cv::Scalar::all(0));
    for (int f : {50, 150, 500})
      cv::putText(img, std::to_string(f), at(f, 0) + cv::Point(-10, 15), cv::FONT_HERSHEY_SIMPLEX,
                  0.35, cv::Scalar::all(0));
    for (int k = 0; k <= 4; ++k)
      cv::putText(img, cv::format("%.1f", max_ms * k / 4), at(0, max_ms * k / 4) + cv::Point(-38, 4),
                  cv::FONT_HERSHEY_SIMPLEX, 0.35, cv::Scalar::all(0));
    cv::putText(img, sources[s] + " (ms per image vs features)", {x0 + left, 18},
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar::all(0), 1, cv::LINE_AA);
    for (const cv::Size size : {cv::Size(320, 240), cv::Size(640, 480)}) {
      const cv::Scalar colour = size.width == 320 ? cv::Scalar(200, 0, 0) : cv::Scalar(0, 0, 200);
      auto series = [&](auto value, bool dashed, int thickness) {
        std::vector<cv::Point> pts;
        for (const auto& r : rows)
          if (r.source == sources[s] && r.size == size) pts.push_back(at(r.features, value(r)));
        for (size_t i = 1; i < pts.size(); ++i) {
          for (double t = 0; t < 1; t += dashed ? 0.1 : 1.0)
            cv::line(img, pts[i - 1] + (pts[i] - pts[i - 1]) * t,
                     pts[i - 1] + (pts[i] - pts[i - 1]) * std::min(1.0, t + (dashed ? 0.05 : 1.0)),
                     colour, thickness, cv::LINE_AA);
        }
      };
      series([](const Row& r) { return r.result.ours.mean; }, false, 2);
      series([](const Row& r) { return r.result.floor.mean; }, true, 2);
      series([](const Row& r) { return r.result.ours.p95; }, false, 1);
      series([](const Row& r) { return r.result.floor.p95; }, true, 1);
    }
  }
  cv::putText(img,
              "blue 320x240, red 640x480; ours solid, floor (GFTT every 10 + LK) dashed; "
              "thick mean, thin p95",
              {10, ph + 25}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar::all(0), 1, cv::LINE_AA);
  cv::imwrite(path, img);
}

}  // namespace

int main(int argc, char** argv) {
  int count = 150, repeats = 3;
  std::string plot_path = "benchmark_tracker_floor.png";
  std::string euroc, tum, only_size;
  int only_features = 0, spread = 0, noise_seed = 7, phase_images = 0, predict = -1;
  cli::Parser cli("benchmark_tracker_floor", "[options]",
                  "  The tracker against goodFeaturesToTrack every 10 images +\n"
                  "  calcOpticalFlowPyrLK, on generated texture and on real images moved by\n"
                  "  known homographies: time, allocations, quality. Figures, never pass/fail.");
  cli.integer("frames", &count, 100, 100000, "images per row (at least 100: ids kept over 100)")
      .integer("repeats", &repeats, 1, 100, "runs per row; figures are their median")
      .text("plot", &plot_path, "where to write the plot", "FILE.png")
      .text("euroc", &euroc, "a EuRoC image (752x480 grey) as real texture", "FILE.png")
      .text("tum", &tum, "a TUM RGB-D image (640x480 colour) as real texture", "FILE.png")
      .text("size", &only_size, "only the rows of this image size (profiling)", "WxH")
      .integer("features", &only_features, 0, 100000, "only the rows of this count (0: all)")
      .integer("spread", &spread, 0, 100,
               "the tracker's search_spread_images, images a search's work runs over (0: the "
               "tracker's default)")
      .integer("predict-motion", &predict, -1, 1,
               "the tracker's predict_motion, 0 or 1 (-1: the tracker's default)")
      .integer("noise-seed", &noise_seed, 0, 1000000,
               "seed of the sensor noise (the quality figures of one seed move by chance: "
               "compare several)")
      .integer("phase", &phase_images, 0, 99,
               "start the swing this many images on (the search images then meet other "
               "motion: which returning points a search finds first depends on it)");
  if (const auto code = cli.parse(argc, argv)) return *code;
  cv::setNumThreads(1);
  TrackerParams base;
  if (spread > 0) base.search_spread_images = spread;
  if (predict >= 0) base.predict_motion = predict == 1;

  std::vector<std::pair<std::string, cv::Mat>> sources;
  sources.push_back({"generated", makeCornerTexture({1024, 768}, 42)});
  for (const auto& [name, file] : {std::pair{"euroc", euroc}, std::pair{"tum", tum}}) {
    if (file.empty()) continue;
    const cv::Mat image = cv::imread(file, cv::IMREAD_GRAYSCALE);
    if (image.empty()) return cli.fail("cannot read " + file);
    sources.push_back({name, image});
  }

  std::printf(
      "benchmark_tracker_floor: one thread, %d images per row, median of %d runs (swing\n"
      "left-right and bob,\n"
      "up to ~8 px per image, sensor noise 3 grey levels), tracker defaults but max_features.\n"
      "floor = goodFeaturesToTrack when the tracker's rule says (every 10 images, 2/3 of\n"
      "the last search's lost) + calcOpticalFlowPyrLK,\n"
      "run on each image right after ours. ms = CPU ms of the thread per image (mean / p95 /\n"
      "max; wall = wall-clock mean, the machine is shared); alloc = heap allocations per\n"
      "image from image %d on (whole process, OpenCV included), images without / with\n"
      "(an image of) a corner search, and kB; err = px from the truth; kept = share followed\n"
      "image to image;\n"
      "ids100 = ids of image 0 still there at image 99; reid = share of new corners that\n"
      "got a lost id back; srch = images with a search; pts = points followed per image,\n"
      "ours / the floor's; n/s = mean ms on images without / with a search, ours and floor's.\n\n",
      count, repeats, kSteadyFrom);
  std::printf(
      "search_spread_images %d, predict_motion %d, noise seed %d, phase %d\n"
      "%-9s %-7s %4s | %19s %5s %19s | %19s %5s %19s | %5s %5s | %5s %5s %5s %7s %5s %4s %7s %11s "
      "%11s\n",
      base.search_spread_images, base.predict_motion ? 1 : 0, noise_seed, phase_images,
      "source", "image", "feat", "ours ms mean/p95/max", "wall", "alloc n/s, kB n/s",
      "floor mean/p95/max", "wall", "alloc n/s, kB n/s", "ratio", "p95/m", "err", "p95e", "kept",
      "ids100", "reid", "srch", "pts o/f", "ours n/s", "floor n/s");
  std::vector<Row> rows;
  for (const auto& [name, texture] : sources) {
    for (const cv::Size size : {cv::Size(320, 240), cv::Size(640, 480)}) {
      if (!only_size.empty() && only_size != cv::format("%dx%d", size.width, size.height)) continue;
      const Sequence seq = makeSequence(texture, size, count, noise_seed, phase_images);
      for (int features : {50, 150, 500}) {
        if (only_features > 0 && features != only_features) continue;
        Row row{name, size, features, medianRow(seq, features, base, repeats)};
        const RowResult& r = row.result;
        auto alloc = [](const Timing& t) {
          return cv::format("%3.0f/%3.0f %4.0f/%4.0f", t.allocations, t.search_allocations,
                            t.kbytes, t.search_kbytes);
        };
        std::printf(
            "%-9s %3dx%-3d %4d | %5.2f / %5.2f / %5.2f %5.2f %19s | %5.2f / %5.2f / %5.2f %5.2f "
            "%19s | %4.2fx %4.1fx | %5.3f %5.3f %4.1f%% %3d/%-3d %4.1f%% %4d %3.0f/%-3.0f "
            "%4.2f/%-6.2f %4.2f/%-6.2f\n",
            name.c_str(), size.width, size.height, features, r.ours.mean, r.ours.p95, r.ours.max,
            r.ours.wall_mean, alloc(r.ours).c_str(), r.floor.mean, r.floor.p95, r.floor.max,
            r.floor.wall_mean, alloc(r.floor).c_str(), r.ratio, r.ours.p95 / r.ours.mean,
            r.quality.mean_error, r.quality.p95_error, 100 * r.quality.kept_per_image,
            r.quality.ids_kept, r.quality.ids_first, 100 * r.quality.reid_rate, r.quality.searches,
            r.quality.points_ours, r.quality.points_floor, r.ours.plain_mean, r.ours.search_mean,
            r.floor.plain_mean, r.floor.search_mean);
        std::fflush(stdout);
        rows.push_back(row);
      }
    }
  }
  plot(rows, plot_path);
  std::printf("\nplot: %s\n", plot_path.c_str());
  return 0;
}
