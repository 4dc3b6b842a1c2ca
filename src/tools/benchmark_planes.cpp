// Plane-stage figures: time of segmentPlanes for 50-1000 tracked points and its error,
// on generated two-view scenes (3 planes, 0.7 px noise, 20 % outliers). One thread.
// Prints a table; it is a measurement, not a test.
//   rosrun mono_plane_detection benchmark_planes [--repeats N]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "mono_plane_detection/homography_voting.h"
#include "mono_plane_detection/synthetic_two_view.h"

using namespace mono_plane_detection;

int main(int argc, char** argv) {
  int repeats = 20;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc)
      repeats = std::max(1, std::atoi(argv[++i]));
    if (!std::strcmp(argv[i], "--help")) {
      std::printf("usage: benchmark_planes [--repeats N]\n");
      return 0;
    }
  }
  std::printf(
      "benchmark_planes: segmentPlanes on generated scenes, 3 planes, 0.7 px noise,\n"
      "20 %% outliers, threshold 2.8 px; %d scenes per row, one thread.\n\n",
      repeats);
  std::printf("  %8s %10s %10s %10s %10s %8s\n", "points", "mean ms", "p95 ms", "error %", "groups",
              "planes");
  for (int points : {50, 200, 500, 1000}) {
    std::vector<double> times;
    double error = 0, groups = 0, planes = 0;
    for (int r = 0; r < repeats; ++r) {
      TwoViewSceneParams sp;
      sp.planes = 3;
      sp.outlier_fraction = 0.2;
      sp.points_per_plane = static_cast<int>(points * 0.8 / 3);
      sp.seed = 100 + r;
      const auto scene = makeTwoViewScene(sp);
      PlaneParams params;
      params.vote_threshold_px = 4.0 * sp.noise_px;
      const auto start = std::chrono::steady_clock::now();
      const auto result = segmentPlanes(scene.view1, scene.view2, params);
      times.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count());
      error += misclassificationError(scene.labels, result.labels) / repeats;
      groups += static_cast<double>(result.groups_coplanar) / repeats;
      planes += static_cast<double>(result.planes.size()) / repeats;
    }
    std::sort(times.begin(), times.end());
    double mean = 0;
    for (double t : times) mean += t / times.size();
    std::printf("  %8d %10.2f %10.2f %10.2f %10.0f %8.1f\n", points, mean,
                times[std::min(times.size() - 1, times.size() * 95 / 100)], 100 * error, groups,
                planes);
  }
  return 0;
}
