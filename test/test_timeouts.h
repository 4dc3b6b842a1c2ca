// How long the rostest nodes wait for the nodelet under test. `make helgrind` runs the
// manager under valgrind, some 50 times slower, and passes ~timeout_scale to stretch
// every deadline; normal runs use 1.
#pragma once

#include <ros/ros.h>

inline double& timeoutScale() {
  static double scale = 1.0;
  return scale;
}

inline void readTimeoutScale() { ros::param::param("~timeout_scale", timeoutScale(), 1.0); }

inline ros::WallDuration scaledWait(double seconds) {
  return ros::WallDuration(seconds * timeoutScale());
}
