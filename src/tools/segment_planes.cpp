// segment_planes: every dominant plane in two-view correspondences.
//   segment_planes [options] FILE|-      one "x1 y1 x2 y2" per line, '#' comments
// Prints one label per input correspondence (0 = no plane, k = plane k by support),
// or with --json the planes with homographies and inliers.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "cli_args.h"
#include "config_dir.h"
#include "profile.h"
#include "mono_plane_detection/planes/correspondence_io.h"
#include "mono_plane_detection/planes/homography_voting.h"

using namespace mono_plane_detection;

namespace {

void printJson(const PlaneSegmentation& result, size_t points) {
  std::printf(
      "{\n  \"points\": %zu,\n  \"noise_px\": %.6f,\n  \"threshold_px\": %.6f,\n"
      "  \"groups_built\": %d,\n  \"groups_coplanar\": %d,\n  \"planes\": [",
      points, result.noise_px, result.threshold_px, result.groups_built, result.groups_coplanar);
  for (size_t k = 0; k < result.planes.size(); ++k) {
    const HomographyPlane& p = result.planes[k];
    std::printf(
        "%s\n    {\"id\": %zu, \"support\": %zu, \"score\": %.6f, \"rms_error_px\": %.6f,\n"
        "     \"homography\": [[%.10g, %.10g, %.10g], [%.10g, %.10g, %.10g], [%.10g, %.10g, "
        "%.10g]],\n"
        "     \"inliers\": [",
        k ? "," : "", k + 1, p.inliers.size(), p.score, p.rms_error_px, p.H(0, 0), p.H(0, 1),
        p.H(0, 2), p.H(1, 0), p.H(1, 1), p.H(1, 2), p.H(2, 0), p.H(2, 1), p.H(2, 2));
    for (size_t i = 0; i < p.inliers.size(); ++i) std::printf("%s%d", i ? ", " : "", p.inliers[i]);
    std::printf("]}");
  }
  std::printf("\n  ]\n}\n");
}

}  // namespace

int main(int argc, char** argv) {
  auto profile =
      readToolProfile(argc, argv, toolConfigDir(MPD_CONFIG_DIR), "planes", planeNodeParamTable(), std::string("none"));
  PlaneParams params = profile.params.pipeline.planes;
  bool json = false;
  std::string path;
  cli::Parser cli("segment_planes", "[options] FILE|-",
                  "  Finds every dominant plane (homography) in two-view correspondences.",
                  "input: one correspondence per line 'x1 y1 x2 y2' (pixels, view 1 then view 2),\n"
                  "  '#' starts a comment; lines longer than " +
                      std::to_string(kMaxCorrespondenceLineBytes) + " bytes are refused.\n"
                  "output: one integer per correspondence, in order: 0 = no plane, k >= 1 = plane k\n"
                  "  (planes numbered by support, largest first).\n"
                  "exit codes: 0 done (fewer than 5 points: all labels 0), 2 bad usage or input\n");
  cli.positional("FILE", &path, "the correspondences; '-' reads standard input")
      .text("profile", &profile.name, profileHelp("planes"), "P")
      .number("threshold", &params.vote_threshold_px, 0.0, 1e3,
              "transfer error for a point to vote / belong, pixels; 0 = estimate the noise "
              "scale from the data (default)", "PX")
      .number("inlier-sigmas", &params.inlier_threshold_sigma, 0.5, 50.0,
              "with --threshold 0: a point belongs within this many noise scales", "K")
      .number("vote-sigmas", &params.vote_threshold_sigma, 0.5, 50.0,
              "with --threshold 0: the vote counts within this many noise scales", "K")
      .number("transfer-sigmas", &params.groups.transfer_threshold_sigma, 0.1, 1000.0,
              "transfer coplanarity test: fifth point within this many noise scales", "K")
      .number("plane-penalty", &params.plane_penalty, 0.0, 1000.0,
              "model selection: a plane costs this x ln(points) squared noise scales", "P")
      .choice("coplanarity-test", &params.groups.coplanarity_test, {"transfer", "cross_ratio"},
              "five-point coplanarity test")
      .flag("no-epipolar-check", &params.epipolar_check,
            "keep planes whose points are off the epipolar lines of the planes' F", false)
      .integer("max-planes", &params.max_planes, 1, 1000, "at most K planes", "K")
      .integer("min-support", &params.min_plane_support, 5, 100000,
               "a plane needs at least N points (planes/min_plane_support's range)")
      .number("invariant-threshold", &params.groups.invariant_threshold, 1e-6, 10.0,
              "five-point invariant agreement", "T")
      .integer<unsigned>("seed", &params.groups.seed, 0, std::numeric_limits<unsigned>::max(),
                         "seed of the group choice", "S")
      .flag("json", &json, "print planes (homography, inliers, rms error) instead of labels");
  if (const auto code = cli.parse(argc, argv)) return *code;
  if (!profile.errors.empty()) return cli.fail(profile.errors.front());

  Correspondences input;
  if (path == "-") {
    input = readCorrespondences(std::cin);
  } else {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      return cli.fail(path + " is a directory, not a file of correspondences");
    std::ifstream file(path);
    if (!file) return cli.fail("cannot open " + path);
    input = readCorrespondences(file);
    if (file.bad()) return cli.fail("cannot read " + path);
  }
  if (!input.error.empty()) {
    std::fprintf(stderr, "segment_planes: %s: %s\n", path.c_str(), input.error.c_str());
    return cli::kExitUsage;
  }

  const PlaneSegmentation result = segmentPlanes(input.view1, input.view2, params);
  if (json) {
    printJson(result, input.view1.size());
  } else {
    std::string out;
    for (int label : result.labels) out += std::to_string(label) + "\n";
    std::fputs(out.c_str(), stdout);
  }
  return 0;
}
