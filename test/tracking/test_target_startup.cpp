// The start-up target joins the tracker once, as four flagged points, after it has been
// seen in confirm_frames consecutive images with consistently tracked corners.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "mono_plane_detection/sim/camera_trajectory.h"
#include "mono_plane_detection/sim/scene_renderer.h"
#include "mono_plane_detection/tracking/target_startup.h"

using namespace mono_plane_detection;

TEST(TargetStartup, AddsTheFourCornersOnceConfirmed) {
  const IndoorScene scene = makeRoom(RoomParams());
  const CameraModel camera;
  const SceneRenderer renderer(scene, camera, RenderOptions());
  TrajectoryParams path;
  FeatureTracker tracker;
  TargetStartup startup;  // confirm_frames 3
  ASSERT_EQ(startup.params().confirm_frames, 3);
  std::optional<TargetDetection> found;
  int image = 0;
  for (; image < 3 && !found; ++image) {
    const cv::Mat view = renderer.render(trajectoryPose(path, 0.1 * image));
    tracker.process(view);
    found = startup.process(view, tracker, camera.K()(0, 0));
    EXPECT_EQ(startup.consecutive(), image + 1);
  }
  ASSERT_TRUE(found) << startup.lastDetection().reason;
  EXPECT_EQ(image, 3);  // not before the third image
  EXPECT_TRUE(startup.found());
  int corners = 0;
  std::vector<std::uint64_t> ids;
  for (const TrackedPoint& p : tracker.current())
    if (p.is_target_corner) {
      ++corners;
      ids.push_back(p.id);
    }
  EXPECT_EQ(corners, 4);
  EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));  // ascending ids = corner order
  const cv::Mat last = renderer.render(trajectoryPose(path, 0.2));
  EXPECT_FALSE(startup.process(last, tracker));  // not twice
  startup.reset();
  TargetParams once;
  once.confirm_frames = 1;
  TargetStartup immediate(once);
  EXPECT_TRUE(immediate.process(last, tracker));
}

// A bright quadrilateral that is somewhere else in every image (texture, a flicker) is
// never confirmed: its corners do not follow the image motion.
TEST(TargetStartup, AJumpingCandidateIsNeverConfirmed) {
  FeatureTracker tracker;
  TargetStartup startup;
  for (int i = 0; i < 8; ++i) {
    cv::Mat image(480, 640, CV_8UC1, cv::Scalar(30));
    const int x = (i % 2) ? 80 : 360;
    image(cv::Rect(x, 150, 212, 150)).setTo(230);
    tracker.process(image);
    EXPECT_FALSE(startup.process(image, tracker)) << "image " << i;
    EXPECT_EQ(startup.consecutive(), 1);
    EXPECT_TRUE(startup.lastDetection().found);  // found each time, never confirmed
  }
  EXPECT_FALSE(startup.found());
}

TEST(TargetStartup, NothingWithoutTheTarget) {
  const cv::Mat grey(480, 640, CV_8UC1, cv::Scalar(90));
  FeatureTracker tracker;
  TargetStartup startup;
  tracker.process(grey);
  EXPECT_FALSE(startup.process(grey, tracker));
  EXPECT_FALSE(startup.found());
  EXPECT_TRUE(tracker.current().empty());
  EXPECT_FALSE(startup.lastDetection().reason.empty());
}

// Issue 12: a lens with strong barrel distortion bends the sheet's sides. Searched in
// the raw image, the sides fitted as straight lines meet off the corners, or the bent
// sheet fails the checks; with the
// lens (setLens, camera_info's K and D) the search runs on the undistorted image and
// the corners come back in raw pixels. Rendered views, exact corners.
TEST(TargetStartup, LensDistortionIsUndoneBeforeTheSidesAreFitted) {
  const IndoorScene scene = makeRoom(RoomParams());
  CameraModel camera;
  camera.k1 = -0.30;
  camera.k2 = 0.08;
  RenderOptions options;
  options.supersample = 2;
  const SceneRenderer renderer(scene, camera, options);
  TargetParams once;
  once.confirm_frames = 1;
  double worst_raw = 0, worst_lens = 0;
  int views = 0;
  // The target off the image centre, where the lens bends most: the camera turned.
  for (double yaw_deg : {-24.0, -18.0, 0.0, 18.0, 24.0}) {
    TrajectoryParams path;
    Pose world_from_camera = trajectoryPose(path, 0.0);
    const cv::Matx33d turn =  // about the world's vertical
        cameraOrientation(yaw_deg * CV_PI / 180, 0, 0) * cameraOrientation(0, 0, 0).t();
    world_from_camera.R = turn * world_from_camera.R;
    const cv::Mat view = renderer.render(world_from_camera);
    FeatureTracker tracker;
    tracker.process(view);
    TargetStartup raw(once), lens(once);
    lens.setLens(camera.K(), camera.distortion());
    const auto in_raw = raw.process(view, tracker, camera.fx);
    const auto with_lens = lens.process(view, tracker);
    ASSERT_TRUE(with_lens) << "yaw " << yaw_deg << ": " << lens.lastDetection().reason;
    double e_raw = 0, e_lens = 0;
    for (int i = 0; i < 4; ++i) {
      const cv::Point2d truth =
          camera.project(world_from_camera.inverse().apply(scene.target.corners[i]));
      e_lens = std::max(e_lens, cv::norm(cv::Point2d(with_lens->corners[i]) - truth));
      if (in_raw) e_raw = std::max(e_raw, cv::norm(cv::Point2d(in_raw->corners[i]) - truth));
    }
    std::printf("yaw %5.1f deg: worst corner error %.2f px raw (%s), %.2f px with the lens\n",
                yaw_deg, e_raw, in_raw ? "found" : "not found", e_lens);
    if (in_raw) worst_raw = std::max(worst_raw, e_raw);
    worst_lens = std::max(worst_lens, e_lens);
    ++views;
  }
  // Measured (k1 -0.30, k2 0.08, fx 525): raw 0.19-0.31 px where found, not found at
  // +-24 deg (bent sides fail the checks); with the lens 0.09-0.14 px, found in all.
  EXPECT_EQ(views, 5);
  EXPECT_LT(worst_lens, 0.2);
  EXPECT_LT(worst_lens, worst_raw);
}
