// eval_two_view: the plane core against sequential MAGSAC on labelled two-view scenes
// (AdelaideRMF: SCENE.txt + SCENE.labels in a folder), in one run: misclassification per
// scene over several seeds and the time per scene, core alone (no process start-up).
//   eval_two_view [options] FOLDER
#include <algorithm>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_args.h"
#include "thread_cpu_time.h"
#include "mono_plane_detection/eval/segmentation_error.h"
#include "mono_plane_detection/eval/sequential_magsac.h"
#include "mono_plane_detection/planes/correspondence_io.h"
#include "mono_plane_detection/planes/homography_voting.h"
#include "mono_plane_detection/sim/synthetic_two_view.h"

using namespace mono_plane_detection;
namespace fs = std::filesystem;

namespace {

// One integer per line, '#' comments; empty on a malformed line.
std::vector<int> readLabels(const std::string& path, std::string& error) {
  std::ifstream in(path);
  std::vector<int> labels;
  if (!in) {
    error = "cannot open " + path;
    return {};
  }
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    line = line.substr(0, line.find('#'));
    std::istringstream fields(line);
    int label;
    if (!(fields >> label)) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      error = path + ":" + std::to_string(n) + ": not a label";
      return {};
    }
    labels.push_back(label);
  }
  return labels;
}

struct Scene {
  std::string name;
  Correspondences points;
  std::vector<int> truth;
};

}  // namespace

