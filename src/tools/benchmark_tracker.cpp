// Tracker figures on generated views with exact ground truth: accuracy and time per
// image for several windows, feature counts and the beyond-the-paper switches.
// Prints tables; it is a measurement, not a test.
//   rosrun mono_plane_detection benchmark_tracker [--frames N]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "cli_args.h"
#include "mono_plane_detection/tracking/feature_tracker.h"
#include "mono_plane_detection/sim/synthetic_views.h"
#include "mono_plane_detection/eval/track_scorer.h"

using namespace mono_plane_detection;

namespace {

struct Motion {
  std::string name;
  std::function<cv::Matx33d(int)> at;  // frame -> texture-to-view homography
};

const double kSensorNoise = 3.0;  // grey levels, per image, like a real sensor
const cv::Point2d kCentred(-180, -160);
const cv::Point2d kPivot(500, 400);  // texture centre

std::vector<Motion> motions() {
  return {
      {"easy",
       [](int k) { return similarity(0.002 * k, kPivot, kCentred + k * cv::Point2d(1.3, -0.7)); }},
      {"fast",
       [](int k) { return similarity(0.004 * k, kPivot, kCentred + k * cv::Point2d(6.0, 1.5)); }},
      // A walking robot's head: forward drift, step bob (~12 px at 2 Hz / 30 fps),
      // sway, roll wobble and a jerk every 25 images.
      {"humanoid",
       [](int k) {
         const double phase = 2 * CV_PI * k / 15.0;
         const double jerk = (k % 25 == 0 && k > 0) ? 10.0 : 0.0;
         const cv::Point2d bob(4.0 * std::sin(phase / 2) + jerk, 12.0 * std::sin(phase));
         return similarity(0.02 * std::sin(phase / 2), kPivot,
                           kCentred + k * cv::Point2d(1.0, 0.0) + bob, 1.0 + 0.001 * k);
       }},
  };
}

struct Result {
  double mean_error = 0, p95_error = 0, survival = 0, mean_ms = 0, p95_ms = 0;
};

Result run(const TrackerParams& params, const Motion& motion, const cv::Mat& texture,
           const cv::Size& view_size, int frames) {
  FeatureTracker tracker(params);
  TrackScorer score;
  std::vector<double> times;
  double tracked = 0, followed = 0;
  for (int k = 0; k < frames; ++k) {
    const cv::Matx33d H = motion.at(k);
    cv::Mat view = warpView(texture, H, view_size);
    cv::Mat noise(view.size(), CV_16S);
    cv::randn(noise, 0, kSensorNoise);
    view.convertTo(view, CV_16S);
    cv::Mat(view + noise).convertTo(view, CV_8U);  // saturates
    const auto start = std::chrono::steady_clock::now();
    const auto& points = tracker.process(view);
    times.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count());
    followed += tracker.previous().size();
    tracked += tracker.lastStats().tracked;
    score.observe(points, H);
  }
  Result r;
  r.mean_error = score.meanError();
  r.p95_error = percentile(score.errors(), 0.95);
  r.survival = followed > 0 ? tracked / followed : 0.0;
  for (double t : times) r.mean_ms += t / times.size();
  r.p95_ms = percentile(times, 0.95);
  return r;
}

void printRow(const std::string& label, const Result& r) {
  std::printf("  %-34s %8.3f %8.3f %9.1f%% %8.2f %8.2f\n", label.c_str(), r.mean_error, r.p95_error,
              100.0 * r.survival, r.mean_ms, r.p95_ms);
}

void printHeader(const char* title) {
  std::printf("\n%s\n  %-34s %8s %8s %10s %8s %8s\n", title, "", "err px", "p95 px", "kept/img",
              "ms", "p95 ms");
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 150;
  cli::Parser cli("benchmark_tracker", "[options]",
                  "  Tracker accuracy and time per image on generated views with exact ground\n"
                  "  truth, for several windows, feature counts and switches. Figures only.");
  cli.integer("frames", &frames, 2, 100000, "generated images per row");
  if (const auto code = cli.parse(argc, argv)) return *code;
  cv::setNumThreads(1);  // one core, as on the robot's budget
  const cv::Mat texture = makeCornerTexture({1400, 1100}, 42);
  const cv::Size vga(640, 480);
  std::printf(
      "benchmark_tracker: %d generated images per row, 640x480 unless stated, one thread.\n"
      "err = distance of a tracked point from where its texture pixel truly is,\n"
      "kept/img = share of points followed from one image to the next.\n"
      "Views carry Gaussian sensor noise of %.0f grey levels.\n",
      frames, kSensorNoise);

  printHeader("LK window size (50 features, all switches on)");
  for (const Motion& m : motions()) {
    for (int w : {3, 7, 11, 15, 21, 31}) {
      TrackerParams p;
      p.window_size_px = w;
      printRow(m.name + "  window " + std::to_string(w), run(p, m, texture, vga, frames));
    }
  }

  printHeader("Features (default window)");
  for (int n : {50, 150, 300}) {
    TrackerParams p;
    p.max_features = n;
    p.min_distance_px = n > 50 ? 10.0 : 15.0;
    printRow("easy  " + std::to_string(n) + " features",
             run(p, motions()[0], texture, vga, frames));
  }

  printHeader("Beyond-the-paper switches (humanoid motion, 50 features)");
  const std::vector<Motion> all_motions = motions();
  const Motion& walk = all_motions[2];
  TrackerParams paper;
  paper.window_size_px = 3;
  paper.forward_backward_check = paper.reanchor_on_search = false;
  paper.mask_existing = paper.reidentify = false;
  paper.spread_grid_columns = 0;
  paper.corner_noise_margin = 0;
  printRow("paper (3x3 window, all off)", run(paper, walk, texture, vga, frames));
  TrackerParams paper_fb = paper;
  paper_fb.forward_backward_check = true;
  printRow("paper + forward-backward check", run(paper_fb, walk, texture, vga, frames));
  TrackerParams all;
  printRow("all on (defaults)", run(all, walk, texture, vga, frames));
  TrackerParams p = all;
  p.forward_backward_check = false;
  printRow("without forward-backward check", run(p, walk, texture, vga, frames));
  p = all;
  p.reanchor_on_search = false;
  printRow("without re-anchoring", run(p, walk, texture, vga, frames));
  p = all;
  p.mask_existing = false;
  printRow("without search mask", run(p, walk, texture, vga, frames));
  p = all;
  p.reidentify = false;
  printRow("without re-identification", run(p, walk, texture, vga, frames));
  p = all;
  p.spread_grid_columns = 0;
  printRow("without spreading over cells", run(p, walk, texture, vga, frames));
  p = all;
  p.corner_noise_margin = 0;
  printRow("without the cells' own quality bar", run(p, walk, texture, vga, frames));
  return 0;
}
