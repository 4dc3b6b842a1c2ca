// The plane stage end to end on synthetic tracks with known planes and poses.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "mono_plane_detection/eval/map_evaluation.h"
#include "mono_plane_detection/geometry/plane_fit.h"
#include "mono_plane_detection/mapping/plane_pipeline.h"
#include "support/synthetic_tracks.h"

using namespace mono_plane_detection;

namespace {

std::vector<TruthPlane> requiredTruth(const SyntheticTracks& world, int frames) {
  std::vector<TruthPlane> truth = truthPlanes(world.scene);
  for (int k = 0; k < frames; k += 10) {
    const auto shares =
        imageShares(world.scene, world.camera, trajectoryPose(world.trajectory, k / 30.0), 16);
    for (size_t i = 0; i < truth.size(); ++i)
      truth[i].max_image_share = std::max(truth[i].max_image_share, shares[i]);
  }
  return truth;
}

}  // namespace

TEST(PlanePipeline, MapsTheRoomsPlanesInMetres) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  const int frames = 240;
  int tracking = 0;
  bool placed = false;
  for (int k = 0; k < frames; ++k) {
    const PipelineResult r = pipeline.process(world.frame(k / 30.0));
    // The map's vertical is decided with the first image placed in metres, not before.
    placed |= r.pose.has_value();
    EXPECT_EQ(pipeline.verticalDecided(), placed) << "frame " << k;
    tracking += r.state == PipelineState::kTracking;
    if (k > 10) {
      EXPECT_FALSE(r.planes.empty()) << "frame " << k;
    }
  }
  EXPECT_GE(tracking, frames - 40);  // all but the start (about 1 s of motion)
  std::vector<MapPlane> confirmed;
  for (const MapPlane& p : pipeline.map().planes())
    if (p.confirmed(pipeline.map().params())) confirmed.push_back(p);
  const auto truth = requiredTruth(world, frames);
  const MapEvaluation e = evaluateMap(confirmed, truth, 0.10, 5.0, 0.15);
  EXPECT_TRUE(e.missed.empty()) << e.missed.size() << " planes missed";
  EXPECT_TRUE(e.split.empty());
  for (const PlaneMatch& m : e.matches) EXPECT_GE(m.truth_id, 0) << "plane " << m.map_id;
  // Independent 0.2 px noise per image is harsher on triangulation than a tracker's
  // (rendered sequences: worst 1.3 deg, README); these bounds were measured at 3.9 deg
  // and 4.3 cm.
  EXPECT_LT(e.worst_normal_error_deg, 5.0);
  EXPECT_LT(e.worst_distance_error_m, 0.10);
  // The sheet upright on the wall, the camera upright: the map's +y is the room's vertical.
  ASSERT_TRUE(pipeline.map().vertical());
  EXPECT_LT(normalAngleDeg(*pipeline.map().vertical(), cv::Vec3d(0, 1, 0)), 1e-12);
}

// The map's vertical (map/up_sigma_deg) is the map's +y only when the camera of its first
// placed image stands upright along it: an odometry frame turned 90 deg (its y along the
// camera's view, as a visual odometry whose frame is the first camera's) gives none; a
// reset map decides again.
TEST(PlanePipeline, TheMapsVerticalIsTakenOnlyFromAnUprightCamera) {
  const SyntheticTracks world("wheeled");
  const Pose turned{cv::Matx33d(1, 0, 0, 0, 0, -1, 0, 1, 0), {0, 0, 0}};  // 90 deg about x
  for (bool upright : {true, false}) {
    PipelineParams params;
    params.pose.metric_source = "odometry";
    PlanePipeline pipeline(params);
    pipeline.setCamera(world.camera.K(), world.camera.distortion());
    auto odometry = [&](double t) {
      return upright ? world.truthMapFromCamera(t) : turned * world.truthMapFromCamera(t);
    };
    int placed = 0;
    for (int k = 0; k < 10; ++k)
      placed += pipeline.process(world.frame(k / 30.0), odometry(k / 30.0)).pose.has_value();
    ASSERT_GT(placed, 0) << upright;
    EXPECT_TRUE(pipeline.verticalDecided());
    EXPECT_EQ(pipeline.map().vertical().has_value(), upright);
    pipeline.reset();
    EXPECT_FALSE(pipeline.verticalDecided());
    EXPECT_FALSE(pipeline.map().vertical());
    pipeline.process(world.frame(1.0), odometry(1.0));
    EXPECT_EQ(pipeline.map().vertical().has_value(), upright) << "after a reset";
    // Another camera starts another map, which decides again.
    pipeline.setCamera(world.camera.K() * 1.01, world.camera.distortion());
    EXPECT_FALSE(pipeline.verticalDecided());
    EXPECT_FALSE(pipeline.map().vertical());
  }
}

