// The make_sequence program: files written, options, exit codes.
#include <gtest/gtest.h>

#include <fstream>

#include "support/run_program.h"

using namespace mono_plane_detection;

namespace {
ProgramRun run(const std::string& args) { return runProgram(MAKE_SEQUENCE_PATH, args); }
bool exists(const std::string& path) { return std::ifstream(path).good(); }
}  // namespace

TEST(MakeSequenceCli, WritesBagAndGroundTruthNextToIt) {
  const std::string bag = std::string(::testing::TempDir()) + "cli_seq.bag";
  const ProgramRun r =
      run("--trajectory rotation --frames 3 --width 160 --height 120 --focal 130 "
          "--noise 2 --blur 2 --exposure-swing 0.2 --target floor --out " +
          bag);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(exists(bag));
  EXPECT_TRUE(exists(std::string(::testing::TempDir()) + "cli_seq.yaml"));
  EXPECT_NE(r.out.find("3 images"), std::string::npos);
  EXPECT_NE(r.out.find("images/s"), std::string::npos);  // rendering speed is reported
}

TEST(MakeSequenceCli, BadUsageExitsTwoAndSaysWhy) {
  EXPECT_EQ(run("--help").code, 0);
  EXPECT_NE(run("--help").out.find("--trajectory"), std::string::npos);
  ProgramRun r = run("--frames 3");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--out"), std::string::npos);
  r = run("--trajectory flying --out x.bag");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("flying"), std::string::npos);
  EXPECT_EQ(run("--frames -4 --out x.bag").code, 2);
  EXPECT_EQ(run("--walls 9 --out x.bag").code, 2);
  EXPECT_EQ(run("--frobnicate 1 --out x.bag").code, 2);
  EXPECT_EQ(run("--frames 2 --out /no/such/folder/x.bag").code, 1);
}
