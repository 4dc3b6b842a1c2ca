// dynamic_reconfigure for a nodelet's runtime parameters, through its parameter table:
// cfg/Planes.cfg and cfg/Tracker.cfg are generated from the same table (param_table
// --cfg / --tracker-cfg), so the .cfg names are the table's with '/' -> '_'.
#pragma once

#include <dynamic_reconfigure/Config.h>
#include <dynamic_reconfigure/server.h>
#include <ros/ros.h>

#include <boost/any.hpp>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "mono_plane_detection/params/param_table.h"

namespace mono_plane_detection {

template <typename Config, typename NodeParams>
class ReconfigureBridge {
 public:
  // Puts `current`'s runtime values on the parameter server under the flat names, then
  // starts the server on `pnh`: it starts from them (the values the nodelet read, YAML and
  // nested names included), not from the .cfg defaults, which would override them.
  // on_change runs for every change, and once as the server starts (first true then; the
  // values are those the nodelet read).
  void start(ros::NodeHandle& pnh, const ParamTable<NodeParams>& table,
             const std::vector<std::string>& names, const NodeParams& current,
             std::function<void(Config&, bool first)> on_change) {
    table_ = &table;
    NodeParams values = current;  // (the table's accessors take a non-const object)
    for (const std::string& name : names) {
      const auto* spec = findParam(table, name);
      if (!spec) continue;  // (the tables' tests check every runtime name is there)
      const std::string flat = runtimeCfgName(name);
      cfg_names_[flat] = name;
      std::visit(
          [&](auto* v) {
            using T = std::remove_pointer_t<decltype(v)>;
            if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, double>)
              pnh.setParam(flat, *v);
            else if constexpr (!std::is_same_v<T, std::string>)
              pnh.setParam(flat, static_cast<int>(*v));
          },
          spec->field(values));
    }
    server_ = std::make_unique<dynamic_reconfigure::Server<Config>>(pnh);
    auto first = std::make_shared<bool>(true);
    server_->setCallback([on_change, first](Config& config, uint32_t) {
      on_change(config, *first);
      *first = false;
    });
  }

  void stop() { server_.reset(); }

  // The config's values over `node` (the others stay).
  void read(const Config& config, NodeParams& node) const {
    for (const auto& description : Config::__getParamDescriptions__()) {
      const auto* spec = specOf(description->name);
      if (!spec) continue;
      boost::any value;
      description->getValue(config, value);
      std::visit(
          [&](auto* v) {
            using T = std::remove_pointer_t<decltype(v)>;
            if constexpr (std::is_same_v<T, bool> || std::is_same_v<T, double>)
              *v = boost::any_cast<T>(value);
            else if constexpr (!std::is_same_v<T, std::string>)
              *v = static_cast<T>(boost::any_cast<int>(value));
          },
          spec->field(node));
    }
  }

  // The config's values over `node` (in_use's, as the nodelet runs now), checked: a value
  // out of its range (dynamic_reconfigure clamps to the .cfg's range but lets a NaN
  // through) keeps the value in use, then the node's own checks (validate(NodeParams&)).
  // What was refused is written back into the config, so that the server reports the
  // values in use. Returns one message per refusal.
  std::vector<std::string> take(Config& config, const NodeParams& in_use, NodeParams& node) const {
    node = in_use;
    read(config, node);
    std::vector<std::string> errors = validate(node, *table_, in_use, "keeping");
    for (std::string& e : validate(node)) errors.push_back(std::move(e));
    if (!errors.empty()) writeBack(node, config);
    return errors;
  }

  // The values in use, after take()'s checks repaired what was refused,
  // written back into the config: the server then reports and stores them (it showed a
  // NaN the nodelet had refused).
  void writeBack(const NodeParams& node, Config& config) const {
    NodeParams values = node;
    dynamic_reconfigure::Config message;
    config.__toMessage__(message);
    auto put = [&](auto& parameters) {
      for (auto& p : parameters) {
        const auto* spec = specOf(p.name);
        if (!spec) continue;
        std::visit(
            [&](auto* v) {
              using T = std::remove_pointer_t<decltype(v)>;
              using Out = decltype(p.value);
              if constexpr (std::is_same_v<Out, double>
                                ? std::is_same_v<T, double>
                                : std::is_integral_v<T> && !std::is_same_v<T, bool>)
                p.value = static_cast<Out>(*v);
            },
            spec->field(values));
      }
    };
    put(message.doubles);
    put(message.ints);
    config.__fromMessage__(message);
  }

 private:
  const ParamSpec<NodeParams>* specOf(const std::string& flat) const {
    const auto it = cfg_names_.find(flat);
    return it == cfg_names_.end() || !table_ ? nullptr : findParam(*table_, it->second);
  }

  const ParamTable<NodeParams>* table_ = nullptr;
  std::map<std::string, std::string> cfg_names_;  // .cfg name -> table name
  std::unique_ptr<dynamic_reconfigure::Server<Config>> server_;
};

}  // namespace mono_plane_detection
