// segment_planes: every dominant plane in two-view correspondences.
//   segment_planes [options] FILE|-      one "x1 y1 x2 y2" per line, '#' comments
// Prints one label per input correspondence (0 = no plane, k = plane k by support),
// or with --json the planes with homographies and inliers.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

#include "cli_args.h"
#include "mono_plane_detection/planes/correspondence_io.h"
#include "mono_plane_detection/planes/homography_voting.h"

using namespace mono_plane_detection;

namespace {

const char* kUsage =
    "usage: segment_planes [options] FILE|-\n"
    "  Finds every dominant plane (homography) in two-view correspondences.\n"
    "  FILE: one correspondence per line 'x1 y1 x2 y2' (pixels, view 1 then view 2),\n"
    "        '#' starts a comment; '-' reads standard input.\n"
    "  Output: one integer per correspondence, in order: 0 = no plane, k >= 1 = plane k\n"
    "          (planes numbered by support, largest first).\n"
    "options:\n"
    "  --threshold PX     transfer error for a point to vote / belong (default 2.0)\n"
    "  --max-planes K     at most K planes (default 8)\n"
    "  --min-support N    a plane needs at least N points (default 8)\n"
    "  --invariant-threshold T  five-point invariant agreement (default 0.1)\n"
    "  --seed S           seed of the group choice (default 1)\n"
    "  --json             print planes (homography, inliers, rms error) instead of labels\n"
    "  --help             this text\n"
    "exit codes: 0 done (fewer than 5 points: all labels 0), 2 bad usage or input\n";

void printJson(const PlaneSegmentation& result, size_t points) {
  std::printf(
      "{\n  \"points\": %zu,\n  \"groups_built\": %d,\n  \"groups_coplanar\": %d,\n  \"planes\": [",
      points, result.groups_built, result.groups_coplanar);
  for (size_t k = 0; k < result.planes.size(); ++k) {
    const Plane& p = result.planes[k];
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
  auto fail = [](const std::string& what) { return usageError("segment_planes", what, kUsage); };
  PlaneParams params;
  bool json = false;
  std::string path;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    double d;
    long n;
    if (arg == "--help" || arg == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (arg == "--json") {
      json = true;
    } else if (arg == "--threshold") {
      const char* v = value();
      if (!v || !parseNumber(v, d) || d <= 0)
        return fail("--threshold needs a positive number of pixels");
      params.vote_threshold_px = d;
    } else if (arg == "--invariant-threshold") {
      const char* v = value();
      if (!v || !parseNumber(v, d) || d <= 0)
        return fail("--invariant-threshold needs a positive number");
      params.groups.invariant_threshold = d;
    } else if (arg == "--max-planes") {
      const char* v = value();
      if (!v || !parseInteger(v, n) || n < 1) return fail("--max-planes needs a whole number >= 1");
      params.max_planes = static_cast<int>(n);
    } else if (arg == "--min-support") {
      const char* v = value();
      if (!v || !parseInteger(v, n) || n < 4)
        return fail("--min-support needs a whole number >= 4");
      params.min_plane_support = static_cast<int>(n);
    } else if (arg == "--seed") {
      const char* v = value();
      if (!v || !parseInteger(v, n) || n < 0) return fail("--seed needs a whole number >= 0");
      params.groups.seed = static_cast<unsigned>(n);
    } else if (arg.size() > 1 && arg[0] == '-' && arg != "-") {
      return fail("unknown option " + arg);
    } else if (path.empty()) {
      path = arg;
    } else {
      return fail("more than one input file");
    }
  }
  if (path.empty()) return fail("no input file");

  Correspondences input;
  if (path == "-") {
    input = readCorrespondences(std::cin);
  } else {
    std::ifstream file(path);
    if (!file) {
      std::fprintf(stderr, "segment_planes: cannot open %s\n", path.c_str());
      return 2;
    }
    input = readCorrespondences(file);
  }
  if (!input.error.empty()) {
    std::fprintf(stderr, "segment_planes: %s: %s\n", path.c_str(), input.error.c_str());
    return 2;
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
