// The start-up target joins the tracker once, as four flagged points, after it has been
// seen in confirm_frames consecutive images with consistently tracked corners.
#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "mono_plane_detection/sim/camera_trajectory.h"
#include "mono_plane_detection/sim/scene_renderer.h"
#include "mono_plane_detection/tracking/target_startup.h"

using namespace mono_plane_detection;

namespace {

// A wide lens (strong barrel distortion) and the wheeled start turned about the vertical
// so the target sits off the image centre, where the lens bends most.
CameraModel barrelLens() {
  CameraModel camera;
  camera.k1 = -0.30;
  camera.k2 = 0.08;
  return camera;
}

Pose turnedStart(double yaw_deg) {
  Pose pose = trajectoryPose(TrajectoryParams(), 0.0);
  const cv::Matx33d turn =  // about the world's vertical
      cameraOrientation(yaw_deg * CV_PI / 180, 0, 0) * cameraOrientation(0, 0, 0).t();
  pose.R = turn * pose.R;
  return pose;
}

}  // namespace

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
  const CameraModel camera = barrelLens();
  RenderOptions options;
  options.supersample = 2;
  const SceneRenderer renderer(scene, camera, options);
  TargetParams once;
  once.confirm_frames = 1;
  double worst_raw = 0, worst_lens = 0;
  int views = 0;
  for (double yaw_deg : {-24.0, -18.0, 0.0, 18.0, 24.0}) {
    const Pose world_from_camera = turnedStart(yaw_deg);
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
  EXPECT_GT(worst_raw, 0);  // found raw in some views: the comparison below has a side
  EXPECT_LT(worst_lens, 0.2);
  EXPECT_LT(worst_lens, worst_raw);
}

