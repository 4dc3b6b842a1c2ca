// The camera's pose in metres from the target, the two-view start and the landmarks,
// against the true trajectory.
#include <gtest/gtest.h>

#include "mono_plane_detection/mapping/pose_estimator.h"
#include "support/synthetic_tracks.h"

using namespace mono_plane_detection;

namespace {

struct Outcome {
  int posed = 0;
  double worst_error = 0;  // m, camera position
  bool initialised_at_end = false;
  PoseSource last_source = PoseSource::kTarget;
};

Outcome run(const SyntheticTracks& world, int frames, bool odometry = false) {
  PoseEstimator estimator(world.camera.K(), world.camera.distortion());
  Outcome r;
  for (int k = 0; k < frames; ++k) {
    const double t = k / 30.0;
    std::optional<Pose> odom;
    if (odometry) {  // odometry with its own origin: 1 m aside and turned
      const Pose odom_from_map{cameraOrientation(0.3, 0, 0), {1, 0, 0}};
      odom = odom_from_map * world.truthMapFromCamera(t);
    }
    const auto e = estimator.update(world.frame(t), odom);
    if (!e) continue;
    ++r.posed;
    r.last_source = e->source;
    r.worst_error =
        std::max(r.worst_error, cv::norm(e->map_from_camera.t - world.truthMapFromCamera(t).t));
  }
  r.initialised_at_end = estimator.initialised();
  return r;
}

}  // namespace

TEST(PoseEstimator, FollowsTheWheeledRobotInMetres) {
  const SyntheticTracks world("wheeled");
  const Outcome r = run(world, 240);  // 8 s: the target leaves the view after about 3 s
  EXPECT_GE(r.posed, 200);            // from the start (about 1 s of motion) on, every image
  EXPECT_TRUE(r.initialised_at_end);
  EXPECT_EQ(r.last_source, PoseSource::kLandmarks);
  EXPECT_LT(r.worst_error, 0.10);  // over about 2.4 m travelled
}

TEST(PoseEstimator, FollowsTheHumanoid) {
  const SyntheticTracks world("humanoid");
  const Outcome r = run(world, 240);
  EXPECT_GE(r.posed, 200);
  EXPECT_LT(r.worst_error, 0.12);
}

TEST(PoseEstimator, NothingBeforeTheTarget) {
  const SyntheticTracks world("wheeled");
  PoseEstimator estimator(world.camera.K(), world.camera.distortion());
  TrackFrame f = world.frame(0);
  for (size_t i = 0; i < f.ids.size(); ++i) f.target_corner[i] = false;
  EXPECT_FALSE(estimator.update(f));
  EXPECT_FALSE(estimator.scaleKnown());
  EXPECT_FALSE(estimator.update(world.frame(0.033)));  // the target appears ...
  EXPECT_TRUE(estimator.scaleKnown());
  EXPECT_FALSE(estimator.initialised());                   // ... but there is no parallax yet
  EXPECT_TRUE(estimator.landmarkPosition(1).has_value());  // corner 1 is fixed
  EXPECT_FALSE(estimator.landmarkPosition(100).has_value());
  estimator.reset();
  EXPECT_FALSE(estimator.scaleKnown());
}

TEST(PoseEstimator, TriangulatedLandmarksAreWhereThePointsAre) {
  const SyntheticTracks world("wheeled");
  PoseEstimator estimator(world.camera.K(), world.camera.distortion());
  for (int k = 0; k < 90; ++k) estimator.update(world.frame(k / 30.0));
  int checked = 0;
  double worst = 0;
  for (size_t i = 0; i < world.points.size(); ++i) {
    const auto x = estimator.landmarkPosition(100 + i);
    if (!x) continue;
    ++checked;
    worst = std::max(worst, cv::norm(*x - world.map_from_world.apply(world.points[i])));
  }
  EXPECT_GT(checked, 60);
  EXPECT_LT(worst, 0.25);  // m; points up to 8 m away
}

TEST(PoseEstimator, OdometryReplacesTheVisualPoseOnceTheTargetFixesTheOffset) {
  const SyntheticTracks world("wheeled");
  const Outcome r = run(world, 150, true);
  EXPECT_GE(r.posed, 110);
  EXPECT_EQ(r.last_source, PoseSource::kOdometry);
  EXPECT_LT(r.worst_error, 0.10);  // all from the start's offset
}

TEST(PoseEstimator, ForgetsLandmarksBeyondTheBound) {
  const SyntheticTracks world("wheeled");
  PoseParams params;
  params.max_landmarks = 60;
  PoseEstimator estimator(world.camera.K(), world.camera.distortion(), params);
  for (int k = 0; k < 120; ++k) {
    estimator.update(world.frame(k / 30.0));
    EXPECT_LE(estimator.landmarks().size(), 60u);
  }
}

TEST(PoseEstimator, SourceNames) {
  EXPECT_STREQ(toString(PoseSource::kTarget), "target");
  EXPECT_STREQ(toString(PoseSource::kLandmarks), "landmarks");
  EXPECT_STREQ(toString(PoseSource::kOdometry), "odometry");
}
