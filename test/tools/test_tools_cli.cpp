// Every command-line program of the package answers --help from its option table (exit
// 0, usage on stdout) and refuses an unknown option (exit 2, reason and usage on stderr),
// without a ROS master and without waiting: the one parser of src/tools/cli_args.h.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "support/run_program.h"

using namespace mono_plane_detection;

namespace {

const std::vector<std::pair<std::string, std::string>> kTools = {
    {"benchmark_latency", BENCHMARK_LATENCY_PATH}, {"benchmark_suite", BENCHMARK_SUITE_PATH},
    {"benchmark_tracker", BENCHMARK_TRACKER_PATH}, {"demo_report", DEMO_REPORT_PATH},
    {"detect_target", DETECT_TARGET_PATH},
    {"make_sequence", MAKE_SEQUENCE_PATH},         {"run_pipeline", RUN_PIPELINE_PATH},
    {"segment_planes", SEGMENT_PLANES_PATH},       {"benchmark_tracker_floor", BENCHMARK_TRACKER_FLOOR_PATH},
    {"eval_two_view", EVAL_TWO_VIEW_PATH},         {"plane_pair", PLANE_PAIR_PATH},
    {"param_table", PARAM_TABLE_PATH},             {"ground_truth_frame", GROUND_TRUTH_FRAME_PATH}};

// No master on port 1: a program that tried to reach one would wait; `timeout` ends it.
ProgramRun run(const std::string& path, const std::string& args) {
  return runProgram("ROS_MASTER_URI=http://localhost:1 timeout 20 " + path, args);
}

}  // namespace

TEST(ToolsCli, EveryToolAnswersHelpFromItsTable) {
  for (const auto& [name, path] : kTools) {
    const ProgramRun r = run(path, "--help");
    EXPECT_EQ(r.code, 0) << name << ": " << r.err;  // demo_report blocked here (exit 124)
    EXPECT_EQ(r.out.rfind("usage: " + name, 0), 0u) << name << ": " << r.out;
    EXPECT_NE(r.out.find("-h, --help"), std::string::npos) << name;
    EXPECT_NE(r.out.find("options:"), std::string::npos) << name;
  }
}

TEST(ToolsCli, EveryToolRefusesAnUnknownOptionWithExitTwo) {
  for (const auto& [name, path] : kTools) {
    const ProgramRun r = run(path, "--frobnicate 3");
    EXPECT_EQ(r.code, 2) << name << ": " << r.err;
    EXPECT_NE(r.err.find("frobnicate"), std::string::npos) << name << ": " << r.err;
    EXPECT_NE(r.err.find("usage: " + name), std::string::npos) << name << ": " << r.err;
  }
}

TEST(ToolsCli, UnreadableInputsExitTwo) {
  ProgramRun r = run(SEGMENT_PLANES_PATH, "/no/such/file.txt");
  EXPECT_EQ(r.code, 2) << r.err;
  r = run(BENCHMARK_LATENCY_PATH, "--bag /no/such/file.bag");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("cannot read"), std::string::npos) << r.err;
  r = run(DEMO_REPORT_PATH, "--truth /no/such/truth.yaml");
  EXPECT_EQ(r.code, 2) << r.err;
  r = run(EVAL_TWO_VIEW_PATH, "/no/such/folder");
  EXPECT_EQ(r.code, 2) << r.err;
  r = run(PLANE_PAIR_PATH, "/no/such/a.png /no/such/b.png --fx 500 --fy 500 --cx 320 --cy 240");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("cannot read image"), std::string::npos) << r.err;
  r = run(PLANE_PAIR_PATH, "/no/such/a.png /no/such/b.png");  // no intrinsics
  EXPECT_EQ(r.code, 2) << r.err;
}

