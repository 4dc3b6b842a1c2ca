// Pose (core) <-> geometry_msgs conversions through tf2's quaternion types. The only ROS
// header under include/: used by the nodelets, the sequence reader and the tests.
#pragma once

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>

#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

inline geometry_msgs::Quaternion toQuaternionMsg(const cv::Matx33d& R) {
  const tf2::Matrix3x3 m(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1),
                         R(2, 2));
  tf2::Quaternion q;
  m.getRotation(q);
  geometry_msgs::Quaternion out;
  out.x = q.x();
  out.y = q.y();
  out.z = q.z();
  out.w = q.w();
  return out;
}

inline cv::Matx33d fromQuaternionMsg(const geometry_msgs::Quaternion& q) {
  const tf2::Matrix3x3 m(tf2::Quaternion(q.x, q.y, q.z, q.w));
  return {m[0][0], m[0][1], m[0][2], m[1][0], m[1][1], m[1][2], m[2][0], m[2][1], m[2][2]};
}

inline geometry_msgs::Transform toTransformMsg(const Pose& p) {
  geometry_msgs::Transform t;
  t.translation.x = p.t[0];
  t.translation.y = p.t[1];
  t.translation.z = p.t[2];
  t.rotation = toQuaternionMsg(p.R);
  return t;
}

inline Pose fromTransformMsg(const geometry_msgs::Transform& t) {
  return {fromQuaternionMsg(t.rotation), {t.translation.x, t.translation.y, t.translation.z}};
}

inline geometry_msgs::Pose toPoseMsg(const Pose& p) {
  geometry_msgs::Pose out;
  out.position.x = p.t[0];
  out.position.y = p.t[1];
  out.position.z = p.t[2];
  out.orientation = toQuaternionMsg(p.R);
  return out;
}

inline Pose fromPoseMsg(const geometry_msgs::Pose& p) {
  return {fromQuaternionMsg(p.orientation), {p.position.x, p.position.y, p.position.z}};
}

}  // namespace mono_plane_detection
