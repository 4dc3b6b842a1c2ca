// Reads a parameter table (param_table.h) from a private node handle: one loop for every
// parameter, the ROS name being the table's name. A value of the wrong type or out of
// range is named in an ERROR and the default is used; an old flat name still works, with
// a warning naming the new one. Returns the errors (for the nodelet's diagnostics).
#pragma once

#include <ros/ros.h>

#include <sstream>
#include <string>
#include <vector>

#include "mono_plane_detection/params/param_table.h"

namespace mono_plane_detection {

template <class P>
std::vector<std::string> readParams(const ros::NodeHandle& pnh, const ParamTable<P>& table,
                                    P& params, const std::string& logger) {
  std::vector<std::string> errors;
  for (const ParamSpec<P>& spec : table) {
    std::string key = spec.name;
    if (!pnh.hasParam(key)) {
      if (spec.old_name.empty() || !pnh.hasParam(spec.old_name)) continue;
      ROS_WARN_STREAM_NAMED(logger, "parameter " << spec.old_name << " is now called "
                                                 << spec.name << ": please rename it");
      key = spec.old_name;
    }
    std::visit(
        [&](auto* value) {
          using T = std::remove_pointer_t<decltype(value)>;
          // ros::param has no size_t or unsigned overloads: read a double, check the range.
          using Read = std::conditional_t<std::is_same_v<T, size_t> || std::is_same_v<T, unsigned>,
                                          double, T>;
          Read read{};
          if (!pnh.getParam(key, read)) {
            errors.push_back(key + " has the wrong type (expected " +
                             (std::is_same_v<T, bool>          ? "a boolean"
                              : std::is_same_v<T, std::string> ? "a string"
                              : std::is_same_v<T, double>      ? "a number"
                                                               : "an integer") +
                             "); using " + toString(ParamField(value)));
            ROS_ERROR_STREAM_NAMED(logger, "parameter " << errors.back());
            return;
          }
          if constexpr (std::is_same_v<Read, double> && !std::is_same_v<T, double>) {
            if (!(read >= spec.min && read <= spec.max) || read != std::floor(read)) {
              std::ostringstream why;
              why << key << " = " << read << " is not an integer in [" << spec.min << ", "
                  << spec.max << "]; using " << *value;
              errors.push_back(why.str());
              ROS_ERROR_STREAM_NAMED(logger, "parameter " << errors.back());
              return;
            }
          }
          *value = static_cast<T>(read);
        },
        spec.field(params));
  }
  for (const std::string& error : validate(params)) {
    ROS_ERROR_STREAM_NAMED(logger, "parameter " << error);
    errors.push_back(error);
  }
  return errors;
}

// For diagnostics: "parameter refused, default used: <first>" (+ how many more).
inline std::string refusedParamsText(const std::vector<std::string>& errors) {
  if (errors.empty()) return {};
  std::string text = (errors.size() == 1 ? std::string("parameter refused, default used: ")
                                         : std::to_string(errors.size()) +
                                               " parameters refused, defaults used (see the log): ") +
                     errors.front();
  return text;
}

// The parameters refused at start and by the last reconfigure ("reconfigure: ..."), for
// refusedParamsText: both nodelets list them alike.
inline std::vector<std::string> refusedParams(const std::vector<std::string>& at_start,
                                              const std::vector<std::string>& by_reconfigure) {
  std::vector<std::string> all = at_start;
  for (const std::string& e : by_reconfigure) all.push_back("reconfigure: " + e);
  return all;
}

}  // namespace mono_plane_detection