TEST(PlanePipeline, ImageSpacePlanesWithoutIntrinsics) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  PipelineResult r;
  for (int k = 0; k < 20; ++k) r = pipeline.process(world.frame(k / 30.0));
  EXPECT_EQ(r.state, PipelineState::kNoCamera);
  EXPECT_FALSE(r.planes.empty());
  EXPECT_FALSE(r.pose);
  EXPECT_TRUE(pipeline.map().planes().empty());
  EXPECT_GT(r.reference_stamp, 0);
}

TEST(PlanePipeline, WaitsForTheTarget) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  PipelineResult r;
  for (int k = 0; k < 10; ++k) {
    TrackFrame f = world.frame(k / 30.0);
    f.target_corner.assign(f.ids.size(), false);
    r = pipeline.process(f);
  }
  EXPECT_EQ(r.state, PipelineState::kWaitingForTarget);
  EXPECT_EQ(r.status, "waiting for target");
  EXPECT_FALSE(r.planes.empty());  // still found in the image
}

// A target start that cannot finish says so (hostile try: "waiting for camera motion" for 550
// images while the camera travelled 3 m, diagnostics OK): the target seen on a still camera,
// then gone (its corners no longer tracked) while the camera moves.
TEST(PlanePipeline, AStartWhoseTargetLeftTheViewSaysSo) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  PipelineResult r;
  for (int k = 0; k < 150; ++k) {
    // Still for 1 s (the first image's view, again and again): no parallax.
    TrackFrame f = world.frame(k < 30 ? 0.0 : k / 30.0);
    f.stamp = 1000 + k / 30.0;
    if (k >= 30) f = withoutTarget(f);  // then the target's corners are gone
    r = pipeline.process(f);
    if (k == 29) {
      EXPECT_EQ(r.state, PipelineState::kInitialising);
      EXPECT_EQ(r.status.rfind("target seen, initialising: waiting for camera motion", 0), 0u)
          << r.status;
      EXPECT_EQ(r.start_target_unseen_s, 0.0);
    }
  }
  EXPECT_EQ(r.state, PipelineState::kInitialising);
  EXPECT_NE(r.status.find("the start-up target is out of view"), std::string::npos) << r.status;
  EXPECT_NEAR(r.start_target_unseen_s, 120 / 30.0, 0.05);
  EXPECT_NEAR(r.start_wait_s, 149 / 30.0, 0.05);
  // A reset forgets the wait.
  pipeline.reset();
  TrackFrame f = world.frame(0.0);
  r = pipeline.process(f);
  EXPECT_EQ(r.start_wait_s, 0.0);
}

// A reloaded tracker numbers its tracks from 1 again: its points are none of the map's,
// whose landmarks those ids name (hostile try: "lost" for the rest of the bag). Tracks that
// are all new with new, larger ids (everything lost and found again) are no restart.
TEST(PlanePipeline, ATrackerThatStartedOverStartsTheMapOver) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  PipelineResult r;
  for (int k = 0; k < 90; ++k) r = pipeline.process(world.frame(k / 30.0));
  ASSERT_TRUE(r.pose) << r.status;
  TrackFrame later = world.frame(90 / 30.0);  // all new, ids above the old: no restart
  for (auto& id : later.ids) id += 100000;
  r = pipeline.process(later);
  EXPECT_FALSE(r.was_reset);
  EXPECT_FALSE(r.tracker_restarted);
  TrackFrame restarted = world.frame(91 / 30.0);  // ids from 1 again
  const std::uint64_t lowest = *std::min_element(restarted.ids.begin(), restarted.ids.end());
  for (auto& id : restarted.ids) id = id - lowest + 1;
  r = pipeline.process(restarted);
  EXPECT_TRUE(r.was_reset);
  EXPECT_TRUE(r.tracker_restarted);
  EXPECT_FALSE(r.pose);
  TrackFrame next = world.frame(92 / 30.0);  // the restarted tracker's next image
  for (auto& id : next.ids) id = id - lowest + 1;
  r = pipeline.process(next);
  EXPECT_FALSE(r.was_reset);
}

