// cfg/Planes.cfg and cfg/Tracker.cfg (dynamic_reconfigure) and the parameter tables agree:
// each committed file is what its table generates, and the config class built from each
// has, for every runtime parameter, the table's type, default and range (issue 14: one
// declaration per parameter).
#include <gtest/gtest.h>
#include <unistd.h>

#include <boost/any.hpp>
#include <fstream>
#include <set>
#include <sstream>

#include "mono_plane_detection/PlanesConfig.h"
#include "mono_plane_detection/TrackerConfig.h"
#include "mono_plane_detection/params/param_table.h"

using namespace mono_plane_detection;

namespace {

// The committed .cfg is what the table generates, and executable.
void expectCommittedFileIsGenerated(const std::string& file, const std::string& generated,
                                    const std::string& flag) {
  const std::string path = std::string(SOURCE_DIR) + "/cfg/" + file;
  std::ifstream in(path);
  ASSERT_TRUE(in) << path << " missing";
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), generated)
      << "cfg/" << file << " is out of date: rosrun "
      << "mono_plane_detection param_table " << flag << " > cfg/" << file;
  // dynamic_reconfigure runs the file; regenerating it by redirection drops the bit.
  EXPECT_EQ(access(path.c_str(), X_OK), 0) << "cfg/" << file << " must be executable";
}

// For every runtime parameter the config class has the table's type, default and range.
template <typename Config, typename NodeParams>
void expectTablesTypeDefaultAndRange(const ParamTable<NodeParams>& table,
                                     const std::vector<std::string>& names) {
  const Config min = Config::__getMin__(), max = Config::__getMax__(),
               def = Config::__getDefault__();
  std::set<std::string> in_cfg;
  for (const auto& d : Config::__getParamDescriptions__()) in_cfg.insert(d->name);
  EXPECT_EQ(in_cfg.size(), names.size());
  NodeParams defaults;
  for (const std::string& name : names) {
    const auto* spec = findParam(table, name);
    ASSERT_NE(spec, nullptr) << name;
    const std::string cfg = runtimeCfgName(name);
    ASSERT_TRUE(in_cfg.count(cfg)) << cfg;
    for (const auto& d : Config::__getParamDescriptions__()) {
      if (d->name != cfg) continue;
      boost::any lo, hi, value;
      d->getValue(min, lo);
      d->getValue(max, hi);
      d->getValue(def, value);
      const ParamField field = spec->field(defaults);
      if (d->type == "double") {
        EXPECT_EQ(boost::any_cast<double>(value), *std::get<double*>(field)) << name;
        EXPECT_EQ(boost::any_cast<double>(lo), spec->min) << name;
        EXPECT_EQ(boost::any_cast<double>(hi), spec->max) << name;
      } else if (d->type == "int") {
        EXPECT_EQ(boost::any_cast<int>(value), numericValue(field)) << name;
        EXPECT_EQ(boost::any_cast<int>(lo), spec->min) << name;
        EXPECT_EQ(boost::any_cast<int>(hi), spec->max) << name;
      } else {
        EXPECT_EQ(d->type, "bool") << name;
        EXPECT_EQ(boost::any_cast<bool>(value), *std::get<bool*>(field)) << name;
      }
    }
  }
}

}  // namespace

TEST(PlanesCfg, CommittedFileIsWhatTheTableGenerates) {
  expectCommittedFileIsGenerated("Planes.cfg", dynamicReconfigureCfg(), "--cfg");
}

TEST(PlanesCfg, EveryRuntimeParameterHasTheTablesTypeDefaultAndRange) {
  expectTablesTypeDefaultAndRange<PlanesConfig>(planeNodeParamTable(), planeRuntimeParamNames());
}

TEST(TrackerCfg, CommittedFileIsWhatTheTableGenerates) {
  expectCommittedFileIsGenerated("Tracker.cfg", trackerReconfigureCfg(), "--tracker-cfg");
}

TEST(TrackerCfg, EveryRuntimeParameterHasTheTablesTypeDefaultAndRange) {
  expectTablesTypeDefaultAndRange<TrackerConfig>(trackerNodeParamTable(),
                                                 trackerRuntimeParamNames());
}

// The structural parameters, which FeatureTracker::setParams refuses, are not offered.
TEST(TrackerCfg, OffersNoParameterThatSizesThePyramids) {
  for (const char* name : {"pyramid_levels", "window_size_px", "reanchor_window_px"})
    for (const auto& d : TrackerConfig::__getParamDescriptions__()) EXPECT_NE(d->name, name);
}