int main(int argc, char** argv) {
  PlaneParams params;
  std::string folder;
  int seeds = 5, repeats = 3;
  double magsac_threshold = 3.0;
  bool per_seed = false;
  cli::Parser cli("eval_two_view", "[options] FOLDER",
                  "  The plane core (segmentPlanes, default settings unless given) against\n"
                  "  sequential MAGSAC++ on every SCENE.txt + SCENE.labels of FOLDER (e.g. the\n"
                  "  AdelaideRMF scenes): misclassification error per scene (best one-to-one\n"
                  "  matching of found to true planes, outliers a class of their own), mean and\n"
                  "  worst over the seeds, and CPU ms per scene (core only, one thread).",
                  "exit codes: 0 done, 2 bad usage or input\n");
  cli.positional("FOLDER", &folder, "folder of SCENE.txt + SCENE.labels")
      .integer("seeds", &seeds, 1, 1000, "group seeds 1..N per scene")
      .integer("repeats", &repeats, 1, 1000, "timed runs per seed (the time is their mean)")
      .number("threshold", &params.vote_threshold_px, 0.0, 1e3,
              "core: inlier threshold, pixels; 0 = estimated (default)", "PX")
      .choice("coplanarity-test", &params.groups.coplanarity_test, {"transfer", "cross_ratio"},
              "core: five-point coplanarity test")
      .integer("max-groups", &params.groups.max_groups, 1, 100000,
               "core: coplanar groups kept per image pair")
      .integer("tries-per-point", &params.groups.tries_per_point, 1, 100000,
               "core: groups tried per point at most")
      .integer("fifth-points", &params.groups.fifth_points, 1, 100,
               "core: groups per four points drawn (the seed's other neighbours as fifth)")
      .integer("pilot-groups", &params.noise_pilot_groups, 1, 1000,
               "core: candidate first planes the noise scale is taken from")
      .integer("min-tries", &params.groups.min_tries, 1, 100000,
               "core: groups tried at least (when points x tries-per-point is fewer)")
      .flag("no-epipolar-check", &params.epipolar_check,
            "core: keep planes whose points are off the epipolar lines of the planes' F", false)
      .number("magsac-threshold", &magsac_threshold, 0.01, 1e3,
              "sequential MAGSAC++: its threshold (maximum sigma), pixels", "PX")
      .flag("per-seed", &per_seed, "print every seed's error, groups, true -> found plane counts");
  if (const auto code = cli.parse(argc, argv)) return *code;

  std::error_code ec;
  if (!fs::is_directory(folder, ec)) return cli.fail(folder + " is not a folder");
  std::vector<Scene> scenes;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (entry.path().extension() != ".labels") continue;
    fs::path txt = entry.path();
    txt.replace_extension(".txt");
    if (!fs::exists(txt)) continue;
    Scene s;
    s.name = entry.path().stem().string();
    std::ifstream in(txt);
    s.points = readCorrespondences(in);
    if (!s.points.error.empty()) return cli.fail(txt.string() + ": " + s.points.error);
    std::string error;
    s.truth = readLabels(entry.path().string(), error);
    if (!error.empty()) return cli.fail(error);
    if (s.truth.size() != s.points.view1.size())
      return cli.fail(s.name + ": " + std::to_string(s.truth.size()) + " labels for " +
                      std::to_string(s.points.view1.size()) + " points");
    scenes.push_back(std::move(s));
  }
  if (scenes.empty()) return cli.fail("no SCENE.txt + SCENE.labels in " + folder);
  std::sort(scenes.begin(), scenes.end(),
            [](const Scene& a, const Scene& b) { return a.name < b.name; });

  cv::setNumThreads(1);
  std::printf("eval_two_view: %zu scenes, seeds 1..%d, coplanarity test %s, threshold %s\n",
              scenes.size(), seeds, params.groups.coplanarity_test.c_str(),
              params.vote_threshold_px > 0 ? cv::format("%.2f px", params.vote_threshold_px).c_str()
                                           : "estimated");
  std::printf("%-14s %6s %6s %6s %8s %8s %8s %9s %9s %9s\n", "scene", "points", "planes",
              "found", "noise px", "err %", "worst %", "ms", "magsac %", "magsac ms");
  double sum_err = 0, sum_ms = 0, sum_magsac = 0, sum_magsac_ms = 0, worst_all = 0;
  for (const Scene& s : scenes) {
    const auto& v1 = s.points.view1;
    const auto& v2 = s.points.view2;
    double err = 0, worst = 0, ms = 0, noise = 0, found = 0;
    std::string per;
    for (int seed = 1; seed <= seeds; ++seed) {
      PlaneParams p = params;
      p.groups.seed = static_cast<unsigned>(seed);
      PlaneSegmentation result;
      const double start = threadCpuMs();
      for (int r = 0; r < repeats; ++r) result = segmentPlanes(v1, v2, p);
      ms += (threadCpuMs() - start) / repeats / seeds;
      const double e = 100.0 * misclassificationError(s.truth, result.labels);
      err += e / seeds;
      worst = std::max(worst, e);
      noise += result.noise_px / seeds;
      found += static_cast<double>(result.planes.size()) / seeds;
      per += cv::format("\n    seed %d: %.2f %% (groups %d coplanar of %d tried), true -> found:",
                        seed, e, result.groups_coplanar, result.groups_built);
      // Which true plane went where: a split or a merge shows as one row spread over two
      // columns or two rows in one column.
      const int true_planes = *std::max_element(s.truth.begin(), s.truth.end());
      for (int t = 0; t <= true_planes; ++t) {
        std::vector<int> row(result.planes.size() + 1, 0);
        for (size_t i = 0; i < s.truth.size(); ++i)
          if (s.truth[i] == t) ++row[static_cast<size_t>(result.labels[i])];
        per += cv::format(" %d:[", t);
        for (size_t f = 0; f < row.size(); ++f) per += cv::format(f ? " %d" : "%d", row[f]);
        per += "]";
      }
      per += cv::format(", noise %.3f px, planes' scales", result.noise_px);
      for (const HomographyPlane& plane : result.planes) per += cv::format(" %.3f", plane.noise_px);
    }
    std::vector<int> magsac;
    const double start = threadCpuMs();
    for (int r = 0; r < repeats; ++r)
      magsac = sequentialMagsac(v1, v2, magsac_threshold, params.min_plane_support,
                                params.max_planes);
    const double magsac_ms = (threadCpuMs() - start) / repeats;
    const double magsac_err = 100.0 * misclassificationError(s.truth, magsac);
    const int planes = *std::max_element(s.truth.begin(), s.truth.end());
    std::printf("%-14s %6zu %6d %6.1f %8.3f %8.2f %8.2f %9.2f %9.2f %9.2f\n", s.name.c_str(),
                v1.size(), planes, found, noise, err, worst, ms, magsac_err, magsac_ms);
    if (per_seed) std::printf("  per seed (outliers are label 0):%s\n", per.c_str());
    sum_err += err;
    sum_ms += ms;
    sum_magsac += magsac_err;
    sum_magsac_ms += magsac_ms;
    worst_all = std::max(worst_all, worst);
  }
  const double n = static_cast<double>(scenes.size());
  std::printf("%-14s %6s %6s %6s %8s %8.2f %8.2f %9.2f %9.2f %9.2f\n", "mean", "", "", "", "",
              sum_err / n, worst_all, sum_ms / n, sum_magsac / n, sum_magsac_ms / n);
  return 0;
}
