// Profiles for the tools (src/tools/profile.h): the nodelets' YAML files read through the
// parameter tables. The humanoid profile once reached run_pipeline as 2 of its 6 keys.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "../../src/tools/config_dir.h"
#include "../../src/tools/profile.h"
#include "support/temp_path.h"

using namespace mono_plane_detection;

namespace {

std::string writeYaml(const std::string& name, const std::string& text) {
  const std::string path = tempPath(name);
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST(Profile, NestedKeysSetTheirFields) {
  PlaneNodeParams p;
  const std::string path = writeYaml("nested.yaml",
                                     "frame_gap: 7\nplanes:\n  vote_threshold_px: 3.5\n  groups:\n"
                                     "    max_groups: 42\npublish_tf: false\nmap_frame: world\n");
  EXPECT_TRUE(applyYamlFile(path, planeNodeParamTable(), p).empty());
  EXPECT_EQ(p.pipeline.frame_gap, 7);
  EXPECT_DOUBLE_EQ(p.pipeline.planes.vote_threshold_px, 3.5);
  EXPECT_EQ(p.pipeline.planes.groups.max_groups, 42);
  EXPECT_FALSE(p.publish_tf);
  EXPECT_EQ(p.map_frame, "world");
}

TEST(Profile, BadValuesAreNamedAndTheDefaultKept) {
  const PlaneNodeParams defaults;
  PlaneNodeParams p;
  const std::string path =
      writeYaml("bad.yaml",
                "frame_gap: 2.5\nplanes:\n  max_planes: many\n  vote_threshold_px: -1\n"
                "no_such_thing: 1\npublish_tf: maybe\n");
  const std::vector<std::string> errors = applyYamlFile(path, planeNodeParamTable(), p);
  ASSERT_EQ(errors.size(), 5u);
  std::string all;
  for (const std::string& e : errors) all += e + "\n";
  EXPECT_NE(all.find("frame_gap: '2.5' is not a whole number"), std::string::npos) << all;
  EXPECT_NE(all.find("planes/max_planes: 'many' is not a number"), std::string::npos) << all;
  EXPECT_NE(all.find("unknown parameter no_such_thing"), std::string::npos) << all;
  EXPECT_NE(all.find("publish_tf: 'maybe' is not true or false"), std::string::npos) << all;
  EXPECT_NE(all.find("planes/vote_threshold_px = -1 is out of range"), std::string::npos) << all;
  EXPECT_EQ(p.pipeline.frame_gap, defaults.pipeline.frame_gap);
  EXPECT_EQ(p.pipeline.planes.max_planes, defaults.pipeline.planes.max_planes);
  EXPECT_DOUBLE_EQ(p.pipeline.planes.vote_threshold_px, defaults.pipeline.planes.vote_threshold_px);
  EXPECT_TRUE(p.publish_tf);
}

TEST(Profile, UnreadableFileIsAnError) {
  TrackerNodeParams p;
  EXPECT_EQ(applyYamlFile("/no/such/file.yaml", trackerNodeParamTable(), p).size(), 1u);
  EXPECT_EQ(
      applyYamlFile(writeYaml("broken.yaml", "a: [1, 2\n"), trackerNodeParamTable(), p).size(), 1u);
}

// Every key of config/tracker_humanoid.yaml reaches the tool, over config/tracker.yaml.
TEST(Profile, HumanoidOverlayGivesAllItsKeys) {
  TrackerNodeParams p;
  ASSERT_TRUE(loadProfile(std::string(SOURCE_DIR) + "/config", "tracker", "humanoid",
                          trackerNodeParamTable(), p)
                  .empty());
  EXPECT_EQ(p.tracker.pyramid_levels, 6);
  EXPECT_EQ(p.tracker.window_size_px, 15);
  EXPECT_DOUBLE_EQ(p.tracker.match_radius_px, 2.0);
  EXPECT_DOUBLE_EQ(p.tracker.forward_backward_max_px, 1.5);
  EXPECT_EQ(p.tracker.redetect_every, 8);
  EXPECT_EQ(p.tracker.max_features, 150);
  PlaneNodeParams planes;
  ASSERT_TRUE(loadProfile(std::string(SOURCE_DIR) + "/config", "planes", "humanoid",
                          planeNodeParamTable(), planes)
                  .empty());
  EXPECT_EQ(planes.pipeline.planes.groups.max_groups, 100);  // config/planes.yaml (core: 300)
}

// config/target.yaml is read by both nodelets' tools (as both launch files load it): a
// US letter sheet set there reaches the tracker's detector and the plane nodelet's scale.
TEST(Profile, TargetFileReachesBothNodelets) {
  const std::string dir = tempPath("config");
  ASSERT_EQ(::mkdir(dir.c_str(), 0700) == 0 || errno == EEXIST, true);
  std::ofstream(dir + "/tracker.yaml") << "max_features: 60\n";
  std::ofstream(dir + "/planes.yaml") << "frame_gap: 6\n";
  std::ofstream(dir + "/target.yaml") << "target:\n  width_m: 0.2794\n  height_m: 0.2159\n";
  TrackerNodeParams tracker;
  EXPECT_TRUE(loadProfile(dir, "tracker", "default", trackerNodeParamTable(), tracker).empty());
  EXPECT_DOUBLE_EQ(tracker.target.width_m, 0.2794);
  EXPECT_DOUBLE_EQ(tracker.target.height_m, 0.2159);
  PlaneNodeParams planes;
  EXPECT_TRUE(loadProfile(dir, "planes", "default", planeNodeParamTable(), planes).empty());
  EXPECT_DOUBLE_EQ(planes.pipeline.target.width_m, 0.2794);
  EXPECT_EQ(planes.pipeline.frame_gap, 6);
}

// run_pipeline's --profile FILE: one file over both nodelets' base files, each name set
// where its table has it (read for each nodelet alone, a tracker name was unknown to the
// planes' table and the other way round: every file was refused).
TEST(Profile, OneFileForBothNodeletsSetsEachNameWhereItIsKnown) {
  const std::string dir = tempPath("config_both");
  ASSERT_EQ(::mkdir(dir.c_str(), 0700) == 0 || errno == EEXIST, true);
  std::ofstream(dir + "/tracker.yaml") << "max_features: 60\n";
  std::ofstream(dir + "/planes.yaml") << "frame_gap: 6\n";
  const std::string file = writeYaml(
      "both.yaml", "max_features: 77\nmap:\n  min_points: 9\ntarget:\n  width_m: 0.2794\n");
  TrackerNodeParams tracker;
  PlaneNodeParams planes;
  EXPECT_EQ(loadProfiles(dir, file, "tracker", trackerNodeParamTable(), tracker, "planes",
                         planeNodeParamTable(), planes),
            std::vector<std::string>());
  EXPECT_EQ(tracker.tracker.max_features, 77);       // the tracker's name
  EXPECT_EQ(planes.pipeline.map.min_points, 9);      // the planes' name
  EXPECT_EQ(planes.pipeline.frame_gap, 6);           // the base file kept
  EXPECT_DOUBLE_EQ(tracker.target.width_m, 0.2794);  // a name both have: both
  EXPECT_DOUBLE_EQ(planes.pipeline.target.width_m, 0.2794);
  // A name neither has is one error naming it; a bad value of a shared name is one error.
  const std::string bad = writeYaml("bad.yaml", "max_feature: 77\ntarget:\n  width_m: fast\n");
  const std::vector<std::string> errors =
      loadProfiles(dir, bad, "tracker", trackerNodeParamTable(), tracker, "planes",
                   planeNodeParamTable(), planes);
  ASSERT_EQ(errors.size(), 2u) << (errors.empty() ? std::string("none") : errors[0]);
  EXPECT_NE(errors[0].find("unknown parameter max_feature (neither tracker nor planes"),
            std::string::npos)
      << errors[0];
  EXPECT_NE(errors[1].find("target/width_m"), std::string::npos) << errors[1];
  // A named profile is still each nodelet's own overlay.
  TrackerNodeParams t2;
  PlaneNodeParams p2;
  EXPECT_TRUE(loadProfiles(std::string(SOURCE_DIR) + "/config", "humanoid", "tracker",
                           trackerNodeParamTable(), t2, "planes", planeNodeParamTable(), p2)
                  .empty());
  TrackerNodeParams t3;
  loadProfile(std::string(SOURCE_DIR) + "/config", "tracker", "humanoid", trackerNodeParamTable(),
              t3);
  EXPECT_EQ(t2.tracker.window_size_px, t3.tracker.window_size_px);
}

TEST(Profile, NoneKeepsTheCoreDefaultsAndUnknownProfilesAreNamed) {
  PlaneNodeParams p;
  EXPECT_TRUE(
      loadProfile(std::string(SOURCE_DIR) + "/config", "planes", "none", planeNodeParamTable(), p)
          .empty());
  EXPECT_EQ(p.pipeline.planes.groups.max_groups,
            PlaneNodeParams().pipeline.planes.groups.max_groups);
  const std::vector<std::string> errors = loadProfile(std::string(SOURCE_DIR) + "/config", "planes",
                                                      "tracked_vehicle", planeNodeParamTable(), p);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("no profile"), std::string::npos) << errors[0];
}

TEST(Profile, ArgumentIsFoundBeforeParsing) {
  const char* a[] = {"tool", "--threshold", "3", "--profile", "wheeled", "x.txt"};
  EXPECT_EQ(profileArgument(6, a, "none"), "wheeled");
  const char* b[] = {"tool", "--profile=humanoid"};
  EXPECT_EQ(profileArgument(2, b, "none"), "humanoid");
  const char* c[] = {"tool", "x.txt", "--profile"};  // no value: the parser reports it
  EXPECT_EQ(profileArgument(3, c, "none"), "none");
}

TEST(Profile, SetFromTextReadsByTheFieldsType) {
  int i = 0;
  double d = 0;
  bool b = false;
  size_t z = 0;
  std::string s;
  EXPECT_EQ(setFromText(&i, "-3", -10, 10), "");
  EXPECT_EQ(i, -3);
  EXPECT_NE(setFromText(&i, "1e10", -10, 10), "");  // outside the range: not cast
  EXPECT_NE(setFromText(&z, "-1", 0, 100), "");
  EXPECT_EQ(setFromText(&d, "2.5e-1", 0, 1), "");
  EXPECT_DOUBLE_EQ(d, 0.25);
  EXPECT_NE(setFromText(&d, "nan", 0, 1), "");
  EXPECT_NE(setFromText(&d, "1.0junk", 0, 1), "");
  EXPECT_EQ(setFromText(&b, "true", 0, 0), "");
  EXPECT_TRUE(b);
  EXPECT_EQ(setFromText(&s, "camera_optical", 0, 0), "");
  EXPECT_EQ(s, "camera_optical");
}

TEST(Profile, ToolProfileReadsTheArgumentAndItsFiles) {
  const char* args[] = {"tool", "--profile", "humanoid", "x.png"};
  const auto profile = readToolProfile(4, args, std::string(SOURCE_DIR) + "/config", "tracker",
                                       trackerNodeParamTable(), std::string("none"));
  EXPECT_EQ(profile.name, "humanoid");
  EXPECT_TRUE(profile.errors.empty());
  EXPECT_EQ(profile.params.tracker.window_size_px, 15);
  const char* none[] = {"tool"};
  const auto fallback = readToolProfile(1, none, std::string(SOURCE_DIR) + "/config", "tracker",
                                        trackerNodeParamTable(), std::string("none"));
  EXPECT_EQ(fallback.name, "none");
  EXPECT_EQ(fallback.params.tracker.window_size_px, TrackerNodeParams().tracker.window_size_px);
  EXPECT_NE(profileHelp("planes").find("config/planes.yaml"), std::string::npos);
}

// An installed tool read its profiles from the source folder it was built from, which is
// gone wherever the package is installed from a binary package: it failed with "bad file".
TEST(ToolConfigDir, TheFolderRosFindsTheShareOrSourceInElseTheBuiltIn) {
  const char* saved = std::getenv("ROS_PACKAGE_PATH");
  const std::string saved_path = saved ? saved : "";
  const std::string built_in = "/built/from/config";

  unsetenv("ROS_PACKAGE_PATH");  // outside a ROS environment
  EXPECT_EQ(toolConfigDir(built_in), built_in);

  // An install prefix's share folder, as rospack finds it.
  const std::string share = tempPath("share");
  const std::string package = share + "/mono_plane_detection";
  std::filesystem::create_directories(package);
  std::ofstream(package + "/package.xml")
      << "<package format=\"2\"><name>mono_plane_detection</name><version>0.0.0</version>"
         "<description>d</description><maintainer email=\"a@b.c\">m</maintainer>"
         "<license>BSD</license></package>\n";
  setenv("ROS_PACKAGE_PATH", share.c_str(), 1);
  EXPECT_EQ(toolConfigDir(built_in), built_in);  // found, but without config/
  std::filesystem::create_directories(package + "/config");
  EXPECT_EQ(toolConfigDir(built_in), package + "/config");

  // A ROS environment that does not hold the package.
  const std::string other = tempPath("other_share");
  std::filesystem::create_directories(other);
  setenv("ROS_PACKAGE_PATH", other.c_str(), 1);
  EXPECT_EQ(toolConfigDir(built_in), built_in);

  if (saved)
    setenv("ROS_PACKAGE_PATH", saved_path.c_str(), 1);
  else
    unsetenv("ROS_PACKAGE_PATH");
}
