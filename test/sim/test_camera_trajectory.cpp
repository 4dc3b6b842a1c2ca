#include <gtest/gtest.h>

#include "mono_plane_detection/sim/camera_trajectory.h"

using namespace mono_plane_detection;

namespace {
double degrees(double rad) { return rad * 180 / CV_PI; }
}  // namespace

TEST(CameraTrajectory, OrientationIsARotationLookingWhereAsked) {
  const cv::Matx33d R = cameraOrientation(0.3, 0.2, 0.05);
  EXPECT_LT(cv::norm(R.t() * R - cv::Matx33d::eye()), 1e-12);
  EXPECT_NEAR(cv::determinant(R), 1.0, 1e-12);
  const cv::Vec3d forward(R(0, 2), R(1, 2), R(2, 2));
  EXPECT_NEAR(degrees(std::asin(-forward[2])), degrees(0.2), 1e-9);  // pitch down
  EXPECT_NEAR(std::atan2(-forward[0], forward[1]), 0.3, 1e-12);      // heading
  const cv::Matx33d level = cameraOrientation(0, 0, 0);
  EXPECT_LT(cv::norm(level * cv::Vec3d(0, 0, 1) - cv::Vec3d(0, 1, 0)), 1e-12);   // z -> +y
  EXPECT_LT(cv::norm(level * cv::Vec3d(0, 1, 0) - cv::Vec3d(0, 0, -1)), 1e-12);  // y (down) -> -z
}

TEST(CameraTrajectory, WheeledStartsAtTheOriginAndDrivesAtItsSpeed) {
  TrajectoryParams p;
  const Pose start = trajectoryPose(p, 0);
  EXPECT_LT(cv::norm(start.t - cv::Vec3d(0, 0, p.camera_height_m)), 1e-12);
  EXPECT_LT(cv::norm(start.R - cameraOrientation(0, p.pitch_down_deg * CV_PI / 180, 0)), 1e-12);
  // Path length over 1 s is speed * 1 s; height constant; heading turns left.
  double length = 0;
  for (int k = 0; k < 30; ++k) {
    const Pose a = trajectoryPose(p, k / 30.0), b = trajectoryPose(p, (k + 1) / 30.0);
    length += cv::norm(b.t - a.t);
    EXPECT_NEAR(b.t[2], p.camera_height_m, 1e-12);
  }
  EXPECT_NEAR(length, p.speed_mps, 1e-3);
  const Pose end = trajectoryPose(p, p.duration_s);
  const cv::Vec3d forward(end.R(0, 2), end.R(1, 2), 0);
  EXPECT_NEAR(degrees(std::atan2(-forward[0], forward[1])), p.turn_deg, 1e-6);
}

TEST(CameraTrajectory, HumanoidBobsAroundTheWheeledPath) {
  TrajectoryParams wheeled, walking;
  walking.name = "humanoid";
  double max_offset = 0, max_height = 0, min_height = 10, max_roll = 0;
  for (int k = 0; k < 300; ++k) {
    const double t = k / 30.0;
    const Pose w = trajectoryPose(wheeled, t), h = trajectoryPose(walking, t);
    max_offset = std::max(max_offset, std::hypot(h.t[0] - w.t[0], h.t[1] - w.t[1]));
    max_height = std::max(max_height, h.t[2]);
    min_height = std::min(min_height, h.t[2]);
    max_roll = std::max(max_roll, std::abs(std::asin(h.R(2, 0))));
  }
  EXPECT_NEAR(max_offset, 0.015, 0.002);              // sway
  EXPECT_NEAR(max_height - min_height, 0.04, 0.002);  // bob +-2 cm
  EXPECT_GT(degrees(max_roll), 1.5);
  EXPECT_LT(degrees(max_roll), 4.0);
}

TEST(CameraTrajectory, RotationStaysInPlace) {
  TrajectoryParams p;
  p.name = "rotation";
  double max_yaw = 0;
  for (int k = 0; k < 300; ++k) {
    const Pose pose = trajectoryPose(p, k / 30.0);
    EXPECT_LT(cv::norm(pose.t - cv::Vec3d(0, 0, p.camera_height_m)), 1e-12);
    max_yaw = std::max(max_yaw, std::abs(std::atan2(-pose.R(0, 2), pose.R(1, 2))));
  }
  EXPECT_NEAR(degrees(max_yaw), p.rotation_amplitude_deg, 0.5);
}

// Issue 18: paths that turn a lot while moving little, where every plane moves with
// nearly the same homography over a few images.
TEST(CameraTrajectory, TurnInPlaceAndLookAroundTurnALotAndMoveLittle) {
  for (const std::string name : {"turn_in_place", "look_around"}) {
    TrajectoryParams p;
    p.name = name;
    ASSERT_TRUE(knownTrajectory(name));
    double path = 0, turned = 0;
    Pose last = trajectoryPose(p, 0);
    for (int k = 1; k <= 300; ++k) {
      const Pose pose = trajectoryPose(p, k / 30.0);
      path += cv::norm(pose.t - last.t);
      const cv::Matx33d dR = last.R.t() * pose.R;
      turned += rotationAngleDeg(dR);
      // Orthonormal, optical axis never up (world z).
      EXPECT_LT(cv::norm(pose.R.t() * pose.R - cv::Matx33d::eye()), 1e-9);
      EXPECT_LE(pose.R(2, 2), 0.0) << name << " image " << k;
      last = pose;
    }
    if (name == "turn_in_place") {
      // 150 deg about a vertical axis 0.15 m behind the camera: an arc of 0.39 m.
      EXPECT_NEAR(path, 0.15 * 150 * CV_PI / 180, 0.01);
      EXPECT_NEAR(turned, 150 * std::cos(10 * CV_PI / 180), 150 * 0.05);
    } else {
      EXPECT_LT(path, 2.2);    // a third of the wheeled speed (1 m), plus the step bob
      EXPECT_GT(turned, 250);  // head swings of +- 35 deg every 4 s on top of the 150 deg
    }
    EXPECT_GT(turned / path, 120) << name;  // degrees per metre; the wheeled path: 50
    std::printf("%s: turned %.0f deg over %.2f m\n", name.c_str(), turned, path);
  }
  EXPECT_FALSE(knownTrajectory("flying"));
}

TEST(CameraModel, ProjectsWithAndWithoutDistortion) {
  CameraModel cam;
  const cv::Point2d centre = cam.project({0, 0, 2});
  EXPECT_NEAR(centre.x, 319.5, 1e-12);
  EXPECT_NEAR(centre.y, 239.5, 1e-12);
  const cv::Point2d p = cam.project({1, 0.5, 5});
  EXPECT_NEAR(p.x, 319.5 + 525 * 0.2, 1e-12);
  EXPECT_NEAR(p.y, 239.5 + 525 * 0.1, 1e-12);
  cam.k1 = -0.2;  // barrel: points move towards the centre
  const cv::Point2d d = cam.project({1, 0.5, 5});
  EXPECT_LT(d.x, p.x);
  EXPECT_NEAR(d.x, 319.5 + 525 * 0.2 * (1 - 0.2 * 0.05), 1e-9);
}
