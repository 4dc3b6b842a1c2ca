// The folder of the nodelets' YAML files that a tool's --profile reads (profile.h).
#pragma once

#include <ros/package.h>
#include <sys/stat.h>

#include <cstdlib>
#include <string>

namespace mono_plane_detection {

// The package's config/ where ROS finds the package, as roslaunch's
// $(find mono_plane_detection) does: the share folder of an installed package, the source
// folder in a devel workspace. Outside a ROS environment (no ROS_PACKAGE_PATH), or when ROS
// does not know the package, the folder the tool was built from. Built-in only, an
// installed tool read the build machine's source tree, which is gone wherever the package
// was installed from a binary package or copied.
inline std::string toolConfigDir(const std::string& built_from) {
  const char* package_path = std::getenv("ROS_PACKAGE_PATH");
  if (!package_path || !*package_path) return built_from;  // rospack would print errors
  const std::string package = ros::package::getPath("mono_plane_detection");
  if (package.empty()) return built_from;
  const std::string config = package + "/config";
  struct stat info {};
  if (stat(config.c_str(), &info) != 0 || !S_ISDIR(info.st_mode)) return built_from;
  return config;
}

}  // namespace mono_plane_detection
