// make_sequence: a synthetic indoor sequence with exact ground truth, as a rosbag.
//   rosrun mono_plane_detection make_sequence --trajectory humanoid --frames 300 --out seq.bag
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "../sim/bag/sequence_writer.h"
#include "cli_args.h"

using namespace mono_plane_detection;

namespace {

const char* kUsage =
    "usage: make_sequence [options] --out FILE.bag\n"
    "  Renders a room (floor, walls, ceiling, the start-up target) seen from a moving camera\n"
    "  and writes a rosbag with /camera/image_raw, /camera/camera_info and /tf (map ->\n"
    "  camera_gt), plus the ground truth (planes, target, poses in the map frame) as\n"
    "  FILE.yaml next to it.\n"
    "options (defaults in brackets):\n"
    "  --trajectory wheeled|humanoid|rotation [wheeled]   --frames N [300]   --fps F [30]\n"
    "  --speed MPS [0.3]   --turn DEG [150]   --seed S [1] (textures, humanoid jerks)\n"
    "  --width W [640] --height H [480] --focal F [525] --k1 K --k2 K [0]  (camera)\n"
    "  --noise SIGMA [0] (grey levels)   --blur N [1] (sub-frames per image)\n"
    "  --supersample N [1]   --exposure GAIN [1]   --exposure-swing S [0] (+-S, 4 s period)\n"
    "  --encoding mono8|bgr8 [mono8]\n"
    "  --target wall|floor [wall]   --walls 0-4 [4]   --no-ceiling\n"
    "  --yaml FILE [next to the bag]   --quiet   --help\n"
    "exit codes: 0 done, 2 bad usage, 1 could not write\n";

}  // namespace

int main(int argc, char** argv) {
  auto fail = [](const std::string& what) { return usageError("make_sequence", what, kUsage); };
  SequenceSpec spec;
  std::string bag_path, yaml_path;
  bool quiet = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (arg == "--quiet") {
      quiet = true;
      continue;
    }
    if (arg == "--no-ceiling") {
      spec.room.ceiling = false;
      continue;
    }
    if (i + 1 >= argc) return fail(arg + " needs a value");
    const std::string value = argv[++i];
    double x = 0;
    const bool numeric = parseNumber(value.c_str(), x);
    auto positive = [&](const char* what) {
      if (!numeric || !(x > 0))
        throw std::invalid_argument(std::string(what) + " needs a positive number");
      return x;
    };
    try {
      if (arg == "--out")
        bag_path = value;
      else if (arg == "--yaml")
        yaml_path = value;
      else if (arg == "--trajectory")
        spec.trajectory.name = value;
      else if (arg == "--encoding")
        spec.encoding = value;
      else if (arg == "--target")
        spec.room.target_on = value;
      else if (arg == "--frames")
        spec.frames = static_cast<int>(positive("--frames"));
      else if (arg == "--fps")
        spec.fps = positive("--fps");
      else if (arg == "--speed")
        spec.trajectory.speed_mps = numeric ? x : positive("--speed");
      else if (arg == "--turn")
        spec.trajectory.turn_deg = numeric ? x : positive("--turn");
      else if (arg == "--seed")
        spec.room.seed = spec.trajectory.seed = static_cast<unsigned>(positive("--seed"));
      else if (arg == "--width")
        spec.camera.size.width = static_cast<int>(positive("--width"));
      else if (arg == "--height")
        spec.camera.size.height = static_cast<int>(positive("--height"));
      else if (arg == "--focal")
        spec.camera.fx = spec.camera.fy = positive("--focal");
      else if (arg == "--k1")
        spec.camera.k1 = numeric ? x : positive("--k1");
      else if (arg == "--k2")
        spec.camera.k2 = numeric ? x : positive("--k2");
      else if (arg == "--noise")
        spec.render.noise_sigma = numeric && x >= 0 ? x : positive("--noise");
      else if (arg == "--blur")
        spec.render.blur_subframes = static_cast<int>(positive("--blur"));
      else if (arg == "--supersample")
        spec.render.supersample = static_cast<int>(positive("--supersample"));
      else if (arg == "--exposure")
        spec.render.exposure = positive("--exposure");
      else if (arg == "--exposure-swing")
        spec.exposure_swing = numeric ? x : positive("--exposure-swing");
      else if (arg == "--walls") {
        if (!numeric || x < 0 || x > 4) return fail("--walls needs 0 to 4");
        spec.room.walls = static_cast<int>(x);
      } else
        return fail("unknown option " + arg);
    } catch (const std::invalid_argument& e) {
      return fail(e.what());
    }
  }
  if (bag_path.empty()) return fail("--out FILE.bag is required");
  if (spec.room.target_on != "wall" && spec.room.target_on != "floor")
    return fail("--target must be wall or floor");
  spec.camera.cx = (spec.camera.size.width - 1) / 2.0;
  spec.camera.cy = (spec.camera.size.height - 1) / 2.0;
  if (yaml_path.empty()) {
    const auto dot = bag_path.rfind(".bag");
    yaml_path = (dot == std::string::npos ? bag_path : bag_path.substr(0, dot)) + ".yaml";
  }
  try {
    const SequenceReport report = writeSequence(spec, bag_path, yaml_path, [&](int k) {
      if (!quiet && ((k + 1) % 50 == 0 || k + 1 == spec.frames)) {
        std::fprintf(stderr, "\rmake_sequence: %d / %d images", k + 1, spec.frames);
      }
    });
    if (!quiet) {
      std::fprintf(stderr, "\n");
      std::printf(
          "wrote %s (%d images, %s trajectory) and %s; rendering %.1f ms per image "
          "(%.0f images/s)\n",
          bag_path.c_str(), report.frames, spec.trajectory.name.c_str(), yaml_path.c_str(),
          report.render_ms_mean, 1000.0 / report.render_ms_mean);
    }
  } catch (const std::runtime_error& e) {
    std::fprintf(stderr, "make_sequence: %s\n", e.what());
    const bool could_not_write = std::string(e.what()).rfind("cannot write", 0) == 0;
    return could_not_write ? 1 : 2;  // otherwise the spec was refused
  }
  return 0;
}
