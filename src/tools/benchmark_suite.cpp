// The benchmark suite (make bench): our tracker and plane stage against plain baselines
// doing the same work in the same run, on generated frames, one thread. Prints a table
// with ours / baseline for every row and writes a plot (time against points).
// A measurement, never a test.
//   rosrun mono_plane_detection benchmark_suite [--frames N] [--repeats N] [--plot file.png]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <string>
#include <vector>

#include "cli_args.h"
#include "thread_cpu_time.h"
#include "mono_plane_detection/eval/segmentation_error.h"
#include "mono_plane_detection/eval/sequential_magsac.h"
#include "mono_plane_detection/tracking/feature_tracker.h"
#include "mono_plane_detection/planes/homography_voting.h"
#include "mono_plane_detection/sim/scene_renderer.h"
#include "mono_plane_detection/sim/synthetic_two_view.h"
#include "mono_plane_detection/tracking/target_detector.h"
#include "mono_plane_detection/tracking/target_startup.h"
#include "mono_plane_detection/sim/synthetic_views.h"

using namespace mono_plane_detection;
using Clock = std::chrono::steady_clock;

namespace {

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

struct Stats {
  double mean = 0, p95 = 0;
};

Stats stats(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  for (double x : v) s.mean += x / v.size();
  std::sort(v.begin(), v.end());
  s.p95 = v[std::min(v.size() - 1, v.size() * 95 / 100)];
  return s;
}

// Frames of a texture drifting and turning slowly (the "easy" motion of benchmark_tracker).
std::vector<cv::Mat> frames(const cv::Size& size, int count) {
  const cv::Mat texture = makeCornerTexture({size.width * 2, size.height * 2}, 42);
  std::vector<cv::Mat> out;
  cv::RNG rng(7);
  for (int k = 0; k < count; ++k) {
    const cv::Point2d shift(-size.width / 2.0 + 1.5 * k, -size.height / 2.0 + 0.5 * k);
    cv::Mat view = warpView(
        texture, similarity(0.002 * k, {size.width / 2.0, size.height / 2.0}, shift), size);
    cv::Mat noise(view.size(), CV_16SC1);
    rng.fill(noise, cv::RNG::NORMAL, 0, 3);
    cv::Mat noisy;
    view.convertTo(noisy, CV_16SC1);
    noisy += noise;
    noisy.convertTo(view, CV_8UC1);
    out.push_back(view);
  }
  return out;
}

// Our tracker, per-frame times.
std::vector<double> timeTracker(const std::vector<cv::Mat>& images, int features) {
  TrackerParams p;
  p.max_features = features;
  FeatureTracker tracker(p);
  std::vector<double> t;
  for (const cv::Mat& image : images) {
    const auto start = Clock::now();
    tracker.process(image);
    t.push_back(msSince(start));
  }
  return t;
}

// The floor cost of tracking: goodFeaturesToTrack when the tracker's own rule says so
// (shouldSearch: every redetect_every images, or 2/3 of the last search's corners lost),
// LK in between, same pyramid and window, no ids, no checks, no matching.
std::vector<double> timeBaselineTracker(const std::vector<cv::Mat>& images, int features) {
  const TrackerParams p;
  std::vector<double> t;
  std::vector<cv::Point2f> points;
  int found_at_search = 0, since_search = 0;
  cv::Mat previous;
  for (size_t k = 0; k < images.size(); ++k) {
    const auto start = Clock::now();
    if (k == 0 ||
        shouldSearch(found_at_search, static_cast<int>(points.size()), ++since_search, p)) {
      cv::goodFeaturesToTrack(images[k], points, features, p.quality_level, p.min_distance_px);
      found_at_search = static_cast<int>(points.size());
      since_search = 0;
    } else {
      std::vector<cv::Point2f> next;
      std::vector<uchar> status;
      std::vector<float> error;
      cv::calcOpticalFlowPyrLK(previous, images[k], points, next, status, error,
                               cv::Size(p.window_size_px, p.window_size_px), p.pyramid_levels - 1);
      points.clear();
      for (size_t i = 0; i < next.size(); ++i)
        if (status[i]) points.push_back(next[i]);
    }
    previous = images[k];
    t.push_back(msSince(start));
  }
  return t;
}

struct PlaneRow {
  int points;
  Stats ours, ours_nodelet, baseline;
  double our_error, nodelet_error, baseline_error;  // misclassification, %
};

PlaneRow benchPlanes(int points, int repeats, const std::string& coplanarity_test) {
  PlaneRow row{points, {}, {}, {}, 0, 0, 0};
  std::vector<double> ours, nodelet, base;
  for (int r = 0; r < repeats; ++r) {
    TwoViewSceneParams sp;
    sp.planes = 3;
    sp.outlier_fraction = 0.2;
    sp.points_per_plane = static_cast<int>(points * 0.8 / 3);
    sp.seed = 100 + r;
    const auto scene = makeTwoViewScene(sp);
    PlaneParams params;
    params.vote_threshold_px = 4.0 * sp.noise_px;
    params.groups.coplanarity_test = coplanarity_test;
    double start = threadCpuMs();
    const auto result = segmentPlanes(scene.view1, scene.view2, params);
    ours.push_back(threadCpuMs() - start);
    // The plane nodelet's setting (config/planes.yaml): 100 coplanar groups per image.
    PlaneParams fewer = params;
    fewer.groups.max_groups = 100;
    start = threadCpuMs();
    const auto fewer_result = segmentPlanes(scene.view1, scene.view2, fewer);
    nodelet.push_back(threadCpuMs() - start);
    start = threadCpuMs();
    const auto labels = sequentialMagsac(scene.view1, scene.view2, params.vote_threshold_px,
                                         params.min_plane_support, params.max_planes);
    base.push_back(threadCpuMs() - start);
    row.our_error += 100 * misclassificationError(scene.labels, result.labels) / repeats;
    row.nodelet_error += 100 * misclassificationError(scene.labels, fewer_result.labels) / repeats;
    row.baseline_error += 100 * misclassificationError(scene.labels, labels) / repeats;
  }
  row.ours = stats(ours);
  row.ours_nodelet = stats(nodelet);
  row.baseline = stats(base);
  return row;
}

// Time against points, both stages, ours solid and baselines dashed (log-free, linear).
void plot(const std::vector<PlaneRow>& planes,
          const std::vector<std::pair<int, std::pair<double, double>>>& tracker,
          const std::string& path) {
  const int w = 720, h = 420, left = 60, bottom = 50, top = 40, right = 20;
  cv::Mat img(h, w, CV_8UC3, cv::Scalar(255, 255, 255));
  double max_ms = 1;
  for (const auto& r : planes) max_ms = std::max({max_ms, r.ours.mean, r.baseline.mean});
  for (const auto& r : tracker) max_ms = std::max({max_ms, r.second.first, r.second.second});
  const double max_points = 1000;
  auto at = [&](double points, double ms) {
    return cv::Point(cvRound(left + (w - left - right) * points / max_points),
                     cvRound(h - bottom - (h - bottom - top) * ms / (1.1 * max_ms)));
  };
  cv::line(img, at(0, 0), at(max_points, 0), {0, 0, 0});
  cv::line(img, at(0, 0), at(0, 1.1 * max_ms), {0, 0, 0});
  for (int p = 0; p <= 1000; p += 250)
    cv::putText(img, std::to_string(p), at(p, 0) + cv::Point(-10, 18), cv::FONT_HERSHEY_SIMPLEX,
                0.4, {0, 0, 0});
  for (int k = 0; k <= 4; ++k) {
    const double ms = 1.1 * max_ms * k / 4;
    cv::putText(img, cv::format("%.0f", ms), at(0, ms) + cv::Point(-40, 4),
                cv::FONT_HERSHEY_SIMPLEX, 0.4, {0, 0, 0});
  }
  auto series = [&](const std::vector<cv::Point>& pts, const cv::Scalar& colour, bool dashed) {
    for (size_t i = 1; i < pts.size(); ++i) {
      if (!dashed) {
        cv::line(img, pts[i - 1], pts[i], colour, 2, cv::LINE_AA);
        continue;
      }
      for (double s = 0; s < 1; s += 0.1)
        cv::line(img, pts[i - 1] + (pts[i] - pts[i - 1]) * s,
                 pts[i - 1] + (pts[i] - pts[i - 1]) * (s + 0.05), colour, 2, cv::LINE_AA);
    }
    for (const auto& p : pts) cv::circle(img, p, 3, colour, cv::FILLED);
  };
  std::vector<cv::Point> po, pb, to, tb;
  for (const auto& r : planes) {
    po.push_back(at(r.points, r.ours.mean));
    pb.push_back(at(r.points, r.baseline.mean));
  }
  for (const auto& r : tracker) {
    to.push_back(at(r.first, r.second.first));
    tb.push_back(at(r.first, r.second.second));
  }
  series(po, {200, 0, 0}, false);
  series(pb, {200, 0, 0}, true);
  series(to, {0, 0, 200}, false);
  series(tb, {0, 0, 200}, true);
  cv::putText(img, "ms per frame vs points (640x480 for tracking), one thread", {left, 20},
              cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1, cv::LINE_AA);
  cv::putText(img, "blue: planes (ours solid, sequential MAGSAC dashed)", {left, h - 22},
              cv::FONT_HERSHEY_SIMPLEX, 0.4, {200, 0, 0}, 1, cv::LINE_AA);
  cv::putText(img, "red: tracker (ours solid, GFTT + LK dashed)", {left, h - 8},
              cv::FONT_HERSHEY_SIMPLEX, 0.4, {0, 0, 200}, 1, cv::LINE_AA);
  cv::imwrite(path, img);
}

// Start-up target search per 640x480 rendered view (the room along the wheeled path, the
// sheet in view in the first images, not later): the sheet detector, the ArUco detector
// (no marker in view: its full search) and the plain baseline every quadrilateral search
// starts from (Otsu, contours, approxPolyDP, convexity).
void benchTargets(int views) {
  RoomParams room;
  const IndoorScene scene = makeRoom(room);
  RenderOptions options;
  options.noise_sigma = 2;
  const CameraModel camera;
  const SceneRenderer renderer(scene, camera, options);
  TrajectoryParams path;
  std::vector<cv::Mat> images;
  for (int i = 0; i < views; ++i)
    images.push_back(renderer.render(trajectoryPose(path, 10.0 * i / views), i));
  TargetParams marker;
  marker.target_type = "aruco";
  std::vector<double> sheet_ms, marker_ms, base_ms;
  int found = 0;
  for (const cv::Mat& image : images) {
    auto start = Clock::now();
    found += detectTarget(image, TargetParams(), camera.fx).found ? 1 : 0;
    sheet_ms.push_back(msSince(start));
    start = Clock::now();
    detectConfiguredTarget(image, marker);
    marker_ms.push_back(msSince(start));
    start = Clock::now();
    cv::Mat binary;
    cv::threshold(image, binary, 0, 255, cv::THRESH_BINARY | cv::THRESH_OTSU);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(binary, contours, cv::RETR_LIST, cv::CHAIN_APPROX_SIMPLE);
    int quads = 0;
    for (const auto& c : contours) {
      std::vector<cv::Point> q;
      cv::approxPolyDP(c, q, 0.03 * cv::arcLength(c, true), true);
      quads += q.size() == 4 && cv::isContourConvex(q);
    }
    base_ms.push_back(msSince(start) + 0 * quads);
  }
  // After confirmation (TargetStartup, redetect_tracked): the sheet found again only in
  // the region around its tracked corners, on the images that show it, vs the whole image.
  std::vector<double> follow_ms;
  int reanchored = 0;
  {
    TargetParams once;
    once.confirm_frames = 1;
    FeatureTracker tracker;
    TargetStartup startup(once);
    for (const cv::Mat& image : images) {
      tracker.process(image);
      const bool confirmed = startup.found();  // every call after confirmation is timed
      auto start = Clock::now();
      startup.process(image, tracker, camera.fx);
      if (!confirmed) continue;
      follow_ms.push_back(msSince(start));
      reanchored += startup.reanchored();
    }
  }
  const size_t followed = follow_ms.size();
  if (follow_ms.empty()) follow_ms.push_back(0);
  const Stats follow = stats(follow_ms);
  const Stats sheet = stats(sheet_ms), aruco = stats(marker_ms), base = stats(base_ms);
  std::printf(
      "\nStart-up target search, 640x480 rendered views (%d, sheet found in %d), ms per\n"
      "image mean / p95:\n"
      "  sheet (ours)              %6.2f / %6.2f\n"
      "  aruco (OpenCV, no marker) %6.2f / %6.2f\n"
      "  baseline (Otsu + contours + approxPolyDP) %6.2f / %6.2f\n",
      views, found, sheet.mean, sheet.p95, aruco.mean, aruco.p95, base.mean, base.p95);
  std::printf(
      "  sheet re-detected around its tracked corners (%zu images after confirmation, "
      "tracks moved in %d) %6.2f / %6.2f\n",
      followed, reanchored, follow.mean, follow.p95);
}

}  // namespace