// The equidistant (fisheye) model of camera_info takes the same path through cv::fisheye.
// Its image: a wide pinhole rendering of the same focal length, resampled to the fisheye's
// pixels (each pixel's ray by cv::fisheye::undistortPoints). Straight sides bend there
// (r = f theta against f tan theta: 8 % shorter at 40 deg off the axis).
TEST(TargetStartup, EquidistantLensIsUndoneBeforeTheSidesAreFitted) {
  const IndoorScene scene = makeRoom(RoomParams());
  CameraModel wide;  // the pinhole rendering, wide enough for the fisheye's corners
  wide.size = cv::Size(1100, 900);
  wide.cx = 549.5;
  wide.cy = 449.5;
  RenderOptions options;
  options.supersample = 2;
  const SceneRenderer renderer(scene, wide, options);
  const cv::Size size(640, 480);
  const cv::Matx33d K(wide.fx, 0, 319.5, 0, wide.fy, 239.5, 0, 0, 1);
  const cv::Mat D = (cv::Mat_<double>(1, 4) << 0.02, -0.01, 0.003, -0.001);
  // Where each fisheye pixel looks, as a pixel of the wide pinhole image.
  std::vector<cv::Point2f> pixels, rays;
  for (int v = 0; v < size.height; ++v)
    for (int u = 0; u < size.width; ++u) pixels.emplace_back(u, v);
  cv::fisheye::undistortPoints(pixels, rays, K, D);
  cv::Mat map_x(size, CV_32F), map_y(size, CV_32F);
  for (int i = 0; i < static_cast<int>(rays.size()); ++i) {
    map_x.at<float>(i / size.width, i % size.width) = float(wide.fx * rays[i].x + wide.cx);
    map_y.at<float>(i / size.width, i % size.width) = float(wide.fy * rays[i].y + wide.cy);
  }
  TargetParams once;
  once.confirm_frames = 1;
  double worst = 0, worst_pinhole = 0;
  int found_pinhole = 0;
  for (double yaw_deg : {-24.0, -12.0, 0.0, 12.0, 24.0}) {
    const Pose world_from_camera = turnedStart(yaw_deg);
    cv::Mat view;
    cv::remap(renderer.render(world_from_camera), view, map_x, map_y, cv::INTER_LINEAR);
    std::vector<cv::Point3d> corners;
    for (const cv::Vec3d& c : scene.target.corners) {
      const cv::Vec3d x = world_from_camera.inverse().apply(c);
      corners.emplace_back(x[0], x[1], x[2]);
    }
    std::vector<cv::Point2d> truth;
    cv::fisheye::projectPoints(corners, truth, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
    FeatureTracker tracker;
    tracker.process(view);
    TargetStartup lens(once), pinhole(once);
    lens.setLens(K, D, true);
    pinhole.setLens(K, cv::Mat());  // the same K read as a pinhole: the sides stay bent
    const auto with_lens = lens.process(view, tracker);
    ASSERT_TRUE(with_lens) << "yaw " << yaw_deg << ": " << lens.lastDetection().reason;
    const auto as_pinhole = pinhole.process(view, tracker);
    double e = 0, e_pinhole = 0;
    for (int i = 0; i < 4; ++i) {
      e = std::max(e, cv::norm(cv::Point2d(with_lens->corners[i]) - truth[i]));
      if (as_pinhole)
        e_pinhole = std::max(e_pinhole, cv::norm(cv::Point2d(as_pinhole->corners[i]) - truth[i]));
    }
    std::printf("yaw %5.1f deg: worst corner error %.2f px with the fisheye lens, %s %.2f px\n",
                yaw_deg, e, as_pinhole ? "as a pinhole" : "as a pinhole: not found", e_pinhole);
    worst = std::max(worst, e);
    if (as_pinhole) {
      ++found_pinhole;
      worst_pinhole = std::max(worst_pinhole, e_pinhole);
    }
  }
  EXPECT_LT(worst, 0.3);
  // The lens model matters: read as a pinhole the bent sheet is refused or its corners
  // are off by more.
  EXPECT_TRUE(found_pinhole < 5 || worst_pinhole > worst) << worst_pinhole << " vs " << worst;
}

namespace {

// The target's true corners in a rendered view, in TargetDetection's order.
std::array<cv::Point2d, 4> trueCorners(const IndoorScene& scene, const CameraModel& camera,
                                       const Pose& world_from_camera) {
  std::array<cv::Point2d, 4> out;
  for (int i = 0; i < 4; ++i)
    out[i] = camera.project(world_from_camera.inverse().apply(scene.target.corners[i]));
  return out;
}

// The target tracks (ascending ids = corner order) of the tracker's current image.
std::vector<TrackedPoint> targetTracks(const FeatureTracker& tracker) {
  std::vector<TrackedPoint> out;
  for (const TrackedPoint& p : tracker.current())
    if (p.is_target_corner) out.push_back(p);
  std::sort(out.begin(), out.end(),
            [](const TrackedPoint& a, const TrackedPoint& b) { return a.id < b.id; });
  return out;
}

// Moves each target track by `drift` (a stand-in for Lucas-Kanade's drift).
void driftTargetTracks(FeatureTracker& tracker, const std::array<cv::Point2f, 4>& drift) {
  const std::vector<TrackedPoint> tracks = targetTracks(tracker);
  ASSERT_EQ(tracks.size(), 4u);
  std::vector<std::uint64_t> ids;
  std::vector<cv::Point2f> uv;
  for (int k = 0; k < 4; ++k) {
    ids.push_back(tracks[k].id);
    uv.push_back(tracks[k].uv + drift[k]);
  }
  ASSERT_EQ(tracker.movePoints(ids, uv), 4);
}

}  // namespace

// Issue 18: after confirmation the tracked corners drift (tenths of a pixel over tens of
// images, degrees of tilt for a small target). Tracks pushed 0.4-1.5 px off are moved back
// onto the re-detected corners in the next image, same ids, within 0.1 px of the truth.
TEST(TargetStartup, DriftedTargetTracksAreReanchoredToTheDetectedCorners) {
  const IndoorScene scene = makeRoom(RoomParams());
  const CameraModel camera;
  RenderOptions options;
  options.supersample = 2;
  const SceneRenderer renderer(scene, camera, options);
  TrajectoryParams path;
  TargetParams once;
  once.confirm_frames = 1;
  FeatureTracker tracker;
  TargetStartup startup(once);
  cv::Mat view = renderer.render(trajectoryPose(path, 0.0));
  tracker.process(view);
  ASSERT_TRUE(startup.process(view, tracker, camera.fx)) << startup.lastDetection().reason;
  const std::vector<TrackedPoint> first = targetTracks(tracker);
  ASSERT_EQ(first.size(), 4u);
  const std::array<cv::Point2f, 4> drift{
      {{0.8f, -0.6f}, {-0.4f, 0.3f}, {1.2f, 0.9f}, {-0.5f, -1.1f}}};
  double worst_drifted = 0, worst = 0, sum = 0;
  for (int image = 1; image <= 8; ++image) {
    driftTargetTracks(tracker, drift);  // on the image before: LK carries it on
    const Pose pose = trajectoryPose(path, 0.05 * image);
    view = renderer.render(pose);
    tracker.process(view);
    const auto truth = trueCorners(scene, camera, pose);
    std::vector<TrackedPoint> tracks = targetTracks(tracker);
    ASSERT_EQ(tracks.size(), 4u) << "image " << image;
    for (int k = 0; k < 4; ++k)
      worst_drifted = std::max(worst_drifted, cv::norm(cv::Point2d(tracks[k].uv) - truth[k]));
    EXPECT_FALSE(startup.process(view, tracker));  // confirmed once only
    EXPECT_TRUE(startup.reanchored()) << "image " << image;
    // The largest move: the 1.5 px pushed onto corner 2, give or take LK's error.
    EXPECT_NEAR(startup.lastReanchorShiftPx(), 1.5, 0.3) << "image " << image;
    tracks = targetTracks(tracker);
    // The corners a search of the whole image finds (the crop's noise estimate differs).
    const TargetDetection whole = detectTarget(view, TargetParams(), camera.fx);
    ASSERT_TRUE(whole.found);
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(tracks[k].id, first[k].id);  // ids kept
      const double e = cv::norm(cv::Point2d(tracks[k].uv) - truth[k]);
      worst = std::max(worst, e);
      sum += e;
      EXPECT_LT(e, 0.15) << "image " << image << " corner " << k;
      EXPECT_LT(cv::norm(tracks[k].uv - whole.corners[k]), 0.03) << "image " << image;
    }
  }
  std::printf("target tracks: drifted %.2f px, re-anchored %.3f px mean, %.3f worst\n",
              worst_drifted, sum / 32, worst);
  // The detector's own error on these renderings (supersampled twice): 0.05-0.1 px.
  EXPECT_LT(sum / 32, 0.1);
  EXPECT_GT(worst_drifted, 0.5);  // the drift was there
  EXPECT_EQ(startup.reanchoredImages(), 8);
  EXPECT_EQ(startup.followedImages(), 8);  // every image had all four target tracks
  startup.reset();
  EXPECT_EQ(startup.followedImages(), 0);
  EXPECT_EQ(startup.reanchoredImages(), 0);
}