// Issue 15 item 14: --frames 0 printed "-nan ms/frame" and a pass (exit 0).
TEST(ToolsCli, RunPipelineRefusesZeroFrames) {
  const ProgramRun r = run(RUN_PIPELINE_PATH, "--frames 0");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.err.find("--frames"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
  EXPECT_EQ(run(RUN_PIPELINE_PATH, "--width 100000").code, 2);
  EXPECT_EQ(run(RUN_PIPELINE_PATH, "--seed -1").code, 2);
}

// The renderer's memory is bounded as make_sequence bounds it: width x height x
// supersample^2 at most kMaxRenderSubpixels, refused before anything is rendered.
TEST(ToolsCli, RunPipelineRefusesMoreSubpixelsThanTheRendererHolds) {
  const ProgramRun r = run(RUN_PIPELINE_PATH, "--width 4096 --height 4096 --supersample 2");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.err.find("sub-pixels"), std::string::npos) << r.err;
}

// docs/tools.md is every tool's --help, so the page cannot drift from the option tables.
// Regenerate: MPD_WRITE_TOOLS_DOC=1 devel/lib/mono_plane_detection/test_tools_cli
TEST(ToolsCli, DocsToolsPageIsEveryToolsHelp) {
  std::string page =
      "# Command-line tools\n\n"
      "Generated from each program's `--help` (its option table in `src/tools/`) by\n"
      "`MPD_WRITE_TOOLS_DOC=1 test_tools_cli`; `test_tools_cli` fails when this page is out\n"
      "of date. Run them as `rosrun mono_plane_detection PROGRAM`. Every program answers\n"
      "`--help` with exit 0 and refuses bad usage with exit 2 and the reason.\n"
      "A `--profile` reads `config/` where ROS finds the package, as roslaunch's `$(find\n"
      "mono_plane_detection)` does: the share folder of an installed package (`catkin_make\n"
      "install`, a binary package), the source folder in a devel workspace; outside a ROS\n"
      "environment, the source folder the program was built from (`src/tools/config_dir.h`).\n";
  for (const auto& [name, path] : kTools) page += "\n## " + name + "\n\n```\n" + run(path, "--help").out + "```\n";
  const std::string doc = std::string(SOURCE_DIR) + "/docs/tools.md";
  if (std::getenv("MPD_WRITE_TOOLS_DOC")) {
    std::ofstream(doc) << page;
    GTEST_SKIP() << "wrote docs/tools.md (compared on the next run)";
  }
  std::stringstream committed;
  committed << std::ifstream(doc).rdbuf();
  EXPECT_EQ(committed.str(), page) << "docs/tools.md is out of date: MPD_WRITE_TOOLS_DOC=1 "
                                      "devel/lib/mono_plane_detection/test_tools_cli";
}

// Issue 12: detect_target prints per image the corners or `none` and the reason (--json
// too); exit 0 when it ran, 2 on bad usage or an unreadable image.
TEST(ToolsCli, DetectTargetOnRealPhotos) {
  const std::string photos = std::string(TEST_DATA_DIR) + "/target_photos/";
  ProgramRun r = run(DETECT_TARGET_PATH,
                     photos + "test1.jpg " + photos + "test4.jpg " + photos + "scanned_img.jpg");
  EXPECT_EQ(r.code, 0) << r.err;
  // test1 (dark wood) and test4 (light wood): found, four corners; a flat scan (no
  // surround): none, with the reason.
  EXPECT_NE(r.out.find("test1.jpg: "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("test1.jpg: none"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("test4.jpg: "), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("test4.jpg: none"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("scanned_img.jpg: none ("), std::string::npos) << r.out;
  r = run(DETECT_TARGET_PATH, "--json " + photos + "test3.jpg " + photos + "result.jpg");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\"found\": true, \"corners\": [["), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"found\": false, \"rejection\""), std::string::npos) << r.out;
  r = run(DETECT_TARGET_PATH, "--target-type aruco " + photos + "test1.jpg");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("none (no marker"), std::string::npos) << r.out;
  r = run(DETECT_TARGET_PATH, "/no/such/image.png");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("cannot read image"), std::string::npos) << r.err;
  EXPECT_EQ(run(DETECT_TARGET_PATH, "").code, 2);  // no image
  EXPECT_EQ(run(DETECT_TARGET_PATH, "--target-type checkerboard " + photos + "test1.jpg").code, 2);
  EXPECT_EQ(run(DETECT_TARGET_PATH, "--target-type aruco --dictionary DICT_9X9_1 " + photos +
                                        "test1.jpg").code,
            2);
}

