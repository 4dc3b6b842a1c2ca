// The parameter tables: defaults in range, validate() names and repairs bad values,
// docs/parameters.md is what the tables generate, config/*.yaml uses only known names
// with values in range.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <tuple>

#include "../../src/tools/profile.h"

#include <dirent.h>

#include <cmath>
#include <limits>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

#include "mono_plane_detection/params/param_table.h"

using namespace mono_plane_detection;

namespace {

template <class P>
void expectSound(const ParamTable<P>& table) {
  std::set<std::string> names;
  P defaults;
  for (const auto& spec : table) {
    EXPECT_TRUE(names.insert(spec.name).second) << "twice: " << spec.name;
    EXPECT_FALSE(spec.description.empty()) << spec.name;
    EXPECT_EQ(rangeError(spec, spec.field(defaults)), "") << "default out of its own range";
    if (isNumber(spec.field(defaults))) {
      EXPECT_LT(spec.min, spec.max) << spec.name;
    }
  }
  EXPECT_TRUE(validate(defaults, table).empty());
}

}  // namespace

TEST(ParamTable, DefaultsAreInRangeAndNamesUnique) {
  expectSound(trackerParamTable());
  expectSound(targetParamTable());
  expectSound(pipelineParamTable());
  expectSound(trackerNodeParamTable());
  expectSound(planeNodeParamTable());
  // The stages' own tables (the pipeline's holds them nested).
  expectSound(groupParamTable());
  expectSound(planeParamTable());
  expectSound(twoViewParamTable());
  expectSound(poseParamTable());
  expectSound(mapParamTable());
  EXPECT_EQ(trackerNodeParamTable().size(),
            trackerParamTable().size() + targetParamTable().size() + 8);  // + node params, rectified
}

TEST(ParamTable, NestedNamesReachTheNestedFields) {
  PipelineParams p;
  const auto* spec = findParam(pipelineParamTable(), "map/max_residual_m");
  ASSERT_NE(spec, nullptr);
  *std::get<double*>(spec->field(p)) = 0.25;
  EXPECT_EQ(p.map.max_residual_m, 0.25);
  spec = findParam(pipelineParamTable(), "planes/groups/seed");
  ASSERT_NE(spec, nullptr);
  *std::get<unsigned*>(spec->field(p)) = 7;
  EXPECT_EQ(p.planes.groups.seed, 7u);
  // Old flat names find the same entry.
  EXPECT_EQ(findParam(pipelineParamTable(), "plane_max_residual_m")->name, "map/max_residual_m");
  EXPECT_EQ(findParam(pipelineParamTable(), "start_parallax_deg")->name,
            "pose/two_view/min_parallax_deg");
}

TEST(ParamTable, AppendNestedPrefixesNamesAndKeepsEachRow) {
  // appendNested on its own, with two toy structs: each row of the sub-table once, its
  // name prefixed, its range, unit, description and old name as they were, its field
  // the nested member's.
  struct Inner {
    double gain = 1.5;
    int count = 3;
  };
  struct Outer {
    Inner inner;
    int own = 0;
  };
  const ParamTable<Inner> inner{
      {"gain", field(&Inner::gain), 0.0, 10.0, "px", "how much", "old_gain"},
      {"count", field(&Inner::count), 1, 9, "", "how many"}};
  ParamTable<Outer> outer{{"own", field(&Outer::own), 0, 5, "", "its own"}};
  appendNested(outer, "inner/", &Outer::inner, inner);
  ASSERT_EQ(outer.size(), 3u);
  EXPECT_EQ(outer[0].name, "own");
  EXPECT_EQ(outer[1].name, "inner/gain");
  EXPECT_EQ(outer[1].old_name, "old_gain");
  EXPECT_EQ(outer[1].unit, "px");
  EXPECT_EQ(outer[1].description, "how much");
  EXPECT_EQ(outer[1].max, 10.0);
  EXPECT_EQ(outer[2].name, "inner/count");
  EXPECT_EQ(outer[2].old_name, "");
  EXPECT_EQ(outer[2].min, 1.0);
  Outer o;
  EXPECT_EQ(*std::get<double*>(outer[1].field(o)), 1.5);
  *std::get<int*>(outer[2].field(o)) = 7;
  EXPECT_EQ(o.inner.count, 7);
  // validate() reaches the nested field through it.
  o.inner.gain = 11;
  const std::vector<std::string> errors = validate(o, outer);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("inner/gain = 11"), std::string::npos) << errors[0];
  EXPECT_EQ(o.inner.gain, 1.5);
}

