// detect_target: checks a printed start-up target and a camera before a run.
//   detect_target [--target-type sheet|aruco] [--json] IMAGE...
// Prints, per image file, the target's four corners in the map frame's corner order
// (pixels) or `none` and the reason the detector gives (docs/start_up.md).
#include <cstdio>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "cli_args.h"
#include "config_dir.h"
#include "profile.h"
#include "mono_plane_detection/tracking/marker_target.h"
#include "mono_plane_detection/tracking/target_detector.h"

using namespace mono_plane_detection;

namespace {

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\u%04x", c);
      out += buffer;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

int main(int argc, char** argv) {
  auto profile =
      readToolProfile(argc, argv, toolConfigDir(MPD_CONFIG_DIR), "tracker", trackerNodeParamTable(), std::string("default"));
  TargetParams params = profile.params.target;
  std::vector<std::string> images;
  bool json = false;
  double focal_px = 0;
  cli::Parser cli(
      "detect_target", "[options] IMAGE...",
      "  Finds the start-up target (white sheet on a darker surface, or an ArUco marker) in\n"
      "  each image file, as the tracker nodelet does.",
      "output: per image 'IMAGE: x0 y0 x1 y1 x2 y2 x3 y3' (pixels, the map frame's corner\n"
      "  order: (-w/2,-h/2) (+w/2,-h/2) (+w/2,+h/2) (-w/2,+h/2), docs/start_up.md) or\n"
      "  'IMAGE: none (reason)'; --json: one array of objects.\n"
      "exit codes: 0 ran (found or not), 2 bad usage or an unreadable image\n");
  cli.positionals("IMAGE", &images, "image files (any format OpenCV reads)")
      .text("profile", &profile.name, profileHelp("tracker"), "P")
      .choice("target-type", &params.target_type, {"sheet", "aruco"}, "which target")
      .number("width-m", &params.width_m, 0.01, 10, "sheet: longer side, metres", "M")
      .number("height-m", &params.height_m, 0.01, 10, "sheet: shorter side, metres", "M")
      .number("focal-px", &focal_px, 0, 1e6,
              "sheet: the camera's focal length, pixels (0: unknown, estimated)", "PX")
      .text("dictionary", &params.dictionary, "aruco: OpenCV dictionary name", "NAME")
      .integer("marker-id", &params.marker_id, 0, 999, "aruco: the marker's id", "ID")
      .number("marker-size-m", &params.marker_size_m, 0.005, 10,
              "aruco: side of the black square, metres", "M")
      .flag("json", &json, "print JSON");
  if (const auto code = cli.parse(argc, argv)) return *code;
  if (!profile.errors.empty()) return cli.fail(profile.errors.front());
  if (const std::string error = targetParamsError(params); !error.empty()) return cli.fail(error);

  int exit_code = 0;
  if (json) std::printf("[");
  bool first = true;
  for (const std::string& path : images) {
    const cv::Mat gray = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (gray.empty()) {
      std::fprintf(stderr, "detect_target: cannot read image %s\n", path.c_str());
      exit_code = cli::kExitUsage;
      continue;
    }
    const TargetDetection d = detectConfiguredTarget(gray, params, focal_px);
    if (json) {
      std::printf("%s\n  {\"image\": %s, \"width\": %d, \"height\": %d, \"found\": %s", first ? "" : ",",
                  jsonString(path).c_str(), gray.cols, gray.rows, d.found ? "true" : "false");
      if (d.found) {
        std::printf(", \"corners\": [");
        for (int i = 0; i < 4; ++i)
          std::printf("%s[%.3f, %.3f]", i ? ", " : "", d.corners[i].x, d.corners[i].y);
        std::printf("]");
        if (params.target_type == "sheet")
          std::printf(", \"surround_ratio\": %.3f", d.surround_ratio);
      } else {
        std::printf(", \"rejection\": %s, \"reason\": %s", jsonString(toString(d.rejection)).c_str(),
                    jsonString(d.reason).c_str());
      }
      std::printf("}");
    } else if (d.found) {
      std::printf("%s:", path.c_str());
      for (const auto& c : d.corners) std::printf(" %.2f %.2f", c.x, c.y);
      std::printf("\n");
    } else {
      std::printf("%s: none (%s: %s)\n", path.c_str(), toString(d.rejection), d.reason.c_str());
    }
    first = false;
  }
  if (json) std::printf("%s]\n", first ? "" : "\n");
  return exit_code;
}
