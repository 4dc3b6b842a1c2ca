// Checks a parameter read from the parameter server: an invalid value (say a negative
// size from a typo in a launch file) is replaced by the default and named in an error,
// so that the nodelet still starts and the user sees why it behaves as it does.
#pragma once

#include <ros/console.h>

#include <string>
#include <utility>

namespace mono_plane_detection {

class ParamCheck {
 public:
  explicit ParamCheck(std::string logger) : logger_(std::move(logger)) {}

  template <class T, class U>
  void operator()(bool invalid, const char* name, T& value, const U& fallback) const {
    if (!invalid) return;
    ROS_ERROR_STREAM_NAMED(
        logger_, "parameter " << name << " = " << value << " is invalid; using " << fallback);
    value = fallback;
  }

 private:
  std::string logger_;
};

}  // namespace mono_plane_detection