namespace {

// 90 images of the wheeled room with ids from 1000 on (ids 1-999 are old and in no image)
// and the tracker's run `run`; the camera placed.
PipelineResult placedWithIdsFrom1000(PlanePipeline& pipeline, const SyntheticTracks& world,
                                     std::uint32_t run) {
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  PipelineResult r;
  for (int k = 0; k < 90; ++k) {
    TrackFrame f = world.frame(k / 30.0);
    for (auto& id : f.ids) id += 1000;
    f.tracker_run = run;
    r = pipeline.process(f);
  }
  return r;
}

// Image 90 with one point left, under this id.
TrackFrame onePointLeft(const SyntheticTracks& world, std::uint64_t id) {
  TrackFrame f = world.frame(90 / 30.0);
  f.ids = {id};
  f.pixels = {f.pixels.front()};
  f.target_corner = {false};
  return f;
}

}  // namespace

// A tracker with one point left that loses it and finds it again under its old id (a
// small max_features set live, hostile try): an old id, none of the last image's, but
// re-identified: no restart. The same id not flagged re-identified is one.
TEST(PlanePipeline, AReidentifiedOldIdIsNoRestart) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  PipelineResult r = placedWithIdsFrom1000(pipeline, world, 0);
  ASSERT_TRUE(r.pose) << r.status;
  const std::uint64_t old_id = 5;
  TrackFrame back = onePointLeft(world, old_id);
  back.reidentified = {true};
  ASSERT_EQ(validateTrackFrame(back), "");
  r = pipeline.process(back);
  EXPECT_FALSE(r.was_reset);
  EXPECT_FALSE(r.tracker_restarted);
  back.stamp += 1 / 30.0;
  back.ids = {old_id - 1};
  back.reidentified.clear();  // (none flagged)
  r = pipeline.process(back);
  EXPECT_TRUE(r.tracker_restarted);
}

// A tracker that says its run (Tracks.tracker_run): another run is a restart whatever the
// ids (here still above the old ones); the same run is none whatever they are (all
// lost, the one left an old id that is neither flagged nor in the last image).
TEST(PlanePipeline, TheTrackersRunTellsARestart) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  PipelineResult r = placedWithIdsFrom1000(pipeline, world, 7);
  ASSERT_TRUE(r.pose) << r.status;
  TrackFrame same = onePointLeft(world, 5);
  same.tracker_run = 7;
  r = pipeline.process(same);
  EXPECT_FALSE(r.tracker_restarted);
  TrackFrame other = world.frame(91 / 30.0);
  for (auto& id : other.ids) id += 100000;  // (ids above the old: the id rule says no)
  other.tracker_run = 8;
  r = pipeline.process(other);
  EXPECT_TRUE(r.tracker_restarted);
  EXPECT_TRUE(r.was_reset);
  TrackFrame next = world.frame(92 / 30.0);
  for (auto& id : next.ids) id += 100000;
  next.tracker_run = 8;
  r = pipeline.process(next);
  EXPECT_FALSE(r.tracker_restarted);
}

TEST(PlanePipeline, ImagePlaneIdsAreStable) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  int first_id = -1, same = 0;
  for (int k = 0; k < 30; ++k) {
    const PipelineResult r = pipeline.process(world.frame(k / 30.0));
    if (r.planes.empty()) continue;
    if (first_id < 0) first_id = r.planes[0].id;
    same += r.planes[0].id == first_id;
  }
  EXPECT_GE(same, 25);
}

TEST(PlanePipeline, TimeGoingBackwardsResetsAPauseIsATrackingLoss) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  for (int k = 0; k < 60; ++k) pipeline.process(world.frame(k / 30.0));
  EXPECT_FALSE(pipeline.map().planes().empty());
  PipelineResult r = pipeline.process(world.frame(3.0));  // 1 s later: > max_gap_s
  EXPECT_TRUE(r.tracking_loss);
  EXPECT_NEAR(r.pause_s, 3.0 - 59 / 30.0, 1e-9);  // the pause itself, for the WARN
  EXPECT_FALSE(r.was_reset);
  EXPECT_FALSE(pipeline.map().planes().empty());  // the map is kept
  r = pipeline.process(world.frame(0.0));         // a bag loop
  EXPECT_TRUE(r.was_reset);
  EXPECT_TRUE(pipeline.map().planes().empty());
}

