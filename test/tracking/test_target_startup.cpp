// The start-up target joins the tracker once, as four flagged points.
#include <gtest/gtest.h>

#include "mono_plane_detection/sim/scene_renderer.h"
#include "mono_plane_detection/tracking/target_startup.h"

using namespace mono_plane_detection;

TEST(TargetStartup, AddsTheFourCornersOnce) {
  const IndoorScene scene = makeRoom(RoomParams());
  const CameraModel camera;
  const SceneRenderer renderer(scene, camera, RenderOptions());
  const cv::Mat start = renderer.render(trajectoryPose(TrajectoryParams(), 0));
  FeatureTracker tracker;
  TargetStartup startup;
  tracker.process(start);
  const auto found = startup.process(start, tracker);
  ASSERT_TRUE(found);
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
  EXPECT_FALSE(startup.process(start, tracker));        // not twice
  startup.reset();
  EXPECT_TRUE(startup.process(start, tracker));
}

TEST(TargetStartup, NothingWithoutTheTarget) {
  const cv::Mat grey(480, 640, CV_8UC1, cv::Scalar(90));
  FeatureTracker tracker;
  TargetStartup startup;
  tracker.process(grey);
  EXPECT_FALSE(startup.process(grey, tracker));
  EXPECT_FALSE(startup.found());
  EXPECT_TRUE(tracker.current().empty());
}
