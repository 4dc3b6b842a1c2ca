// make_sequence: a synthetic indoor sequence with exact ground truth, as a rosbag.
//   rosrun mono_plane_detection make_sequence --trajectory humanoid --frames 300 --out seq.bag
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>

#include "../sim/bag/sequence_writer.h"
#include "cli_args.h"
#include "mono_plane_detection/sim/scene_renderer.h"

using namespace mono_plane_detection;

namespace {

// Where a path leads, following symbolic links even to a file that does not exist yet.
std::filesystem::path resolved(const std::string& text) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p = fs::absolute(text, ec);
  for (int hop = 0; hop < 16 && fs::is_symlink(p, ec); ++hop) {
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) break;
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  const fs::path canonical = fs::weakly_canonical(p, ec);
  return ec ? p.lexically_normal() : canonical;
}

// Two paths name the same file (or would, once created).
bool sameFile(const std::string& a, const std::string& b) { return resolved(a) == resolved(b); }

}  // namespace

int main(int argc, char** argv) {
  SequenceSpec spec;
  std::string bag_path, yaml_path;
  bool quiet = false;
  unsigned seed = spec.room.seed;
  std::string target = "sheet", textures;
  cli::Parser cli(
      "make_sequence", "[options] --out FILE.bag",
      "  Renders a room (floor, walls, ceiling, furniture with --layout furnished, the\n"
      "  start-up target) seen from a moving camera\n"
      "  and writes a rosbag with /camera/image_raw, /camera/camera_info and /tf (map ->\n"
      "  camera_gt), plus the ground truth (planes, target, poses in the map frame) as\n"
      "  FILE.yaml next to it.",
      "limits: width x height x supersample^2 at most 2^24 sub-pixels (renderer memory);\n"
      "  the bag and the YAML must be two different files.\n"
      "exit codes: 0 done, 2 bad usage, 1 could not write\n");
  cli.text("out", &bag_path, "the bag to write (required)", "FILE.bag")
      .text("yaml", &yaml_path, "the ground truth to write (default: the bag's name, .yaml)",
            "FILE")
      .choice("trajectory", &spec.trajectory.name,
              {"wheeled", "humanoid", "rotation", "turn_in_place", "look_around"},
              "camera motion")
      .integer("frames", &spec.frames, 1, 100000, "images")
      .number("fps", &spec.fps, 0.1, 1000.0, "images per second (stamps 1/F apart)", "F")
      .number("speed", &spec.trajectory.speed_mps, -5.0, 5.0, "forward speed, m/s", "MPS")
      .number("turn", &spec.trajectory.turn_deg, -3600.0, 3600.0,
              "total left turn over the sequence, degrees", "DEG")
      .integer<unsigned>("seed", &seed, 0, std::numeric_limits<unsigned>::max(),
                         "textures and humanoid jerks", "S")
      .integer("width", &spec.camera.size.width, 16, 8192, "image width, pixels", "W")
      .integer("height", &spec.camera.size.height, 16, 8192, "image height, pixels", "H")
      .number("focal", &spec.camera.fx, 1.0, 1e5, "focal length fx = fy, pixels", "F")
      .number("k1", &spec.camera.k1, -10.0, 10.0, "radial distortion k1", "K")
      .number("k2", &spec.camera.k2, -10.0, 10.0, "radial distortion k2", "K")
      .number("noise", &spec.render.noise_sigma, 0.0, 255.0, "image noise sigma, grey levels",
              "SIGMA")
      .integer("blur", &spec.render.blur_subframes, 1, 64, "sub-frames averaged per image")
      .integer("supersample", &spec.render.supersample, 1, 8, "rays per pixel side")
      .number("exposure", &spec.render.exposure, 1e-3, 100.0, "intensity gain", "GAIN")
      .number("exposure-swing", &spec.exposure_swing, 0.0, 0.99,
              "exposure varies by +-S, 4 s period", "S")
      .choice("encoding", &spec.encoding, {"mono8", "bgr8"}, "image encoding")
      .choice("target", &target, {"none", "sheet", "aruco", "wall", "floor"},
              "the start-up target: none, a white sheet or an ArUco marker (wall, floor: a "
              "sheet there, as before)")
      .choice("target-on", &spec.room.target_on, {"wall", "floor", "table"},
              "where the target is (table: --layout furnished)")
      .choice("background", &spec.room.target_background, {"black", "grey", "wood"},
              "around the sheet: a black border, a mid-grey wall, a wood-like table")
      .integer("aruco-id", &spec.room.aruco_id, 0, 49, "the marker's id (DICT_4X4_50)")
      .number("aruco-size", &spec.room.aruco_size_m, 0.03, 1.0,
              "side of the marker's black square, m", "M")
      .choice("layout", &spec.room.layout, {"bare", "furnished"},
              "bare: floor, walls, ceiling; furnished: a sideboard, a bookshelf, a table and "
              "a door recess, plain painted walls with posters next to textured ones")
      .text("textures", &textures,
            "paint the floor and walls (posters too) with the photographs in DIR", "DIR")
      .integer("walls", &spec.room.walls, 0, 4, "walls of the room")
      .flag("no-ceiling", &spec.room.ceiling, "a room without a ceiling", false)
      .flag("quiet", &quiet, "no progress and summary");
  if (const auto code = cli.parse(argc, argv)) return *code;
  if (bag_path.empty()) return cli.fail("--out FILE.bag is required");
  spec.room.seed = spec.trajectory.seed = seed;
  if (target == "wall" || target == "floor") {  // the old meaning of --target
    spec.room.target_on = target;
    target = "sheet";
  }
  spec.room.target_type = target;
  if (spec.room.target_on == "table" && spec.room.layout != "furnished")
    return cli.fail("--target-on table needs --layout furnished (the bare room has no table)");
  if (!textures.empty()) {
    try {
      spec.room.photos = loadTexturePhotos(textures);
    } catch (const std::exception& e) {
      return cli.fail(std::string("--textures: ") + e.what());
    }
  }
  spec.camera.fy = spec.camera.fx;
  if (const std::string e = renderSizeError(spec.camera.size, spec.render.supersample); !e.empty())
    return cli.fail(e);
  spec.camera.cx = (spec.camera.size.width - 1) / 2.0;
  spec.camera.cy = (spec.camera.size.height - 1) / 2.0;
  if (yaml_path.empty()) {
    const auto dot = bag_path.rfind(".bag");
    yaml_path = (dot == std::string::npos ? bag_path : bag_path.substr(0, dot)) + ".yaml";
  }
  if (sameFile(bag_path, yaml_path))
    return cli.fail("--out and --yaml name the same file " + bag_path +
                    ": one would overwrite the other");
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
  } catch (const SequenceWriteError& e) {
    std::fprintf(stderr, "make_sequence: %s\n", e.what());
    return 1;
  } catch (const SequenceSpecError& e) {
    return cli.fail(e.what());
  }
  return 0;
}