int main(int argc, char** argv) {
  int count = 100, repeats = 20;
  bool planes_only = false;
  int only_points = 0;
  std::string plot_path = "benchmark.png";
  std::string coplanarity_test = PlaneParams().groups.coplanarity_test;
  cli::Parser cli("benchmark_suite", "[options]",
                  "  The benchmark suite: tracker and plane segmentation, ours against\n"
                  "  baselines, with a plot. Figures, never pass/fail.");
  cli.integer("frames", &count, 20, 100000, "generated frames per tracker row")
      .integer("repeats", &repeats, 1, 10000, "scenes per plane row")
      .text("plot", &plot_path, "where to write the plot", "FILE.png")
      .flag("planes-only", &planes_only, "only the plane rows (no tracker, no target search)")
      .integer("points", &only_points, 0, 100000,
               "only the plane row of this many points (0: all)")
      .choice("coplanarity-test", &coplanarity_test, {"transfer", "cross_ratio"},
              "the plane rows' five-point coplanarity test");
  if (const auto code = cli.parse(argc, argv)) return *code;
  cv::setNumThreads(1);
  std::printf(
      "benchmark_suite: one thread; %d generated frames per tracker row, %d scenes per "
      "plane row.\n\n",
      count, repeats);
  if (!planes_only) {
    std::printf(
        "Tracker (ours) against goodFeaturesToTrack + calcOpticalFlowPyrLK (baseline),\n"
        "ms per frame, mean / p95:\n");
    std::printf("  %-10s %6s %16s %16s %8s\n", "image", "feat.", "ours", "baseline", "ratio");
  }
  std::vector<std::pair<int, std::pair<double, double>>> tracker_vga;
  const std::vector<cv::Size> sizes =
      planes_only ? std::vector<cv::Size>{}
                  : std::vector<cv::Size>{{320, 240}, {640, 480}, {1280, 720}};
  for (const cv::Size size : sizes) {
    const std::vector<cv::Mat> images = frames(size, count);
    for (int features : {50, 150, 500}) {
      const Stats ours = stats(timeTracker(images, features));
      const Stats base = stats(timeBaselineTracker(images, features));
      std::printf("  %4dx%-5d %6d %7.2f / %6.2f %7.2f / %6.2f %7.2fx\n", size.width, size.height,
                  features, ours.mean, ours.p95, base.mean, base.p95, ours.mean / base.mean);
      if (size.width == 640) tracker_vga.push_back({features, {ours.mean, base.mean}});
    }
  }
  std::printf(
      "\nPlane stage (segmentPlanes) against sequential MAGSAC (cv::findHomography\n"
      "USAC_MAGSAC, remove inliers, repeat), 3 planes, 20 %% outliers, 0.7 px noise,\n"
      "threshold 2.8 px. Thread CPU ms per frame mean / p95, misclassification error:\n");
  std::printf("  ours: core defaults (300 groups); nodelet: 100 groups as config/planes.yaml; "
              "both with coplanarity test %s\n",
              coplanarity_test.c_str());
  std::printf("  %6s %15s %15s %15s %7s %7s %9s %9s %9s\n", "points", "ours", "nodelet", "baseline",
              "ratio", "ratio n", "ours err", "nod. err", "base err");
  std::vector<PlaneRow> rows;
  for (int points : {50, 200, 500, 1000}) {
    if (only_points > 0 && points != only_points) continue;
    const PlaneRow r = benchPlanes(points, repeats, coplanarity_test);
    rows.push_back(r);
    std::printf(
        "  %6d %6.2f / %6.2f %6.2f / %6.2f %6.2f / %6.2f %6.2fx %6.2fx %8.1f%% %8.1f%% %8.1f%%\n",
        r.points, r.ours.mean, r.ours.p95, r.ours_nodelet.mean, r.ours_nodelet.p95, r.baseline.mean,
        r.baseline.p95, r.ours.mean / r.baseline.mean, r.ours_nodelet.mean / r.baseline.mean,
        r.our_error, r.nodelet_error, r.baseline_error);
  }
  if (!planes_only) benchTargets(std::max(20, count / 2));
  plot(rows, tracker_vga, plot_path);
  std::printf("\nplot: %s\n", plot_path.c_str());
  return 0;
}
