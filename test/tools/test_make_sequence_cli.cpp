// The make_sequence program: files written, options, exit codes.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <vector>

#include "support/run_program.h"

using namespace mono_plane_detection;

namespace {
ProgramRun run(const std::string& args) { return runProgram(MAKE_SEQUENCE_PATH, args); }
bool exists(const std::string& path) { return std::ifstream(path).good(); }
}  // namespace

TEST(MakeSequenceCli, WritesBagAndGroundTruthNextToIt) {
  const std::string bag = tempPath("cli_seq.bag");
  const ProgramRun r =
      run("--trajectory rotation --frames 3 --width 160 --height 120 --focal 130 "
          "--noise 2 --blur 2 --exposure-swing 0.2 --target floor --out " +
          bag);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(exists(bag));
  EXPECT_TRUE(exists(tempPath("cli_seq.yaml")));
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

namespace {
// Bounded: the old program ran for ever on some of these; `timeout` turns that into a
// failure (exit 124) instead of a hung test.
ProgramRun runBounded(const std::string& args) {
  return runProgram(std::string("timeout 30 ") + MAKE_SEQUENCE_PATH, args);
}
std::string temp(const std::string& name) { return tempPath(name); }
}  // namespace

// Issue 15 item 13: sizes and counts are bounded with a clear message (the old program
// died of bad_alloc, SIGABRT, or ran until killed).
TEST(MakeSequenceCli, SizesAndCountsAreBounded) {
  const std::string bag = temp("bounded.bag");
  for (const std::string& option :
       {std::string("--width 100000 --height 100000"), std::string("--supersample 1000"),
        std::string("--frames 1000000000"), std::string("--blur 100000"),
        std::string("--width 8192 --height 8192"), std::string("--width 4096 --height 4096 --supersample 2"),
        std::string("--frames 2147483648"), std::string("--fps 1e300")}) {
    const ProgramRun r = runBounded(option + " --quiet --out " + bag);
    EXPECT_EQ(r.code, 2) << option << ": " << r.err;
    EXPECT_FALSE(r.err.empty()) << option;
    EXPECT_FALSE(exists(bag)) << option;
  }
}

// Issue 15 item 13: --out X --yaml X wrote the bag, then the YAML over it, and exited 0.
TEST(MakeSequenceCli, OutputsNeverOverwriteEachOther) {
  const std::string bag = temp("same.bag");
  // The same file spelt three ways: as is, through "./", and through "../<folder>/".
  const std::string dir = ::testing::TempDir();
  const std::string name = bag.substr(dir.size());
  for (const std::string& yaml : {bag, dir + "./" + name, dir + "../" + dir.substr(1) + name}) {
    const ProgramRun r = runBounded("--frames 2 --width 64 --height 48 --quiet --out " + bag +
                                    " --yaml " + yaml);
    EXPECT_EQ(r.code, 2) << yaml << ": " << r.err;
    EXPECT_NE(r.err.find("same file"), std::string::npos) << r.err;
    EXPECT_FALSE(exists(bag));
  }
}

// Exit code 1 (cannot write) comes from a typed error, not from the message text.
TEST(MakeSequenceCli, UnwritableYamlExitsOne) {
  const ProgramRun r = runBounded("--frames 2 --width 64 --height 48 --quiet --out " +
                                  temp("ok.bag") + " --yaml /no/such/folder/x.yaml");
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("cannot write"), std::string::npos);
}

// Issue 12 part 4 and issue 18: the target, its background, the furnished room and real
// photographs as textures, each written into a bag and its ground truth.
TEST(MakeSequenceCli, TargetsBackgroundsLayoutAndTextures) {
  const std::string textures = std::string(TEST_DATA_DIR) + "/textures";
  struct Case {
    std::string args, yaml_has;
  };
  const std::vector<Case> cases = {
      {"--target none", "type: none"},
      {"--target aruco --aruco-id 3", "aruco_id: 3"},
      {"--target sheet --background grey", "background: grey"},
      {"--target sheet --background wood --layout furnished --target-on table", "table_+z"},
      {"--layout furnished --textures " + textures, "surface: photo"},
      {"--layout furnished --trajectory turn_in_place", "shelf_+x"},
      {"--trajectory look_around", "look_around"},
  };
  int n = 0;
  for (const Case& c : cases) {
    const std::string bag = temp("options_" + std::to_string(n++) + ".bag");
    const ProgramRun r =
        runBounded("--frames 2 --width 80 --height 60 --focal 66 --quiet " + c.args + " --out " + bag);
    ASSERT_EQ(r.code, 0) << c.args << ": " << r.err;
    std::ifstream yaml(bag.substr(0, bag.size() - 4) + ".yaml");
    const std::string text((std::istreambuf_iterator<char>(yaml)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find(c.yaml_has), std::string::npos) << c.args;
  }
  // Bad usage: a table in the bare room, a folder without images, unknown values.
  for (const std::string& bad :
       {std::string("--target-on table"), std::string("--textures /no/such/folder"),
        std::string("--target poster"), std::string("--background pink"),
        std::string("--layout castle"), std::string("--aruco-id 50")}) {
    const ProgramRun r = runBounded("--frames 2 --width 80 --height 60 --quiet " + bad + " --out " +
                                    temp("bad_option.bag"));
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_FALSE(r.err.empty()) << bad;
  }
}