// Issue 15, cases 5 and 8: these values reached OpenCV (assert) or took 8 s per image.
TEST(ParamTable, ValidateRepairsOutOfRangeValuesAndSaysWhy) {
  TrackerParams p;
  p.min_distance_px = -5;
  p.reanchor_window_px = 1000;
  p.window_size_px = 2001;
  p.quality_level = std::nan("");
  p.max_features = 150;  // valid: kept
  const auto errors = validate(p);
  ASSERT_EQ(errors.size(), 4u);
  EXPECT_EQ(errors[0], "min_distance_px = -5 is out of range [0, 200] px; using the default 15");
  EXPECT_NE(errors[1].find("quality_level = nan"), std::string::npos) << errors[1];
  EXPECT_EQ(errors[2], "window_size_px = 2001 is out of range [3, 51] px; using the default 7");
  EXPECT_EQ(errors[3], "reanchor_window_px = 1000 is out of range [1, 15] px; using the default 3");
  const TrackerParams d;
  EXPECT_EQ(p.min_distance_px, d.min_distance_px);
  EXPECT_EQ(p.reanchor_window_px, d.reanchor_window_px);
  EXPECT_EQ(p.window_size_px, d.window_size_px);
  EXPECT_EQ(p.quality_level, d.quality_level);
  EXPECT_EQ(p.max_features, 150);
}

// While a nodelet runs (dynamic_reconfigure) a refused value keeps the value in use.
TEST(ParamTable, ValidateAgainstTheValuesInUseKeepsThem) {
  TrackerParams in_use;
  in_use.quality_level = 0.02;
  TrackerParams p = in_use;
  p.quality_level = std::nan("");
  p.max_features = 150;  // valid: taken
  const auto errors = validate(p, trackerParamTable(), in_use, "keeping");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("quality_level = nan"), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("; keeping 0.02"), std::string::npos) << errors[0];
  EXPECT_EQ(p.quality_level, 0.02);
  EXPECT_EQ(p.max_features, 150);
}

TEST(ParamTable, ValidateNestedAndNodeParams) {
  PlaneNodeParams p;
  p.pipeline.map.max_planes = 0;
  p.pipeline.planes.min_plane_support = 4;
  p.max_odom_jump_m = INFINITY;
  p.expected_min_rate_hz = 50;
  p.expected_max_rate_hz = 10;
  const auto errors = validate(p);
  ASSERT_EQ(errors.size(), 4u);
  EXPECT_NE(errors[0].find("planes/min_plane_support = 4"), std::string::npos) << errors[0];
  EXPECT_NE(errors[1].find("map/max_planes = 0"), std::string::npos) << errors[1];
  EXPECT_NE(errors[2].find("max_odom_jump_m = inf"), std::string::npos) << errors[2];
  EXPECT_NE(errors[3].find("expected_min_rate_hz = 50 is above"), std::string::npos);
  const PlaneNodeParams d;
  EXPECT_EQ(p.pipeline.map.max_planes, d.pipeline.map.max_planes);
  EXPECT_EQ(p.expected_min_rate_hz, d.expected_min_rate_hz);
}

// The core's own parameters (no ROS: the offline tools, the tests) validate alike.
TEST(ParamTable, ValidatePipelineParams) {
  PipelineParams p;
  EXPECT_TRUE(validate(p).empty());
  p.frame_gap = 0;
  p.map.max_planes = 0;
  const auto errors = validate(p);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_NE(errors[0].find("frame_gap = 0"), std::string::npos) << errors[0];
  EXPECT_NE(errors[1].find("map/max_planes = 0"), std::string::npos) << errors[1];
  EXPECT_EQ(p.frame_gap, PipelineParams().frame_gap);
  EXPECT_EQ(p.map.max_planes, PipelineParams().map.max_planes);
}

