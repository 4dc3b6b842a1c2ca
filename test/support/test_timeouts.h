// How long the rostest nodes wait for the node under test. `make helgrind` runs the
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

// Runs this node's callbacks until done() holds or `seconds` (scaled) have passed;
// returns done().
template <class Done>
bool spinUntil(Done done, double seconds) {
  const ros::WallTime deadline = ros::WallTime::now() + scaledWait(seconds);
  while (ros::ok() && !done() && ros::WallTime::now() < deadline) {
    ros::spinOnce();
    ros::WallDuration(0.002).sleep();
  }
  return done();
}
