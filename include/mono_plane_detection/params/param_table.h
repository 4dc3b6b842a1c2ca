// One declaration per parameter: a table per Params struct gives each field its name
// (the ROS parameter and YAML key, '/' for a nested struct), its range, unit and
// meaning; the default is the struct's own default member initializer. From the table
// come validate() (core, nodelets, tools, tests), the nodelets' parameter reading and
// docs/parameters.md (param_table --markdown). ROS-free.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "mono_plane_detection/mapping/plane_pipeline.h"
#include "mono_plane_detection/tracking/feature_tracker.h"
#include "mono_plane_detection/tracking/target_detector.h"

namespace mono_plane_detection {

// Where one parameter lives inside a Params object.
using ParamField = std::variant<int*, double*, bool*, size_t*, unsigned*, std::string*>;

template <class P>
struct ParamSpec {
  // A table row: {name, field, min, max, unit, description} or with an old name (a
  // constructor rather than an aggregate, so that rows without one need not name it).
  ParamSpec(std::string name_, std::function<ParamField(P&)> field_, double min_, double max_,
            std::string unit_, std::string description_, std::string old_name_ = "")
      : name(std::move(name_)),
        field(std::move(field_)),
        min(min_),
        max(max_),
        unit(std::move(unit_)),
        description(std::move(description_)),
        old_name(std::move(old_name_)) {}

