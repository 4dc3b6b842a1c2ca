// The start-up target joins the tracker once, as four flagged points, after it has been
// seen in confirm_frames consecutive images with consistently tracked corners.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

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