// The images missing before each one, from the stamps' gaps (the plane nodelet's count of
// tracks missing): none in a regular stream, 2 when two images of it never came, none in
// a pause.
TEST(PlanePipeline, MissingImagesAreCountedFromTheStampsGaps) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  long missing = 0;
  for (int k = 0; k < 10; ++k) missing += pipeline.process(world.frame(k / 30.0)).missing_images;
  EXPECT_EQ(missing, 0);
  EXPECT_EQ(pipeline.process(world.frame(12 / 30.0)).missing_images, 2);
  EXPECT_EQ(pipeline.process(world.frame(13 / 30.0)).missing_images, 0);
  const PipelineResult pause = pipeline.process(world.frame(3.0));
  EXPECT_TRUE(pause.tracking_loss);
  EXPECT_EQ(pause.missing_images, 0);
}

// dynamic_reconfigure's path: the per-image parameters take effect on the next image,
// without a restart (the map and the image history are kept).
TEST(PlanePipeline, PerImageParamsApplyToTheNextImage) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;  // no intrinsics: the reference is frame_gap images back
  PipelineResult r;
  size_t most = 0;
  for (int k = 0; k < 30; ++k) {
    r = pipeline.process(world.frame(k / 30.0));
    most = std::max(most, r.planes.size());
  }
  ASSERT_GE(most, 2u);  // the room's planes, more than one at a time
  EXPECT_NEAR(r.reference_stamp, world.frame((29 - 5) / 30.0).stamp, 1e-9);
  PlaneParams one_plane;
  one_plane.max_planes = 1;
  pipeline.setPerImageParams(one_plane, 8, 5.0);
  EXPECT_EQ(pipeline.params().frame_gap, 8);
  for (int k = 30; k < 40; ++k) {
    r = pipeline.process(world.frame(k / 30.0));
    EXPECT_NEAR(r.reference_stamp, world.frame((k - 8) / 30.0).stamp, 1e-9) << k;
    EXPECT_LE(r.planes.size(), 1u) << k;
  }
  // A pause of 2 s is no tracking loss under max_gap_s 5 (it is under the default 1).
  r = pipeline.process(world.frame(40 / 30.0 + 2.0));
  EXPECT_FALSE(r.tracking_loss);
  pipeline.setPerImageParams(PlaneParams(), 5, 1.0);
  r = pipeline.process(world.frame(40 / 30.0 + 4.0));
  EXPECT_TRUE(r.tracking_loss);
}

// A 1 Hz stream (a low-rate bag): its one second between images is its rhythm from the
// first image (before the period is known a pause is over 3 x max_gap_s); a pause is then
// over 3 of its periods.
TEST(PlanePipeline, LowRateStreamIsNotAPauseOnceItsPeriodIsKnown) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  std::vector<bool> lost;
  double stamp = 100;
  for (int k = 0; k < 10; ++k, stamp += 1.05) {
    TrackFrame f = world.frame(k / 30.0);
    f.stamp = stamp;
    lost.push_back(pipeline.process(f).tracking_loss);
  }
  EXPECT_EQ(lost, std::vector<bool>(10, false));
  TrackFrame f = world.frame(10 / 30.0);
  f.stamp = stamp + 4.0;  // four periods later: a pause
  EXPECT_TRUE(pipeline.process(f).tracking_loss);
}