// A metric source that cannot give metres is named (the plane nodelet's ERROR).
TEST(ParamTable, MetricSourceProblems) {
  PlaneNodeParams p;
  EXPECT_EQ(metricSourceProblem(p), "");  // target
  p.pipeline.pose.metric_source = "odometry";
  EXPECT_EQ(metricSourceProblem(p),
            "pose/metric_source odometry needs odom_frame: no metres until it is set");
  p.odom_frame = "odom";
  EXPECT_EQ(metricSourceProblem(p), "");
  p.pipeline.pose.metric_source = "camera_height";
  EXPECT_NE(metricSourceProblem(p).find("needs pose/camera_height_m > 0"), std::string::npos);
  p.pipeline.pose.floor.camera_height_m = 1.2;
  EXPECT_EQ(metricSourceProblem(p), "");
}

TEST(ParamTable, FieldValuesAsText) {
  bool b = true;
  int i = -3;
  double d = 0.25;
  std::string s = "odom";
  EXPECT_EQ(toString(ParamField(&b)), "true");
  EXPECT_EQ(toString(ParamField(&i)), "-3");
  EXPECT_EQ(toString(ParamField(&d)), "0.25");
  EXPECT_EQ(toString(ParamField(&s)), "\"odom\"");
  double nan = -std::numeric_limits<double>::quiet_NaN();  // (sign bit set)
  EXPECT_EQ(toString(ParamField(&nan)), "nan");
}

// The hostile new-user try: map_frame "" was taken and put on tf as a frame named "".
TEST(ParamTable, FrameNamesTfWouldRefuseAreRepaired) {
  PlaneNodeParams p;
  p.map_frame = "";
  auto errors = validate(p);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("map_frame = '' is empty"), std::string::npos) << errors[0];
  EXPECT_EQ(p.map_frame, "plane_map");
  p.odom_frame = "/odom";
  p.map_frame = "odom";
  errors = validate(p);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_NE(errors[0].find("'/odom' starts with '/'"), std::string::npos) << errors[0];
  EXPECT_NE(errors[1].find("is also the odom_frame"), std::string::npos) << errors[1];
  EXPECT_EQ(p.odom_frame, "odom");
  EXPECT_EQ(p.map_frame, "plane_map");
  // The default would clash again: another name.
  PlaneNodeParams clash;
  clash.odom_frame = "plane_map";
  errors = validate(clash);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(clash.map_frame, "plane_map_mono") << errors[0];
  PlaneNodeParams ok;
  ok.odom_frame = "odom";
  ok.camera_frame = "camera_estimate";
  EXPECT_TRUE(validate(ok).empty());
}

TEST(ParamTable, MarkdownHasOneRowPerParameter) {
  const std::string md = toMarkdown(trackerParamTable());
  size_t rows = 0;
  for (char c : md) rows += c == '\n';
  EXPECT_EQ(rows, trackerParamTable().size() + 2);
  EXPECT_NE(md.find("| `window_size_px` | 7 | 3 .. 51 | px |"), std::string::npos) << md;
  // The runtime parameters (dynamic_reconfigure) are marked live, the others not.
  const std::string live = toMarkdown(trackerParamTable(), trackerRuntimeParamNames());
  const auto row = [&](const std::string& name) {
    const size_t at = live.find("| `" + name + "` |");
    return at == std::string::npos ? std::string() : live.substr(at, live.find('\n', at) - at);
  };
  EXPECT_NE(row("max_features").find("(**live**)"), std::string::npos) << row("max_features");
  EXPECT_EQ(row("window_size_px").find("(**live**)"), std::string::npos) << row("window_size_px");
  EXPECT_EQ(md.find("**live**"), std::string::npos);  // none without the list
}

TEST(ParamTable, CommittedDocsAreUpToDate) {
  std::ifstream file(std::string(SOURCE_DIR) + "/docs/parameters.md");
  ASSERT_TRUE(file) << "docs/parameters.md missing";
  std::stringstream committed;
  committed << file.rdbuf();
  EXPECT_EQ(committed.str(), parametersMarkdown())
      << "docs/parameters.md is out of date: rosrun mono_plane_detection param_table "
         "--markdown > docs/parameters.md";
}

