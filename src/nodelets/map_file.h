// ~save_map's file: the map's planes as YAML (planesYaml) written to a path.
#pragma once

#include <string>

#include "mono_plane_detection/PlaneArray.h"

namespace mono_plane_detection {

struct MapFileResult {
  bool success = false;
  int planes = 0;       // metric planes written
  std::string message;  // "wrote N planes to PATH", or why nothing was written
};

// Writes `planes` (null: no map yet) as YAML to `path`; refuses an empty path first. A
// relative path is relative to this process's working directory (the manager's:
// ROS_HOME, ~/.ros, under roslaunch; not the caller's), so the message names the whole
// path.
MapFileResult writeMapFile(const PlaneArray* planes, const std::string& path);

}  // namespace mono_plane_detection
