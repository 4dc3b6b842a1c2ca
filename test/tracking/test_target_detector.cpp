// The start-up target in rendered views with exact ground truth.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "mono_plane_detection/sim/scene_renderer.h"
#include "mono_plane_detection/tracking/target_detector.h"

using namespace mono_plane_detection;

namespace {

struct View {
  IndoorScene scene;
  CameraModel camera;
  Pose world_from_camera;
  cv::Mat image;
};

View render(const std::string& target_on, const std::string& trajectory, double t, double noise = 0,
            int blur = 1) {
  RoomParams room;
  room.target_on = target_on;
  View v{makeRoom(room), CameraModel(), Pose(), cv::Mat()};
  TrajectoryParams tp;
  tp.name = trajectory;
  if (target_on == "floor") tp.pitch_down_deg = 35;
  RenderOptions options;
  options.noise_sigma = noise;
  options.supersample = 2;
  const SceneRenderer renderer(v.scene, v.camera, options);
  v.world_from_camera = trajectoryPose(tp, t);
  std::vector<Pose> path;
  for (int s = 0; s < blur; ++s) path.push_back(trajectoryPose(tp, std::max(0.0, t - 0.005 * s)));
  v.image = renderer.renderBlurred(path, 3);
  return v;
}

// Largest distance between detected corners and the true ones, in the map order.
double cornerError(const View& v, const TargetDetection& d) {
  double worst = 0;
  for (int i = 0; i < 4; ++i) {
    const cv::Point2d truth =
        v.camera.project(v.world_from_camera.inverse().apply(v.scene.target.corners[i]));
    worst = std::max(worst, cv::norm(cv::Point2d(d.corners[i]) - truth));
  }
  return worst;
}

// Position error (m) and angle error (deg) of the pose from the target.
std::pair<double, double> poseError(const View& v, const TargetPose& p) {
  const Pose truth = v.scene.target.world_from_map.inverse() * v.world_from_camera;
  const cv::Matx33d dR = truth.R.t() * p.map_from_camera.R;
  const double angle = std::acos(std::min(1.0, (cv::trace(dR) - 1) / 2)) * 180 / CV_PI;
  return {cv::norm(truth.t - p.map_from_camera.t), angle};
}

}  // namespace

TEST(TargetDetector, FindsTheTargetOnTheWallToSubPixel) {
  for (const std::string trajectory : {"wheeled", "humanoid"}) {
    const View v = render("wall", trajectory, 0.0);
    const TargetDetection d = detectTarget(v.image);
    ASSERT_TRUE(d.found) << trajectory << ": " << d.reason;
    EXPECT_LT(cornerError(v, d), 0.2) << trajectory;  // measured 0.10-0.11
    const auto pose = cameraPoseFromTarget(d, v.camera.K(), v.camera.distortion());
    ASSERT_TRUE(pose);
    const auto [metres, degrees] = poseError(v, *pose);
    std::printf("%s: corners %.3f px, position %.1f mm, angle %.3f deg, reprojection %.3f px\n",
                trajectory.c_str(), cornerError(v, d), 1000 * metres, degrees,
                pose->reprojection_error_px);
    (void)metres;
    // A 0.297 m target 2 m away spans ~78 px: 0.1 px at its corners fixes the range to
    // a few millimetres but its tilt only to a few degrees (a nearly frontal plane looks
    // the same tilted slightly), which moves the position sideways. Measured: range
    // 0.1-0.3 %, tilt 0.4-3.3 deg.
    const Pose truth = v.scene.target.world_from_map.inverse() * v.world_from_camera;
    EXPECT_LT(std::abs(cv::norm(pose->map_from_camera.t) - cv::norm(truth.t)) / cv::norm(truth.t),
              0.01);
    EXPECT_LT(degrees, 5.0) << trajectory;
    EXPECT_LT(metres, 0.2) << trajectory;
  }
}

TEST(TargetDetector, NoiseAndMotionBlur) {
  const View v = render("wall", "humanoid", 0.3, 3.0, 4);
  const TargetDetection d = detectTarget(v.image);
  ASSERT_TRUE(d.found) << d.reason;
  EXPECT_LT(cornerError(v, d), 0.6);
  const auto pose = cameraPoseFromTarget(d, v.camera.K(), v.camera.distortion());
  ASSERT_TRUE(pose);
  const Pose truth = v.scene.target.world_from_map.inverse() * v.world_from_camera;
  EXPECT_LT(std::abs(cv::norm(pose->map_from_camera.t) - cv::norm(truth.t)) / cv::norm(truth.t),
            0.02);
}