// plane_pair --matches writes every undistorted match in segment_planes' input format
// (how test/data/euroc_1403715274212143104.txt was made): two real TUM office frames, ORB
// (SIFT needs OpenCV 4.4), the file read back by segment_planes, one label per match.
TEST(ToolsCli, PlanePairWritesItsMatchesForSegmentPlanes) {
  const std::string tum = std::string(TEST_DATA_DIR) + "/tum_office/";
  const std::string matches = tempPath("plane_pair_matches.txt");
  ProgramRun r = run(PLANE_PAIR_PATH, tum + "1341847987.758741.jpg " + tum +
                                          "1341847989.802890.png --fx 535.4 --fy 539.2 --cx 320.1 "
                                          "--cy 247.6 --features orb --json --overlay " +
                                          tempPath("plane_pair.png") + " --matches " + matches);
  ASSERT_EQ(r.code, 0) << r.err;
  const size_t at = r.out.find("\"matches\": ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const int count = std::stoi(r.out.substr(at + 11));
  EXPECT_GT(count, 50);
  r = run(SEGMENT_PLANES_PATH, matches);
  EXPECT_EQ(r.code, 0) << r.err;
  std::istringstream labels(r.out);
  int lines = 0;
  for (std::string line; std::getline(labels, line);) lines += !line.empty();
  EXPECT_EQ(lines, count);
  // With lens distortion the written points are undistorted: the same matches, moved
  // (k1 -0.3 moves a point 100 px from the centre by about 1 px, at the corners by ~20).
  const std::string distorted = tempPath("plane_pair_matches_k1.txt");
  r = run(PLANE_PAIR_PATH, tum + "1341847987.758741.jpg " + tum +
                               "1341847989.802890.png --fx 535.4 --fy 539.2 --cx 320.1 --cy 247.6 "
                               "--k1 -0.3 --features orb --no-overlay --matches " + distorted);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.find("overlay:"), std::string::npos) << r.out;  // --no-overlay: none written
  auto points = [](const std::string& path) {
    std::ifstream in(path);
    std::vector<std::vector<double>> rows;
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      std::vector<double> row(4);
      for (double& v : row) fields >> v;
      rows.push_back(row);
    }
    return rows;
  };
  const auto plain = points(matches), undistorted = points(distorted);
  ASSERT_EQ(plain.size(), undistorted.size());
  int moved = 0;
  for (size_t i = 0; i < plain.size(); ++i) {
    const double dx = undistorted[i][0] - plain[i][0], dy = undistorted[i][1] - plain[i][1];
    // Undistortion moves a point outwards from the principal point (k1 < 0: barrel).
    const double out = dx * (plain[i][0] - 320.1) + dy * (plain[i][1] - 247.6);
    moved += std::hypot(dx, dy) > 0.5 && out > 0;
  }
  EXPECT_GT(moved, static_cast<int>(plain.size()) * 8 / 10) << moved << " of " << plain.size();
  EXPECT_EQ(run(PLANE_PAIR_PATH, tum + "1341847987.758741.jpg " + tum +
                                     "1341847989.802890.png --fx 535.4 --fy 539.2 --features orb "
                                     "--overlay " + tempPath("plane_pair.png") +
                                     " --matches /no/such/dir/m.txt").code,
            2);
}

// Every tool that takes parameters reads the nodelets' profiles (--profile, profile.h);
// an unknown profile is a usage error naming the missing file.
TEST(ToolsCli, ToolsWithParametersRefuseAnUnknownProfile) {
  const std::vector<std::pair<std::string, std::string>> tools = {
      {SEGMENT_PLANES_PATH, "a.txt"}, {RUN_PIPELINE_PATH, ""}, {DETECT_TARGET_PATH, "a.png"},
      {PLANE_PAIR_PATH, "a.png b.png"}};
  for (const auto& [path, args] : tools) {
    const ProgramRun r = run(path, "--profile tracked_vehicle " + args);
    EXPECT_EQ(r.code, 2) << path << ": " << r.err;
    EXPECT_NE(r.err.find("no profile"), std::string::npos) << path << ": " << r.err;
  }
}