// A detection that does not agree with the tracks (here: tracks pushed 3 px away, more
// than confirm_tolerance_px) or no detection at all leaves the tracks where they are;
// redetect_tracked false never moves them.
TEST(TargetStartup, NoReanchorWhenTheDetectionDisagreesOrFails) {
  const IndoorScene scene = makeRoom(RoomParams());
  const CameraModel camera;
  const SceneRenderer renderer(scene, camera, RenderOptions());
  TrajectoryParams path;
  for (const bool redetect : {true, false}) {
    TargetParams params;
    params.confirm_frames = 1;
    params.redetect_tracked = redetect;
    FeatureTracker tracker;
    TargetStartup startup(params);
    cv::Mat view = renderer.render(trajectoryPose(path, 0.0));
    tracker.process(view);
    ASSERT_TRUE(startup.process(view, tracker, camera.fx));
    // Far off: the detection (found) is more than 2 px from two of the tracks.
    driftTargetTracks(tracker, {{{3.0f, 0.0f}, {0, 0}, {0, 0}, {0.0f, -3.0f}}});
    std::vector<TrackedPoint> before = targetTracks(tracker);
    EXPECT_FALSE(startup.process(view, tracker));
    EXPECT_FALSE(startup.reanchored());
    std::vector<TrackedPoint> after = targetTracks(tracker);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(after[k].uv, before[k].uv) << "corner " << k;
    // Close (1 px): moved back, unless switched off.
    driftTargetTracks(tracker, {{{-2.0f, 0.0f}, {0, 0}, {0, 0}, {0.0f, 2.0f}}});
    before = targetTracks(tracker);
    startup.process(view, tracker);
    EXPECT_EQ(startup.reanchored(), redetect);
    if (redetect) {
      EXPECT_NEAR(startup.lastReanchorShiftPx(), 1.0, 0.1);  // net push left
    }
    after = targetTracks(tracker);
    EXPECT_EQ(after[0].uv != before[0].uv, redetect);
    // No target in the image searched (the region blank): nothing moves.
    const cv::Mat blank(view.size(), CV_8UC1, cv::Scalar(120));
    before = after;
    startup.process(blank, tracker);
    EXPECT_FALSE(startup.reanchored());
    after = targetTracks(tracker);
    for (int k = 0; k < 4; ++k) EXPECT_EQ(after[k].uv, before[k].uv) << "corner " << k;
    // Re-detection on: three images followed with all four corners tracked, one of them
    // re-anchored; off: the target is not followed at all.
    EXPECT_EQ(startup.followedImages(), redetect ? 3 : 0);
    EXPECT_EQ(startup.reanchoredImages(), redetect ? 1 : 0);
  }
}

// With a lens (setLens) the region is searched undistorted and the tracks are moved in
// raw pixels.
TEST(TargetStartup, ReanchoringWithLensDistortionGivesRawPixels) {
  const IndoorScene scene = makeRoom(RoomParams());
  const CameraModel camera = barrelLens();
  RenderOptions options;
  options.supersample = 2;
  const SceneRenderer renderer(scene, camera, options);
  const Pose pose = turnedStart(18);
  const cv::Mat view = renderer.render(pose);
  TargetParams once;
  once.confirm_frames = 1;
  FeatureTracker tracker;
  TargetStartup startup(once);
  startup.setLens(camera.K(), camera.distortion());
  tracker.process(view);
  ASSERT_TRUE(startup.process(view, tracker)) << startup.lastDetection().reason;
  driftTargetTracks(tracker, {{{0.8f, -0.6f}, {-0.4f, 0.3f}, {1.2f, 0.9f}, {-0.5f, -1.1f}}});
  startup.process(view, tracker);
  ASSERT_TRUE(startup.reanchored());
  const auto truth = trueCorners(scene, camera, pose);
  const std::vector<TrackedPoint> tracks = targetTracks(tracker);
  for (int k = 0; k < 4; ++k)
    EXPECT_LT(cv::norm(cv::Point2d(tracks[k].uv) - truth[k]), 0.2) << "corner " << k;
}
