// The ROS map frame against the core's target frame (include/mono_plane_detection/ros/map_frame.h).
#include <gtest/gtest.h>

#include <cmath>

#include "mono_plane_detection/ros/map_frame.h"
#include "mono_plane_detection/sim/camera_trajectory.h"

using namespace mono_plane_detection;

namespace {
cv::Vec3d tiltedUp(double deg) {  // z up tilted by deg towards +x
  return {std::sin(deg * CV_PI / 180), 0, std::cos(deg * CV_PI / 180)};
}
}  // namespace

// REP 103 with the target upright on a wall: its up is the map's z, the direction out
// of the wall (towards the camera) is -x, its width (to the right seen from the camera) -y.
TEST(MapFrame, TargetUprightOnAWallGivesZUp) {
  const cv::Matx33d& R = rosMapFromTarget().R;
  EXPECT_LT(cv::norm(R * R.t() - cv::Matx33d::eye(), cv::NORM_INF), 1e-15);
  EXPECT_NEAR(cv::determinant(R), 1.0, 1e-15);
  EXPECT_LT(cv::norm(R * cv::Vec3d(0, 1, 0) - cv::Vec3d(0, 0, 1)), 1e-15);
  EXPECT_LT(cv::norm(R * cv::Vec3d(0, 0, 1) - cv::Vec3d(-1, 0, 0)), 1e-15);
  EXPECT_LT(cv::norm(R * cv::Vec3d(1, 0, 0) - cv::Vec3d(0, -1, 0)), 1e-15);
  EXPECT_EQ(cv::norm(rosMapFromTarget().t), 0.0);
}

TEST(MapFrame, TargetFromRosMapUndoesTheRotation) {
  const Pose target_from_camera{cameraOrientation(0.3, 0.2, -0.1), {0.4, -0.7, 2.1}};
  const Pose back = targetFromRosMap(rosMapFromTarget() * target_from_camera);
  EXPECT_LT(cv::norm(back.R - target_from_camera.R, cv::NORM_INF), 1e-12);
  EXPECT_LT(cv::norm(back.t - target_from_camera.t), 1e-12);
}

// Points of a core plane n . x = d satisfy a x + b y + c z + d' = 0 in the ROS map.
TEST(MapFrame, RosPlaneHoldsThePlanesPoints) {
  const cv::Vec3d n = cv::normalize(cv::Vec3d(0.2, 0.9, -0.3));
  const double d = 1.7;
  const RosPlane plane = toRosPlane(n, d);
  EXPECT_NEAR(cv::norm(plane.normal), 1.0, 1e-12);
  cv::Vec3d u = n.cross(cv::Vec3d(1, 0, 0));
  u = cv::normalize(u);
  const cv::Vec3d v = n.cross(u);
  for (const double a : {-2.0, 0.0, 3.5}) {
    for (const double b : {-1.0, 0.5}) {
      const cv::Vec3d x = d * n + a * u + b * v;  // on the plane, in the target frame
      const cv::Vec3d x_ros = rosMapFromTarget().apply(x);
      EXPECT_NEAR(plane.normal.dot(x_ros) + plane.d, 0.0, 1e-12);
    }
  }
  // The floor 0.8 m under the target's centre (target frame: y = -0.8, normal up).
  const RosPlane floor = toRosPlane({0, 1, 0}, -0.8);
  EXPECT_LT(cv::norm(floor.normal - cv::Vec3d(0, 0, 1)), 1e-15);
  EXPECT_NEAR(floor.d, 0.8, 1e-15);  // z + 0.8 = 0
}

TEST(MapFrame, PlaneKindByTiltFromGravity) {
  EXPECT_EQ(planeKind({0, 0, 1}), PlaneKind::kFloor);
  EXPECT_EQ(planeKind({0, 0, 5}), PlaneKind::kFloor);  // not of unit length
  EXPECT_EQ(planeKind({0, 0, -1}), PlaneKind::kCeiling);
  EXPECT_EQ(planeKind({1, 0, 0}), PlaneKind::kWall);
  EXPECT_EQ(planeKind({0, -2, 0}), PlaneKind::kWall);
  // The default 15 deg either side of horizontal and vertical.
  EXPECT_EQ(planeKind(tiltedUp(14)), PlaneKind::kFloor);
  EXPECT_EQ(planeKind(tiltedUp(16)), PlaneKind::kOther);
  EXPECT_EQ(planeKind(-tiltedUp(14)), PlaneKind::kCeiling);
  EXPECT_EQ(planeKind(tiltedUp(90 - 14)), PlaneKind::kWall);
  EXPECT_EQ(planeKind(tiltedUp(90 + 14)), PlaneKind::kWall);
  EXPECT_EQ(planeKind(tiltedUp(90 - 16)), PlaneKind::kOther);
  EXPECT_EQ(planeKind(tiltedUp(45)), PlaneKind::kOther);  // a ramp
  EXPECT_EQ(planeKind(tiltedUp(20), 25.0), PlaneKind::kFloor);
  // No direction: nothing.
  EXPECT_EQ(planeKind({0, 0, 0}), PlaneKind::kOther);
  EXPECT_EQ(planeKind({std::nan(""), 0, 1}), PlaneKind::kOther);
}

TEST(MapFrame, PlaneKindNames) {
  EXPECT_STREQ(planeKindName(PlaneKind::kFloor), "floor");
  EXPECT_STREQ(planeKindName(PlaneKind::kWall), "wall");
  EXPECT_STREQ(planeKindName(PlaneKind::kCeiling), "ceiling");
  EXPECT_STREQ(planeKindName(PlaneKind::kOther), "other");
}
