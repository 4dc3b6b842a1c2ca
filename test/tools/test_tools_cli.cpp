// Every command-line program of the package answers --help from its option table (exit
// 0, usage on stdout) and refuses an unknown option (exit 2, reason and usage on stderr),
// without a ROS master and without waiting: the one parser of src/tools/cli_args.h.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "support/run_program.h"

using namespace mono_plane_detection;

namespace {

const std::vector<std::pair<std::string, std::string>> kTools = {
    {"benchmark_latency", BENCHMARK_LATENCY_PATH}, {"benchmark_suite", BENCHMARK_SUITE_PATH},
    {"benchmark_tracker", BENCHMARK_TRACKER_PATH}, {"demo_report", DEMO_REPORT_PATH},
    {"make_sequence", MAKE_SEQUENCE_PATH},         {"run_pipeline", RUN_PIPELINE_PATH},
    {"segment_planes", SEGMENT_PLANES_PATH},       {"eval_two_view", EVAL_TWO_VIEW_PATH},
    {"plane_pair", PLANE_PAIR_PATH}};

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
