// Pose <-> geometry_msgs conversions (include/mono_plane_detection/ros/pose_msg.h).
#include <gtest/gtest.h>

#include <cmath>

#include "mono_plane_detection/sim/camera_trajectory.h"
#include "mono_plane_detection/ros/pose_msg.h"

using namespace mono_plane_detection;

TEST(PoseMsg, QuarterTurnAboutZ) {
  const cv::Matx33d Rz(0, -1, 0, 1, 0, 0, 0, 0, 1);
  const geometry_msgs::Quaternion q = toQuaternionMsg(Rz);
  EXPECT_NEAR(q.x, 0, 1e-12);
  EXPECT_NEAR(q.y, 0, 1e-12);
  EXPECT_NEAR(std::abs(q.z), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(std::abs(q.w), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q.z * q.w, 0.5, 1e-12);  // +90 deg, whichever sign
}

TEST(PoseMsg, RoundTripsThroughTransformAndPose) {
  for (int k = 0; k < 50; ++k) {
    const Pose p{cameraOrientation(0.13 * k - 3, 0.05 * k - 1, 0.07 * k - 1.5),
                 {0.1 * k, -0.2 * k, 3.0 - 0.05 * k}};
    const Pose a = fromTransformMsg(toTransformMsg(p));
    const Pose b = fromPoseMsg(toPoseMsg(p));
    EXPECT_LT(cv::norm(a.R - p.R, cv::NORM_INF), 1e-12) << k;
    EXPECT_LT(cv::norm(b.R - p.R, cv::NORM_INF), 1e-12) << k;
    EXPECT_LT(cv::norm(a.t - p.t), 1e-12);
    EXPECT_LT(cv::norm(b.t - p.t), 1e-12);
  }
}

// A quaternion that is not of unit length (tf from a user's hand-written launch file,
// rounded digits) is the same rotation.
TEST(PoseMsg, QuaternionNotOfUnitLengthIsTheSameRotation) {
  const cv::Matx33d R = cameraOrientation(0.4, -0.3, 1.1);
  geometry_msgs::Quaternion q = toQuaternionMsg(R);
  for (const double scale : {1.0, 0.98, 1.02, 3.0}) {
    geometry_msgs::Quaternion s = q;
    s.x *= scale, s.y *= scale, s.z *= scale, s.w *= scale;
    EXPECT_LT(cv::norm(fromQuaternionMsg(s) - R, cv::NORM_INF), 1e-12) << scale;
  }
  // -q is the same rotation as q.
  q.x = -q.x, q.y = -q.y, q.z = -q.z, q.w = -q.w;
  EXPECT_LT(cv::norm(fromQuaternionMsg(q) - R, cv::NORM_INF), 1e-12);
}
