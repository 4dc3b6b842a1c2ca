// cfg/Planes.cfg (dynamic_reconfigure) and the parameter table agree: the committed file is
// what the table generates, and the config class built from it has, for every runtime
// parameter, the table's type, default and range (issue 14: one declaration per parameter).
#include <gtest/gtest.h>

#include <boost/any.hpp>
#include <fstream>
#include <set>
#include <sstream>
#include <unistd.h>

#include "mono_plane_detection/PlanesConfig.h"
#include "mono_plane_detection/params/param_table.h"

using namespace mono_plane_detection;

TEST(PlanesCfg, CommittedFileIsWhatTheTableGenerates) {
  std::ifstream file(std::string(SOURCE_DIR) + "/cfg/Planes.cfg");
  ASSERT_TRUE(file) << "cfg/Planes.cfg missing";
  std::stringstream text;
  text << file.rdbuf();
  EXPECT_EQ(text.str(), dynamicReconfigureCfg())
      << "cfg/Planes.cfg is out of date: rosrun mono_plane_detection param_table --cfg > "
         "cfg/Planes.cfg";
  // dynamic_reconfigure runs the file; regenerating it by redirection drops the bit.
  EXPECT_EQ(access((std::string(SOURCE_DIR) + "/cfg/Planes.cfg").c_str(), X_OK), 0)
      << "cfg/Planes.cfg must be executable: chmod +x cfg/Planes.cfg";
}

TEST(PlanesCfg, EveryRuntimeParameterHasTheTablesTypeDefaultAndRange) {
  const PlanesConfig min = PlanesConfig::__getMin__(), max = PlanesConfig::__getMax__(),
                     def = PlanesConfig::__getDefault__();
  std::set<std::string> in_cfg;
  for (const auto& d : PlanesConfig::__getParamDescriptions__()) in_cfg.insert(d->name);
  EXPECT_EQ(in_cfg.size(), planeRuntimeParamNames().size());
  PlaneNodeParams defaults;
  for (const std::string& name : planeRuntimeParamNames()) {
    const auto* spec = findParam(planeNodeParamTable(), name);
    ASSERT_NE(spec, nullptr) << name;
    const std::string cfg = runtimeCfgName(name);
    ASSERT_TRUE(in_cfg.count(cfg)) << cfg;
    for (const auto& d : PlanesConfig::__getParamDescriptions__()) {
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