namespace {

// Every key known, current and in range: what applyYamlFile (the tools' --profile) and the
// nodelets' table reader both accept without a word.
template <class P>
void checkConfig(const std::string& path, const ParamTable<P>& table) {
  SCOPED_TRACE(path);
  P params;
  for (const std::string& error : applyYamlFile(path, table, params)) ADD_FAILURE() << error;
  std::vector<std::pair<std::string, YAML::Node>> keys;
  flattenYaml(YAML::LoadFile(path), "", keys);
  EXPECT_FALSE(keys.empty());
  for (const auto& [name, value] : keys) {
    const ParamSpec<P>* spec = findParam(table, name);
    ASSERT_NE(spec, nullptr) << "unknown parameter " << name;
    EXPECT_EQ(spec->name, name) << "old name in the config";
  }
}

}  // namespace

TEST(ParamTable, ConfigFilesUseKnownNamesInRange) {
  const std::string dir = std::string(SOURCE_DIR) + "/config";
  DIR* d = opendir(dir.c_str());
  ASSERT_NE(d, nullptr);
  int files = 0;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    if (name.size() < 5 || name.substr(name.size() - 5) != ".yaml") continue;
    ++files;
    if (name.rfind("tracker", 0) == 0)
      checkConfig(dir + "/" + name, trackerNodeParamTable());
    else if (name.rfind("planes", 0) == 0)
      checkConfig(dir + "/" + name, planeNodeParamTable());
    else if (name == "target.yaml") {  // loaded by both nodelets: known to both
      checkConfig(dir + "/" + name, trackerNodeParamTable());
      checkConfig(dir + "/" + name, planeNodeParamTable());
    } else
      ADD_FAILURE() << "config/" << name << ": which nodelet?";
  }
  closedir(d);
  EXPECT_EQ(files, 7);
}

// A parameter a launch file sets only when its argument is given (<param if=...>) must have
// its value in the config the same node loads on every launch: otherwise an earlier
// launch's value stays on the parameter server (metric_source:=odometry once, and the
// next plain launch waited for odometry).
TEST(ParamTable, ParamsLaunchFilesSetConditionallyAreInTheConfig) {
  const std::string dir = std::string(SOURCE_DIR);
  for (const auto& [launch_file, config, least] :
       std::vector<std::tuple<std::string, std::string, int>>{
           // pose/metric_source, pose/camera_height_m, odom_frame, map_frame, tf_mode, rectified
           {"planes.launch", "planes.yaml", 6},
           {"tracker.launch", "tracker.yaml", 3}}) {  // lazy, detect_target, rectified
    std::vector<std::pair<std::string, YAML::Node>> keys;
    flattenYaml(YAML::LoadFile(dir + "/config/" + config), "", keys);
    std::set<std::string> in_config;
    for (const auto& key : keys) in_config.insert(key.first);
    std::ifstream launch(dir + "/launch/" + launch_file);
    ASSERT_TRUE(launch.good()) << launch_file;
    const std::string text((std::istreambuf_iterator<char>(launch)),
                           std::istreambuf_iterator<char>());
    int conditional = 0;
    for (size_t at = text.find("<param if="); at != std::string::npos;
         at = text.find("<param if=", at + 1)) {
      const size_t name = text.find("name=\"", at) + 6;
      const std::string param = text.substr(name, text.find('"', name) - name);
      ++conditional;
      EXPECT_TRUE(in_config.count(param))
          << param << " is set only with its launch argument (" << launch_file << ")";
    }
    EXPECT_GE(conditional, least) << launch_file;
  }
}

// Issue 12: target_type and the marker's dictionary are names the ranges cannot check:
// an unknown one is an error naming it, and the defaults are used.
TEST(ParamTable, UnknownTargetTypeOrDictionaryFallsBack) {
  TrackerNodeParams p;
  p.target.target_type = "checkerboard";
  auto errors = validate(p);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("checkerboard"), std::string::npos) << errors[0];
  EXPECT_EQ(p.target.target_type, "sheet");
  PlaneNodeParams q;
  q.pipeline.target.target_type = "aruco";
  q.pipeline.target.dictionary = "DICT_9X9_1";
  errors = validate(q);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("DICT_9X9_1"), std::string::npos) << errors[0];
  EXPECT_EQ(q.pipeline.target.dictionary, "DICT_4X4_50");
  TrackerNodeParams ok;
  ok.target.target_type = "aruco";
  ok.target.marker_id = 12;
  EXPECT_TRUE(validate(ok).empty());
  EXPECT_EQ(ok.target.target_type, "aruco");
}
