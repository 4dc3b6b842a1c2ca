// The floor's homography between two views of the room, turned into metres by the
// camera's known height, against the true motion.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <unordered_map>

#include "mono_plane_detection/mapping/camera_height_scale.h"
#include "support/synthetic_tracks.h"

using namespace mono_plane_detection;

namespace {

struct TwoViews {
  std::vector<cv::Point2d> first, second;
  Pose second_from_first;  // truth
  cv::Vec3d down;          // truth, first camera frame
};

// Tracks of the room (the target's corners left out) at t0 and t1, normalised.
TwoViews twoViews(const SyntheticTracks& world, double t0, double t1) {
  const TrackFrame a = world.frame(t0), b = world.frame(t1);
  std::unordered_map<std::uint64_t, size_t> in_a;
  for (size_t i = 0; i < a.ids.size(); ++i) in_a.emplace(a.ids[i], i);
  std::vector<cv::Point2d> pa, pb;
  for (size_t i = 0; i < b.ids.size(); ++i) {
    const auto it = in_a.find(b.ids[i]);
    if (it == in_a.end() || b.target_corner[i]) continue;
    pa.push_back(a.pixels[it->second]);
    pb.push_back(b.pixels[i]);
  }
  TwoViews v;
  cv::undistortPoints(pa, v.first, world.camera.K(), world.camera.distortion());
  cv::undistortPoints(pb, v.second, world.camera.K(), world.camera.distortion());
  const Pose w1 = trajectoryPose(world.trajectory, t0), w2 = trajectoryPose(world.trajectory, t1);
  v.second_from_first = w2.inverse() * w1;
  v.down = w1.R.t() * cv::Vec3d(0, 0, -1);
  return v;
}

double angleDeg(const cv::Vec3d& a, const cv::Vec3d& b) {
  return std::acos(std::min(1.0, a.dot(b) / cv::norm(a) / cv::norm(b))) * 180 / CV_PI;
}

FloorParams floorParams(double height) {
  FloorParams p;
  p.camera_height_m = height;
  return p;
}

}  // namespace

// Measured on these views: floor normal 1.1 deg, length of the motion 1.4 % short.
TEST(CameraHeightScale, WheeledRobotsMotionInMetres) {
  const SyntheticTracks world("wheeled", 100);  // dense: the floor in view is small
  const TwoViews v = twoViews(world, 0.0, 1.5);
  const FloorStart s = floorStart(v.first, v.second, world.camera.K()(0, 0), floorParams(0.8));
  ASSERT_TRUE(s.ok) << s.reason;
  EXPECT_LT(angleDeg(s.down, v.down), 2.0);
  const double truth = cv::norm(v.second_from_first.t);
  EXPECT_NEAR(cv::norm(s.second_from_first.t), truth, 0.03 * truth);
  EXPECT_LT(angleDeg(s.second_from_first.t, v.second_from_first.t), 8.0);
  EXPECT_GE(s.floor_points.size(), 20u);
}

// camera_height is for wheeled robots (a camera at a fixed height); the humanoid's head,
// bobbing at 1.2 m, is covered by test_pose_estimator's CameraHeightGivesMetres only.

TEST(CameraHeightScale, SaysWhyNot) {
  const SyntheticTracks world("wheeled", 100);  // dense: the floor in view is small
  const TwoViews still = twoViews(world, 0.0, 0.02);
  const FloorStart s = floorStart(still.first, still.second, world.camera.K()(0, 0), floorParams(0.8));
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.reason.find("parallax"), std::string::npos) << s.reason;
  const TwoViews v = twoViews(world, 0.0, 1.0);
  const FloorStart unknown = floorStart(v.first, v.second, world.camera.K()(0, 0), floorParams(0));
  EXPECT_FALSE(unknown.ok);
  EXPECT_EQ(unknown.reason, "camera height unknown");
  // A camera looking up (nominal pitch -60 deg) has no floor near its down direction.
  FloorParams up = floorParams(0.8);
  up.pitch_down_deg = -60;
  up.max_floor_angle_deg = 20;
  EXPECT_FALSE(floorStart(v.first, v.second, world.camera.K()(0, 0), up).ok);
}

TEST(CameraHeightScale, FloorMapFrame) {
  // A camera pitched 10 deg down, 0.8 m above the floor.
  const double pitch = 10 * CV_PI / 180;
  const cv::Vec3d down(0, std::cos(pitch), std::sin(pitch));
  const Pose map_from_camera = floorMapFromCamera(down, 0.8);
  EXPECT_NEAR(map_from_camera.t[1], 0.8, 1e-12);  // y up: the camera 0.8 m above
  EXPECT_NEAR(map_from_camera.t[0], 0, 1e-12);
  EXPECT_NEAR(map_from_camera.t[2], 0, 1e-12);
  EXPECT_NEAR(cv::determinant(map_from_camera.R), 1, 1e-12);
  const cv::Vec3d ahead = map_from_camera.R * cv::Vec3d(0, 0, 1);  // optical axis in the map
  EXPECT_LT(ahead[2], -0.9);                                        // along -z: ROS x forward
  EXPECT_NEAR(ahead[1], -std::sin(pitch), 1e-12);                   // looking down
  EXPECT_NEAR(ahead[0], 0, 1e-12);
}
