// Profiles for the command-line tools: the nodelets' YAML files (config/tracker.yaml,
// config/planes.yaml, and config/target.yaml for both) with a robot's overlay on top
// (config/<nodelet>_<profile>.yaml), read through the same parameter tables as the nodelets, so a
// tool runs with exactly the settings `roslaunch ... profile:=humanoid` gives.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "mono_plane_detection/params/param_table.h"

namespace mono_plane_detection {

// Every leaf of a YAML map as "a/b/c" -> node (the table's nested names).
inline void flattenYaml(const YAML::Node& node, const std::string& prefix,
                        std::vector<std::pair<std::string, YAML::Node>>& out) {
  for (const auto& kv : node) {
    const std::string name = prefix + kv.first.as<std::string>();
    if (kv.second.IsMap())
      flattenYaml(kv.second, name + "/", out);
    else
      out.emplace_back(name, kv.second);
  }
}

// One name of a YAML file set through the table (a problem with its value appended to
// errors); false when the table has no such name.
template <class P>
bool applyYamlKey(const std::string& path, const std::string& name, const YAML::Node& value,
                  const ParamTable<P>& table, P& params, std::vector<std::string>& errors) {
  const ParamSpec<P>* spec = findParam(table, name);
  if (!spec) return false;
  const std::string error =
      value.IsScalar() ? setFromText(spec->field(params), value.Scalar(), spec->min, spec->max)
                       : "not a single value";
  if (!error.empty()) errors.push_back(path + ": " + name + ": " + error);
  return true;
}

// Sets params from one YAML file through the table; returns one line per problem (file
// unreadable, unknown name, wrong type, out of range: the default is kept).
template <class P>
std::vector<std::string> applyYamlFile(const std::string& path, const ParamTable<P>& table,
                                       P& params) {
  std::vector<std::pair<std::string, YAML::Node>> keys;
  try {
    flattenYaml(YAML::LoadFile(path), "", keys);
  } catch (const YAML::Exception& e) {
    return {path + ": " + e.what()};
  }
  std::vector<std::string> errors;
  for (const auto& [name, value] : keys)
    if (!applyYamlKey(path, name, value, table, params, errors))
      errors.push_back(path + ": unknown parameter " + name);
  for (const std::string& error : validate(params)) errors.push_back(path + ": " + error);
  return errors;
}

// A --profile that names a .yaml file rather than a profile of config/.
inline bool isProfileFile(const std::string& profile) {
  return profile.size() > 5 && profile.substr(profile.size() - 5) == ".yaml";
}

// config/<nodelet>.yaml and config/target.yaml, then config/<nodelet>_<profile>.yaml over it
// ("default": no overlay; "none": not even the base file, the core's defaults). A profile that is a
// path to a .yaml file is read over the base file instead of an overlay.
template <class P>
std::vector<std::string> loadProfile(const std::string& config_dir, const std::string& nodelet,
                                     const std::string& profile, const ParamTable<P>& table,
                                     P& params) {
  if (profile == "none") return {};
  const bool is_file = isProfileFile(profile);
  std::vector<std::string> errors = applyYamlFile(config_dir + "/" + nodelet + ".yaml", table, params);
  // The start-up target: one file for both nodelets, loaded by both launch files (a
  // config folder without it: the defaults, which are what it holds as shipped).
  const std::string target = config_dir + "/target.yaml";
  if (std::ifstream(target))
    for (std::string& e : applyYamlFile(target, table, params)) errors.push_back(std::move(e));
  if (profile == "default" || profile.empty()) return errors;
  const std::string overlay =
      is_file ? profile : config_dir + "/" + nodelet + "_" + profile + ".yaml";
  if (!std::ifstream(overlay)) {
    errors.push_back("no profile " + overlay);
    return errors;
  }
  for (std::string& e : applyYamlFile(overlay, table, params)) errors.push_back(std::move(e));
  return errors;
}

// A tool that runs both nodelets (run_pipeline): a named profile is each nodelet's own
// overlay; a .yaml file is one file over both base files, each name set in the nodelet
// (or both) whose table has it, an error only when neither has it. (Read for each nodelet
// alone, every name of one nodelet was unknown to the other: no file could be used.)
template <class A, class B>
std::vector<std::string> loadProfiles(const std::string& config_dir, const std::string& profile,
                                      const std::string& nodelet_a, const ParamTable<A>& table_a,
                                      A& a, const std::string& nodelet_b,
                                      const ParamTable<B>& table_b, B& b) {
  const bool is_file = isProfileFile(profile);
  const std::string base = is_file ? "default" : profile;
  std::vector<std::string> errors = loadProfile(config_dir, nodelet_a, base, table_a, a);
  for (std::string& e : loadProfile(config_dir, nodelet_b, base, table_b, b))
    errors.push_back(std::move(e));
  if (!is_file) return errors;
  std::vector<std::pair<std::string, YAML::Node>> keys;
  try {
    flattenYaml(YAML::LoadFile(profile), "", keys);
  } catch (const YAML::Exception& e) {
    errors.push_back(profile + ": " + e.what());
    return errors;
  }
  for (const auto& [name, value] : keys) {
    std::vector<std::string> b_errors;  // a name both have: its problem said once
    const bool in_a = applyYamlKey(profile, name, value, table_a, a, errors);
    const bool in_b = applyYamlKey(profile, name, value, table_b, b, in_a ? b_errors : errors);
    if (!in_a && !in_b)
      errors.push_back(profile + ": unknown parameter " + name + " (neither " + nodelet_a +
                       " nor " + nodelet_b + " has it)");
  }
  for (const std::string& error : validate(a)) errors.push_back(profile + ": " + error);
  for (const std::string& error : validate(b)) errors.push_back(profile + ": " + error);
  return errors;
}

// The value of --profile (or --profile=X) before the parser runs, so that options given
// on the command line override the profile whatever their order.
inline std::string profileArgument(int argc, const char* const* argv, const std::string& fallback) {
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--profile") == 0 && i + 1 < argc) return argv[i + 1];
    if (std::strncmp(argv[i], "--profile=", 10) == 0) return argv[i] + 10;
  }
  return fallback;
}

// A tool's --profile, read before the parser runs so that the profile's values show in
// --help and options given on the command line override them.
template <class P>
struct ToolProfile {
  std::string name;                 // register &name as the "profile" option
  P params;                         // the nodelet's parameters under that profile
  std::vector<std::string> errors;  // report the first after parsing (cli.fail)
};

template <class P>
ToolProfile<P> readToolProfile(int argc, const char* const* argv, const std::string& config_dir,
                               const std::string& nodelet, const ParamTable<P>& table,
                               const std::string& fallback) {
  ToolProfile<P> profile;
  profile.name = profileArgument(argc, argv, fallback);
  profile.errors = loadProfile(config_dir, nodelet, profile.name, table, profile.params);
  return profile;
}

// The option's help, the same in every tool.
inline std::string profileHelp(const std::string& nodelet) {
  return "parameters of config/" + nodelet +
         ".yaml with the overlay of profile P (default, wheeled, humanoid) or a .yaml file "
         "over it; none: the core's defaults";
}

}  // namespace mono_plane_detection
