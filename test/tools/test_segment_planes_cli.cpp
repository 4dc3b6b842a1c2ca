// The segment_planes program: output format, options and exit codes.
#include <gtest/gtest.h>

#include <sstream>

#include "mono_plane_detection/eval/segmentation_error.h"
#include "mono_plane_detection/sim/synthetic_two_view.h"
#include "support/run_program.h"

using namespace mono_plane_detection;

namespace {

ProgramRun run(const std::string& args) { return runProgram(SEGMENT_PLANES_PATH, args); }
std::string writeFile(const std::string& name, const std::string& text) {
  return writeTempFile(name, text);
}

}  // namespace

TEST(SegmentPlanesCli, LabelsOnePerLineMatchingTheTruth) {
  TwoViewSceneParams sp;
  sp.planes = 2;
  const auto scene = makeTwoViewScene(sp);
  std::ostringstream text;
  text << "# x1 y1 x2 y2\n";
  for (size_t i = 0; i < scene.view1.size(); ++i) {
    text << scene.view1[i].x << " " << scene.view1[i].y << " " << scene.view2[i].x << " "
         << scene.view2[i].y << "\n";
  }
  const ProgramRun r = run("--threshold 3 " + writeFile("scene.txt", text.str()));
  ASSERT_EQ(r.code, 0) << r.err;
  std::vector<int> labels;
  std::istringstream in(r.out);
  for (int l; in >> l;) labels.push_back(l);
  ASSERT_EQ(labels.size(), scene.labels.size());
  EXPECT_LT(misclassificationError(scene.labels, labels), 0.05);

  const ProgramRun json = run("--json --max-planes 1 " + writeFile("scene.txt", text.str()));
  ASSERT_EQ(json.code, 0);
  EXPECT_NE(json.out.find("\"homography\""), std::string::npos);
  EXPECT_NE(json.out.find("\"inliers\""), std::string::npos);
  EXPECT_NE(json.out.find("\"id\": 1"), std::string::npos);
  EXPECT_EQ(json.out.find("\"id\": 2"), std::string::npos);  // --max-planes 1
}

TEST(SegmentPlanesCli, FewerThanFivePointsAreAllZero) {
  const ProgramRun r = run(writeFile("few.txt", "1 2 3 4\n5 6 7 8\n"));
  EXPECT_EQ(r.code, 0);
  EXPECT_EQ(r.out, "0\n0\n");
}

TEST(SegmentPlanesCli, MalformedInputNamesTheLineAndExitsTwo) {
  ProgramRun r = run(writeFile("bad.txt", "1 2 3 4\n1 2 3\n"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("line 2"), std::string::npos);
  r = run(writeFile("nan.txt", "1 2 3 4\nnan 2 3 4\n"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("line 2"), std::string::npos);
  r = run(writeFile("text.txt", "hello world\n"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("line 1"), std::string::npos);
}

TEST(SegmentPlanesCli, OptionsAndUsage) {
  EXPECT_EQ(run("--help").code, 0);
  EXPECT_NE(run("--help").out.find("--threshold"), std::string::npos);
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("--threshold -1 x.txt").code, 2);
  EXPECT_EQ(run("--max-planes zero x.txt").code, 2);
  EXPECT_EQ(run("--frobnicate x.txt").code, 2);
  EXPECT_EQ(run("/no/such/file.txt").code, 2);
  const std::string few = writeFile("few2.txt", "1 2 3 4\n");
  EXPECT_EQ(run("--threshold 3 --min-support 5 --seed 7 " + few).code, 0);
}

// Issue 15 item 10: values a long holds but an int does not were truncated (exit 0, every
// label 0); now refused with the range.
TEST(SegmentPlanesCli, CountsOutsideIntAreRefusedNotTruncated) {
  const std::string few = writeFile("few3.txt", "1 2 3 4\n");
  for (const char* option : {"--max-planes 4294967295", "--max-planes 2147483648",
                             "--min-support 4294967296", "--min-support 2147483652",
                             "--seed 4294967296", "--seed -1"}) {
    const ProgramRun r = run(std::string(option) + " " + few);
    EXPECT_EQ(r.code, 2) << option;
    EXPECT_NE(r.err.find("range"), std::string::npos) << option << ": " << r.err;
  }
  EXPECT_EQ(run("--seed 4294967295 " + few).code, 0);
}

// Issue 15 item 12: a directory was read as an empty file (exit 0, no output).
TEST(SegmentPlanesCli, ADirectoryIsRefused) {
  const ProgramRun r = run(::testing::TempDir());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("directory"), std::string::npos) << r.err;
}

// Issue 15 item 9: a huge line is refused by its length, read as a stream.
TEST(SegmentPlanesCli, AVeryLongLineIsRefusedByItsLength) {
  std::string line;
  for (int i = 0; i < 100000; ++i) line += "1 ";
  const ProgramRun r = run(writeFile("long.txt", "1 2 3 4\n" + line + "\n"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("line 2: longer than"), std::string::npos) << r.err;
}

// Issue 15 item 12: subnormal input is read; a NUL inside a number is not.
TEST(SegmentPlanesCli, SubnormalReadEmbeddedNulRefused) {
  ProgramRun r = run(writeFile("subnormal.txt", "1e-320 2 3 4\n"));
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out, "0\n");
  r = run(writeFile("nul.txt", std::string("1.0\0junk 2 3 4\n", 15)));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("line 1"), std::string::npos) << r.err;
}