  std::string name;                       // ROS name and YAML key path ("pose/max_jump_m")
  std::function<ParamField(P&)> field;    // the struct member it sets
  double min = 0, max = 0;                // inclusive range (numbers only)
  std::string unit;                       // "px", "m", "s", "deg", "" for counts and ratios
  std::string description;                // one line for people
  std::string old_name;                   // accepted with a warning, "" when none
};

template <class P>
using ParamTable = std::vector<ParamSpec<P>>;

// The field accessor of a member: field(&TrackerParams::max_features).
template <class P, class T>
std::function<ParamField(P&)> field(T P::*member) {
  return [member](P& p) -> ParamField { return &(p.*member); };
}

// A sub-struct's table inside its parent's, names prefixed ("pose/" + "max_jump_m").
template <class P, class Sub>
void appendNested(ParamTable<P>& table, const std::string& prefix, Sub P::*member,
                  const ParamTable<Sub>& sub) {
  for (const ParamSpec<Sub>& s : sub) {
    ParamSpec<P> spec{prefix + s.name, nullptr, s.min, s.max, s.unit, s.description, ""};
    auto inner = s.field;
    spec.field = [member, inner](P& p) { return inner(p.*member); };
    if (!s.old_name.empty()) spec.old_name = s.old_name;
    table.push_back(std::move(spec));
  }
}

std::string toString(const ParamField& value);
bool isNumber(const ParamField& value);
// The value as a double (numbers; bool as 0/1); NaN for strings.
double numericValue(const ParamField& value);

// Empty when the value is in range, else "NAME = VALUE is out of range [MIN, MAX] UNIT".
// Sets a field from a value written as text (a YAML scalar, a command-line value): the
// field's type decides how it is read. Empty when set, else why not (not a number, not a
// whole number in [min, max], not true/false). Ranges of numbers are validate()'s job.
std::string setFromText(const ParamField& field, const std::string& text, double min,
                        double max);

template <class P>
std::string rangeError(const ParamSpec<P>& spec, const ParamField& value) {
  if (!isNumber(value)) return {};
  const double v = numericValue(value);
  if (std::isfinite(v) && v >= spec.min && v <= spec.max) return {};
  std::ostringstream why;
  why << spec.name << " = " << toString(value) << " is out of range [" << spec.min << ", "
      << spec.max << "]" << (spec.unit.empty() ? "" : " ") << spec.unit;
  return why.str();
}

// Puts `fallback`'s value back into every out-of-range field of `params` and returns one
// message per field ("NAME = VALUE is out of range [MIN, MAX]; <using> D"): at start the
// defaults ("using the default"), while running the values in use ("keeping": a bad input
// is dropped, the state kept). (fallback_values by value: a spec's field() reaches a
// field through a mutable P.)
template <class P>
std::vector<std::string> validate(P& params, const ParamTable<P>& table, P fallback_values,
                                  const std::string& using_text) {
  std::vector<std::string> errors;
  for (const ParamSpec<P>& spec : table) {
    const ParamField value = spec.field(params);
    std::string error = rangeError(spec, value);
    if (error.empty()) continue;
    const ParamField fallback = spec.field(fallback_values);
    error += "; " + using_text + " " + toString(fallback);
    std::visit(
        [&](auto* target) {
          using T = std::remove_pointer_t<decltype(target)>;
          *target = *std::get<T*>(fallback);
        },
        value);
    errors.push_back(std::move(error));
  }
  return errors;
}

// The same with the defaults of a default-constructed P.
template <class P>
std::vector<std::string> validate(P& params, const ParamTable<P>& table) {
  return validate(params, table, P(), "using the default");
}

template <class P>
const ParamSpec<P>* findParam(const ParamTable<P>& table, const std::string& name) {
  for (const ParamSpec<P>& spec : table)
    if (spec.name == name || (!spec.old_name.empty() && spec.old_name == name)) return &spec;
  return nullptr;
}

// A Markdown table: name, default, range, unit, meaning.
template <class P>
std::string toMarkdown(const ParamTable<P>& table, const std::vector<std::string>& live = {}) {
  std::ostringstream out;
  out << "| parameter | default | range | unit | meaning |\n|---|---|---|---|---|\n";
  P defaults;
  for (const ParamSpec<P>& spec : table) {
    const ParamField value = spec.field(defaults);
    std::ostringstream range;
    if (isNumber(value)) range << spec.min << " .. " << spec.max;
    const bool is_live = std::find(live.begin(), live.end(), spec.name) != live.end();
    out << "| `" << spec.name << "` | " << toString(value) << " | " << range.str() << " | "
        << spec.unit << " | " << spec.description
        << (spec.old_name.empty() ? "" : " (was `" + spec.old_name + "`)")
        << (is_live ? " (**live**)" : "") << " |\n";
  }
  return out.str();
}

// The nodelets' parameters beyond the core structs (node behaviour, frames, topics).
struct TrackerNodeParams {
  TrackerParams tracker;  // names without prefix: max_features, ...
  TargetParams target;    // target/width_m, ...
  bool lazy = true;
  bool detect_target = true;
  bool rectified = false;  // the images are rectified (P, no distortion)
  double max_gap_s = 1.0;
  double target_timeout_s = 30.0;  // WARN when images come this long without a target
  std::string image_transport = "raw";
  double expected_min_rate_hz = 5.0;
  double expected_max_rate_hz = 100.0;
};

struct PlaneNodeParams {
  PipelineParams pipeline;  // frame_gap, planes/..., pose/..., map/..., target/...
  std::string map_frame = "plane_map";
  std::string odom_frame;
  bool publish_tf = true;
  std::string tf_mode = "auto";      // auto | above_odom | below_odom (docs/ros_interface.md)
  std::string camera_frame;          // no odometry: child of map_frame; "" = <tracks frame>_estimate
  bool rectified = false;            // the tracks are of rectified images (P, no distortion)
  double target_timeout_s = 30.0;
  std::string image_transport = "raw";
  double max_odom_jump_m = 1.0;
  double odom_wait_s = 0.25;         // tracks wait this long for odometry at their stamp
  double expected_min_rate_hz = 5.0;
  double expected_max_rate_hz = 100.0;
};

// The tables. Each parameter of the core structs is declared here once.
const ParamTable<TrackerParams>& trackerParamTable();
const ParamTable<TargetParams>& targetParamTable();
const ParamTable<GroupParams>& groupParamTable();
const ParamTable<PlaneParams>& planeParamTable();
const ParamTable<TwoViewParams>& twoViewParamTable();
const ParamTable<PoseParams>& poseParamTable();
const ParamTable<MapParams>& mapParamTable();
const ParamTable<PipelineParams>& pipelineParamTable();
const ParamTable<TrackerNodeParams>& trackerNodeParamTable();
const ParamTable<PlaneNodeParams>& planeNodeParamTable();

// The PlaneNodelet parameters that can change while it runs (dynamic_reconfigure): read
// anew on every image. Table names; in cfg/Planes.cfg each is the name with '/' -> '_'.
const std::vector<std::string>& planeRuntimeParamNames();
std::string runtimeCfgName(const std::string& table_name);

// The TrackerNodelet parameters that can change while it runs (dynamic_reconfigure): those
// FeatureTracker::setParams takes between images (not the pyramid or the windows).
const std::vector<std::string>& trackerRuntimeParamNames();

// cfg/Planes.cfg and cfg/Tracker.cfg (dynamic_reconfigure), generated from the tables for
// those parameters (param_table --cfg / --tracker-cfg; test_planes_cfg checks the committed
// files are up to date).
std::string dynamicReconfigureCfg();
std::string trackerReconfigureCfg();

// docs/parameters.md: both nodelets' tables (generated; test_param_table checks the
// committed file is up to date).
std::string parametersMarkdown();

// validate() with the checks that tie two parameters together (rate window order).
std::vector<std::string> validate(TrackerNodeParams& params);
std::vector<std::string> validate(PlaneNodeParams& params);
// Why the metric source set cannot give metres (odometry without odom_frame, camera_height
// without a height), "" when it can: a configuration error that stays until fixed.
std::string metricSourceProblem(const PlaneNodeParams& params);
std::vector<std::string> validate(TrackerParams& params);
std::vector<std::string> validate(PipelineParams& params);

}  // namespace mono_plane_detection