TEST(PlanePipeline, CameraIntrinsicsAreChecked) {
  EXPECT_EQ(cameraIntrinsicsError(CameraModel().K(), cv::Mat()), "");
  EXPECT_NE(cameraIntrinsicsError(cv::Matx33d::zeros(), cv::Mat()), "");
  cv::Matx33d K = CameraModel().K();
  K(0, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(cameraIntrinsicsError(K, cv::Mat()), "");
  const cv::Mat bad =
      (cv::Mat_<double>(1, 5) << 0, std::numeric_limits<double>::infinity(), 0, 0, 0);
  EXPECT_NE(cameraIntrinsicsError(CameraModel().K(), bad), "");
  PlanePipeline pipeline;
  EXPECT_FALSE(pipeline.hasCamera());
  pipeline.setCamera(CameraModel().K(), cv::Mat());
  EXPECT_TRUE(pipeline.hasCamera());
}

// Issue 15, case 3: the same K with 5 then 8 coefficients (a recalibration) made cv::norm
// assert on different sizes. A change of calibration restarts what depends on it.
TEST(PlanePipeline, RecalibrationWithAnotherNumberOfCoefficientsRestarts) {
  const cv::Matx33d K = CameraModel().K();
  PlanePipeline pipeline;
  EXPECT_EQ(pipeline.setCamera(K, cv::Mat::zeros(1, 5, CV_64F)), "");
  const PoseEstimator* first = pipeline.poseEstimator();
  ASSERT_NE(first, nullptr);
  EXPECT_EQ(pipeline.setCamera(K, cv::Mat::zeros(1, 5, CV_64F)), "");  // the same: kept
  EXPECT_EQ(pipeline.setCamera(K, cv::Mat::zeros(1, 8, CV_64F)), "");
  EXPECT_EQ(pipeline.setCamera(K, cv::Mat::zeros(14, 1, CV_32F)), "");
  EXPECT_EQ(pipeline.setCamera(K, cv::Mat()), "");
  EXPECT_TRUE(pipeline.hasCamera());
  // Lengths OpenCV does not take are refused and the camera is kept (issue 15, case 4).
  for (int n : {1, 3, 6, 100}) {
    const std::string error = pipeline.setCamera(K, cv::Mat::zeros(1, n, CV_64F));
    EXPECT_NE(error.find(std::to_string(n) + " distortion coefficients"), std::string::npos)
        << error;
    EXPECT_NE(cameraIntrinsicsError(K, cv::Mat::zeros(1, n, CV_64F)), "");
  }
  EXPECT_TRUE(pipeline.hasCamera());
}

// Issue 18: the image to compare with is chosen by its rotation-free parallax. A robot
// that stops and turns on the spot: while older images within reach still have
// parallax they are used; once every image within reach is a rotation away, the status
// says so and nothing is segmented (every plane would move with one homography).
TEST(PlanePipeline, PureRotationIsReportedAndNotSegmented) {
  const SyntheticTracks world("wheeled");
  PlanePipeline pipeline;
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  PipelineResult r;
  for (int k = 0; k <= 60; ++k) r = pipeline.process(world.frame(k / 30.0));
  ASSERT_EQ(r.state, PipelineState::kTracking);
  EXPECT_FALSE(r.pure_rotation);
  EXPECT_GE(r.parallax_px, pipeline.params().keyframe_parallax_px);
  // Then it turns left on the spot, 0.5 deg per image.
  const Pose stop = trajectoryPose(world.trajectory, 2.0);
  int segmented_early = 0, rotation_late = 0;
  for (int k = 1; k <= 80; ++k) {
    const double yaw = 0.5 * k * CV_PI / 180;
    const cv::Matx33d turn(std::cos(yaw), -std::sin(yaw), 0, std::sin(yaw), std::cos(yaw), 0, 0, 0,
                           1);
    const Pose pose{turn * stop.R, stop.t};
    r = pipeline.process(world.frameAt(pose, 1002.0 + k / 30.0));
    if (k <= 10 && !r.planes.empty() && r.parallax_px >= pipeline.params().min_parallax_px)
      ++segmented_early;
    if (k > 60) {
      ASSERT_TRUE(r.pose) << k;
      rotation_late += r.pure_rotation;
      if (r.pure_rotation) {
        EXPECT_TRUE(r.planes.empty());
        EXPECT_NE(r.status.find("pure rotation"), std::string::npos) << r.status;
        EXPECT_NE(r.status.find("no planes segmented"), std::string::npos) << r.status;
        EXPECT_NE(r.status.find("under min_parallax_px 4.00"), std::string::npos) << r.status;
        EXPECT_LT(r.parallax_px, pipeline.params().min_parallax_px);
      }
    }
  }
  EXPECT_GE(segmented_early, 8);  // the images from before the stop still have parallax
  EXPECT_EQ(rotation_late, 20);
}

// Slow motion: a fixed gap of 5 images would hold 1.7 cm of motion; the keyframe is
// taken further back, where the parallax is.
TEST(PlanePipeline, SlowMotionComparesWithAnOlderKeyframe) {
  SyntheticTracks world("wheeled");
  world.trajectory.speed_mps = 0.1;
  PlanePipeline pipeline;
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  int measured = 0, far_back = 0;
  for (int k = 0; k < 200; ++k) {
    const TrackFrame f = world.frame(k / 30.0);
    const PipelineResult r = pipeline.process(f);
    if (r.parallax_px < 0 || r.pure_rotation) continue;
    ++measured;
    EXPECT_GE(r.parallax_px, pipeline.params().min_parallax_px);
    far_back += f.stamp - r.reference_stamp > 5.5 / 30.0;
  }
  EXPECT_GE(measured, 100);
  EXPECT_GE(far_back, measured * 9 / 10);
}

// camera_height on the humanoid (no floor in the image: an up-to-scale start, checked by
// its floor landmarks later): the planes seen while the start was being checked reach
// the map once the check passes, so the map holds planes first seen before any pose was
// given out.
TEST(PlanePipeline, PlanesSeenWhileAnUnscaledStartIsCheckedAreMapped) {
  const SyntheticTracks world("humanoid", 100);
  PipelineParams params;
  params.pose.metric_source = "camera_height";
  params.pose.floor.camera_height_m = 1.2;
  PlanePipeline pipeline(params);
  pipeline.setCamera(world.camera.K(), world.camera.distortion());
  double first_pose = -1;
  bool map_before_pose = false;
  for (int k = 0; k < 240; ++k) {
    const TrackFrame room = withoutTarget(world.frame(k / 30.0));
    const PipelineResult r = pipeline.process(room);
    if (!r.pose) map_before_pose |= !pipeline.map().planes().empty();
    if (r.pose && first_pose < 0) first_pose = room.stamp;
  }
  ASSERT_GT(first_pose, 0) << "no metric start";
  EXPECT_FALSE(map_before_pose) << "nothing is mapped before the check";
  EXPECT_FALSE(pipeline.map().vertical());  // its up is its own floor's first fit
  int earlier = 0;
  for (const MapPlane& p : pipeline.map().planes())
    earlier += p.confirmed(pipeline.map().params()) && p.first_seen < first_pose - 1.0;
  EXPECT_GE(earlier, 1) << "no plane from the images seen while checking";
}

// camera_height, an up-to-scale start whose floor is seen little (a humanoid's head): the
// check fits the map's up and scale to 30 or more floor landmarks, while each image plane
// of the floor holds a few of them. The map's floor plane holds the check's landmarks from
// the first metric image on, so it is as level as the map (measured: without them, the
// rendered humanoid's noise seed 7 mapped its floor from 10 points, 1.92 deg off, 6.1 %
// of its distance; with them 0.53 deg, 0.4 %). Here (15 % of the floor's points, seed 3)
// without them: no floor in the map at the first metric image, at the end an unconfirmed
// one 6.2 deg off; with them 35 points 0.3 deg off, at the end confirmed, 0.7 deg.
// The humanoid room with 15 % of its floor points: the floor's image planes are small.
SyntheticTracks thinFloorRoom(unsigned seed) {
  SyntheticTracks world("humanoid", 100, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<cv::Vec3d> points;
  std::vector<int> plane_of;
  for (size_t i = 0; i < world.points.size(); ++i)
    if (world.scene.planes[world.plane_of[i]].name != "floor" || unit(rng) < 0.15) {
      points.push_back(world.points[i]);
      plane_of.push_back(world.plane_of[i]);
    }
  world.points = points;
  world.plane_of = plane_of;
  return world;
}

PipelineParams cameraHeightParams() {
  PipelineParams params;
  params.pose.metric_source = "camera_height";
  params.pose.floor.camera_height_m = 1.2;
  return params;
}

// The thin-floor room seen by a camera_height pipeline.
class PlanePipelineThinFloor : public ::testing::Test {
 protected:
  void SetUp() override { pipeline.setCamera(world.camera.K(), world.camera.distortion()); }

  const unsigned seed = 3;
  SyntheticTracks world = thinFloorRoom(seed);
  const PipelineParams params = cameraHeightParams();
  PlanePipeline pipeline{params};
};

TEST_F(PlanePipelineThinFloor, TheFloorTheCheckFittedIsTheMapsFloor) {
  const cv::Vec3d up(0, 1, 0);  // the truth's (the target's frame: y up)
  // The truth's orientation of the map from the cameras' (summed over the placed images):
  // well fixed by each, while the short straight path after the turn fixes the rotation
  // about it only by the head's 2 cm of bob and sway.
  cv::Matx33d truth_from_map_sum = cv::Matx33d::zeros();
  int placed = 0;
  auto floorPlane = [&](const PlanePipeline& p) -> const MapPlane* {
    const MapPlane* best = nullptr;
    for (const MapPlane& plane : p.map().planes())
      if (plane.normal.dot(up) > 0.9 && (!best || plane.points.size() > best->points.size()))
        best = &plane;
    return best;
  };
  for (int k = 0; k < 300; ++k) {
    const TrackFrame room = withoutTarget(world.frame(k / 30.0, 0.5, seed));  // no target here
    const PipelineResult r = pipeline.process(room);
    if (!r.pose) continue;
    const cv::Matx33d truth_from_map =
        world.truthMapFromCamera(k / 30.0).R * r.pose->map_from_camera.R.t();
    truth_from_map_sum += truth_from_map;
    if (placed++ > 0) continue;
    const MapPlane* floor = floorPlane(pipeline);
    EXPECT_NE(floor, nullptr) << "no floor in the map at the first metric image " << k;
    if (!floor) continue;
    EXPECT_GE(floor->points.size(), static_cast<size_t>(params.pose.floor.min_check_points));
    size_t held = 0;
    for (std::uint64_t id : pipeline.poseEstimator()->checkedFloor().ids)
      held += floor->points.count(id);
    EXPECT_GE(held, static_cast<size_t>(params.pose.floor.min_check_points)) << "the check's floor";
    EXPECT_LT(normalAngleDeg(truth_from_map * floor->normal, up), 1.5);
  }
  ASSERT_GE(placed, 20) << "no metric start";
  cv::Mat w, u, vt;
  cv::SVD::compute(cv::Mat(truth_from_map_sum), w, u, vt);
  const cv::Matx33d truth_from_map(cv::Mat(u * vt));
  const MapPlane* floor = floorPlane(pipeline);
  ASSERT_NE(floor, nullptr) << "no floor in the map";
  EXPECT_TRUE(floor->confirmed(pipeline.map().params()));
  EXPECT_LT(normalAngleDeg(truth_from_map * floor->normal, up), 1.5);
}

// Two images with one stamp (a driver that stamps twice): images are told apart by their
// number (PoseEstimator::imageIndex), so the start is checked and placed as with distinct
// stamps and the floor the check fitted is one confirmed map plane.
TEST_F(PlanePipelineThinFloor, TwinStampsStillCheckAndMapTheFloor) {
  int placed = 0;
  for (int k = 0; k < 300; ++k) {
    TrackFrame room = withoutTarget(world.frame(k / 30.0, 0.5, seed));
    room.stamp = world.frame((k - k % 2) / 30.0).stamp;  // images 2j and 2j+1: one stamp
    if (pipeline.process(room).pose) ++placed;
  }
  ASSERT_GE(placed, 20) << "no metric start";
  const std::vector<std::uint64_t>& checked = pipeline.poseEstimator()->checkedFloor().ids;
  ASSERT_GE(checked.size(), static_cast<size_t>(params.pose.floor.min_check_points));
  int holding = 0;  // map planes holding most of the check's floor points
  for (const MapPlane& plane : pipeline.map().planes()) {
    size_t held = 0;
    for (std::uint64_t id : checked) held += plane.points.count(id);
    if (2 * held > checked.size()) {
      ++holding;
      EXPECT_TRUE(plane.confirmed(pipeline.map().params()));
    }
  }
  EXPECT_EQ(holding, 1);
}

// With known poses (odometry) an image plane gets a plane from its tracks' motion before
// its points have landmarks (motion_plane_images): the room's planes are confirmed
// earlier (measured: image 15 instead of 57, the front wall 1.70 deg / 0.002 m off under
// 0.2 px of independent noise per image), and every plane confirmed is a true one.
TEST(PlanePipeline, WithKnownPosesPlanesAreMappedBeforeTheirLandmarks) {
  const SyntheticTracks world("wheeled");
  auto firstConfirmed = [&](int motion_plane_images, MapEvaluation& at_end) {
    PipelineParams params;
    params.pose.metric_source = "odometry";
    params.motion_plane_images = motion_plane_images;
    PlanePipeline pipeline(params);
    pipeline.setCamera(world.camera.K(), world.camera.distortion());
    int first = -1;
    const int frames = 60;
    for (int k = 0; k < frames; ++k) {
      const double t = k / 30.0;
      pipeline.process(world.frame(t), world.truthMapFromCamera(t));
      std::vector<MapPlane> confirmed;
      for (const MapPlane& p : pipeline.map().planes())
        if (p.confirmed(pipeline.map().params())) confirmed.push_back(p);
      if (first < 0 && !confirmed.empty()) first = k;
      at_end = evaluateMap(confirmed, requiredTruth(world, frames), 0.10, 20.0, 0.3);
    }
    return first;
  };
  MapEvaluation without, with;
  const int first_without = firstConfirmed(0, without);
  const int first_with = firstConfirmed(5, with);
  std::printf("first confirmed plane: image %d without, %d with planes from motion\n",
              first_without, first_with);
  for (const PlaneMatch& m : with.matches)
    std::printf("  plane %d -> %s: %.2f deg, %.3f m\n", m.map_id, m.truth_name.c_str(),
                m.normal_error_deg, m.distance_error_m);
  ASSERT_GE(first_with, 0);
  ASSERT_GE(first_without, 0);  // both confirm a plane within the 60 images, with sooner
  EXPECT_LT(first_with, first_without);
  ASSERT_FALSE(with.matches.empty());
  for (const PlaneMatch& m : with.matches) EXPECT_GE(m.truth_id, 0) << "plane " << m.map_id;
  EXPECT_TRUE(with.split.empty());
  EXPECT_LT(with.worst_normal_error_deg, 2.0);
  EXPECT_LT(with.worst_distance_error_m, 0.05);
}

// Odometry poses are checked against the tracks (odometry_check.h): the truth agrees; an
// odom_frame that moves with the robot (its "odometry" turns the camera but never moves
// it: base_link through a head's joints, a hostile try) disagrees, and the monitor says so.
TEST(PlanePipeline, OdometryThatDoesNotMoveTheCameraAsItsImagesShowIsFound) {
  const SyntheticTracks world("wheeled");
  // first_alarm: the first image at which the monitor disagreed, -1 none.
  auto run = [&](bool travel, int& decided, int& disagreeing, int& first_alarm) {
    PipelineParams params;
    params.pose.metric_source = "odometry";
    PlanePipeline pipeline(params);
    pipeline.setCamera(world.camera.K(), world.camera.distortion());
    decided = disagreeing = 0;
    first_alarm = -1;
    for (int k = 0; k < 240; ++k) {
      const double t = k / 30.0;
      Pose odometry = world.truthMapFromCamera(t);
      if (!travel) odometry.t = world.truthMapFromCamera(0).t;  // turns, never moves
      const PipelineResult r = pipeline.process(world.frame(t), odometry);
      decided += r.odometry_check.decided;
      disagreeing += r.odometry_check.decided && !r.odometry_check.agrees;
      if (first_alarm < 0 && pipeline.odometryMonitor().disagrees()) first_alarm = k;
    }
    return pipeline.odometryMonitor().summary();
  };
  int decided = 0, disagreeing = 0, first_alarm = -1;
  EXPECT_EQ(run(true, decided, disagreeing, first_alarm), "");
  std::printf("true odometry: %d of %d checks disagree\n", disagreeing, decided);
  // One image in 5 is checked, where planes other than the largest hold 8 tracks; a
  // single check may fail (measured 1 of 26: a wrong essential matrix from 36 tracks),
  // the monitor never (7 of 10).
  EXPECT_GE(decided, 15);
  EXPECT_LE(disagreeing, decided / 5);
  EXPECT_EQ(first_alarm, -1);
  const std::string said = run(false, decided, disagreeing, first_alarm);
  std::printf("odometry without travel: %d of %d checks disagree, alarm at image %d: %s\n",
              disagreeing, decided, first_alarm, said.c_str());
  EXPECT_GE(decided, 15);
  EXPECT_GE(disagreeing, decided * 9 / 10);
  EXPECT_GE(first_alarm, 0);
  EXPECT_EQ(said.rfind("its translation ", 0), 0u) << said;
}