TEST(TargetDetector, OnTheFloorInTheSameOrder) {
  const View v = render("floor", "wheeled", 0.0);
  const TargetDetection d = detectTarget(v.image);
  ASSERT_TRUE(d.found) << d.reason;
  EXPECT_LT(cornerError(v, d), 0.3);
  // Corners 0 and 1 are the near edge: lower in the image.
  EXPECT_GT(d.corners[0].y, d.corners[3].y);
  EXPECT_LT(d.corners[0].x, d.corners[1].x);
}

TEST(TargetDetector, NothingWhenTheTargetIsOutOfView) {
  int checked = 0;
  for (double t = 5.0; t <= 10.0; t += 0.5) {
    const View v = render("wall", "wheeled", t, 2.0);
    bool visible = false;
    for (const auto& c : v.scene.target.corners) {
      const cv::Vec3d x = v.world_from_camera.inverse().apply(c);
      const cv::Point2d p = v.camera.project(x);
      visible = visible || (x[2] > 0 && p.x >= 0 && p.y >= 0 && p.x < 640 && p.y < 480);
    }
    if (visible) continue;
    const TargetDetection d = detectTarget(v.image);
    EXPECT_FALSE(d.found) << "false target at t = " << t;
    EXPECT_FALSE(d.reason.empty());
    ++checked;
  }
  EXPECT_GE(checked, 8);
}

TEST(TargetDetector, DegenerateImages) {
  EXPECT_FALSE(detectTarget(cv::Mat()).found);
  EXPECT_FALSE(detectTarget(cv::Mat(1, 1, CV_8UC1, cv::Scalar(9))).found);
  EXPECT_FALSE(detectTarget(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0))).found);
  EXPECT_FALSE(detectTarget(cv::Mat(480, 640, CV_8UC1, cv::Scalar(255))).found);
  EXPECT_FALSE(detectTarget(cv::Mat(480, 640, CV_8UC3, cv::Scalar(0))).found);
  // Shapes that cannot be the target: a triangle, a thin bar, a disc; and the target
  // cut by the image edge. (A square can: an A4 sheet seen obliquely looks square.)
  cv::Mat shapes(480, 640, CV_8UC1, cv::Scalar(0));
  std::vector<cv::Point> triangle{{50, 300}, {150, 300}, {100, 200}};
  cv::fillConvexPoly(shapes, triangle, 255);
  shapes(cv::Rect(250, 100, 300, 30)).setTo(255);
  cv::circle(shapes, {400, 350}, 60, 255, cv::FILLED);
  EXPECT_FALSE(detectTarget(shapes).found);
  cv::Mat cut(480, 640, CV_8UC1, cv::Scalar(0));
  cut(cv::Rect(300, 400, 212, 80)).setTo(255);
  EXPECT_FALSE(detectTarget(cut).found);
  // The right shape is.
  cv::Mat a4(480, 640, CV_8UC1, cv::Scalar(0));
  a4(cv::Rect(200, 150, 212, 150)).setTo(255);
  EXPECT_TRUE(detectTarget(a4).found);
}

TEST(TargetDetector, PoseNeedsUsableIntrinsics) {
  const View v = render("wall", "wheeled", 0.0);
  const TargetDetection d = detectTarget(v.image);
  ASSERT_TRUE(d.found);
  EXPECT_FALSE(cameraPoseFromTarget(d, cv::Matx33d::zeros(), cv::Mat()));
  cv::Matx33d nan_k = v.camera.K();
  nan_k(0, 2) = std::nan("");
  EXPECT_FALSE(cameraPoseFromTarget(d, nan_k, cv::Mat()));
  EXPECT_FALSE(cameraPoseFromTarget(TargetDetection(), v.camera.K(), cv::Mat()));
  const auto map = targetCornersInMap(TargetParams());
  EXPECT_DOUBLE_EQ(map[2].x - map[0].x, 0.297);
  EXPECT_DOUBLE_EQ(map[2].y - map[0].y, 0.210);
}
