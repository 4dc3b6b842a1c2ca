// What the nodelets do with one message, without ROS transport (issue 15): camera_info
// checks, image stamps beyond 2^31 s, images smaller than the tracker's windows, a
// stream mixing cameras, images missing from the stream, odometry that is not finite or
// jumps.
#include <cv_bridge/cv_bridge.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <opencv2/calib3d.hpp>
#include <sstream>

#include "../../src/nodelets/camera_info_check.h"
#include "../../src/nodelets/map_file.h"
#include "../../src/nodelets/nodelet_diagnostics.h"
#include "../../src/nodelets/plane_messages.h"
#include "../../src/nodelets/plane_status.h"
#include "../../src/nodelets/recent_events.h"
#include "../../src/nodelets/stretched_wait.h"
#include "../../src/nodelets/tracker_front_end.h"
#include "mono_plane_detection/sim/synthetic_views.h"
#include "mono_plane_detection/tracking/target_detector.h"

using namespace mono_plane_detection;

namespace {

sensor_msgs::CameraInfo cameraInfo(std::vector<double> D, const std::string& model = "plumb_bob") {
  sensor_msgs::CameraInfo info;
  info.width = 640;
  info.height = 480;
  info.K = {500, 0, 320, 0, 500, 240, 0, 0, 1};
  info.P = {500, 0, 320, 0, 0, 500, 240, 0, 0, 0, 1, 0};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.distortion_model = model;
  info.D = std::move(D);
  return info;
}

sensor_msgs::ImagePtr image(const cv::Mat& grey, uint32_t secs, uint32_t nsecs = 0,
                            const std::string& frame = "camera") {
  std_msgs::Header header;
  header.stamp = ros::Time(secs, nsecs);
  header.frame_id = frame;
  return cv_bridge::CvImage(header, "mono8", grey).toImageMsg();
}

cv::Mat textured(const cv::Size& size) {
  static const cv::Mat texture = makeCornerTexture({1000, 800}, 7);
  return texture(cv::Rect(cv::Point(100, 100), size)).clone();
}

}  // namespace

// Issue 15, case 2: D: [] made cv::Mat::reshape throw.
TEST(CameraInfoCheck, EmptyDistortionMeansNone) {
  cv::Matx33d K;
  cv::Mat D;
  EXPECT_EQ(fromCameraInfo(cameraInfo({}), K, D), "");
  EXPECT_TRUE(D.empty());
  EXPECT_EQ(K(0, 0), 500);
  EXPECT_EQ(fromCameraInfo(cameraInfo({}, ""), K, D), "");  // no model either
}

// Issue 15, case 4: lengths OpenCV does not take asserted later in undistortPoints.
TEST(CameraInfoCheck, DistortionLengthsOpenCvDoesNotTakeAreRefused) {
  cv::Matx33d K;
  cv::Mat D;
  for (size_t n : {1, 3, 6, 100}) {
    const std::string error = fromCameraInfo(cameraInfo(std::vector<double>(n, 0.01)), K, D);
    EXPECT_NE(error.find(std::to_string(n) + " distortion coefficients"), std::string::npos)
        << n << ": " << error;
  }
  for (size_t n : {4, 5, 8, 12, 14}) {
    EXPECT_EQ(fromCameraInfo(cameraInfo(std::vector<double>(n, 0.01), "rational_polynomial"), K, D),
              "")
        << n;
    EXPECT_EQ(D.total(), n);
    EXPECT_EQ(D.type(), CV_64F);
  }
  EXPECT_NE(fromCameraInfo(cameraInfo({0, 0, 0, 0}, "equidistant"), K, D), "");
  EXPECT_NE(fromCameraInfo(cameraInfo({0, 0, 0, 0, 0}, "kannala"), K, D), "");
  auto bad = cameraInfo({});
  bad.P[3] = INFINITY;
  EXPECT_NE(cameraInfoError(bad).find("P[3]"), std::string::npos);
  bad = cameraInfo({});
  bad.K[0] = 0;
  EXPECT_NE(cameraInfoError(bad), "");
  bad = cameraInfo({});
  bad.width = 0;
  EXPECT_NE(cameraInfoError(bad), "");
}

// image_geometry's semantics: a rectified stream's pixels are P's, without distortion;
// a raw stream's are K and D (issue 14: image_rect with D gave 0 planes).
TEST(CameraInfoCheck, RectifiedStreamsUsePWithoutDistortion) {
  sensor_msgs::CameraInfo info = cameraInfo({-0.3, 0.1, 0, 0, 0});
  info.P = {450, 0, 300, 0, 0, 460, 230, 0, 0, 0, 1, 0};
  CameraIntrinsics raw, rect;
  ASSERT_EQ(intrinsicsFromCameraInfo(info, false, raw), "");
  EXPECT_EQ(raw.K(0, 0), 500);
  EXPECT_EQ(raw.D.total(), 5u);
  ASSERT_EQ(intrinsicsFromCameraInfo(info, true, rect), "");
  EXPECT_EQ(rect.K(0, 0), 450);
  EXPECT_EQ(rect.K(1, 1), 460);
  EXPECT_EQ(rect.K(0, 2), 300);
  EXPECT_EQ(rect.K(1, 2), 230);
  EXPECT_TRUE(rect.D.empty());
  EXPECT_TRUE(rect.fisheye_D.empty());
  info.P.fill(0.0);  // a rectified stream without P is refused
  EXPECT_NE(intrinsicsFromCameraInfo(info, true, rect), "");
  EXPECT_TRUE(isRectifiedTopic("/camera/image_rect"));
  EXPECT_TRUE(isRectifiedTopic("/rear/image_rect_color"));
  EXPECT_FALSE(isRectifiedTopic("/camera/image_raw"));
  EXPECT_FALSE(isRectifiedTopic("/image_rect_cam/image_raw"));
  // Both nodelets' rule: the parameter, or the topic's name.
  EXPECT_EQ(rectifiedBy(false, "/camera/image_raw"), "");
  EXPECT_EQ(rectifiedBy(false, "/camera/image_rect"), "/camera/image_rect");
  EXPECT_EQ(rectifiedBy(true, "/camera/image_raw"), "parameter rectified");
}

// What each nodelet's diagnostics say it uses ("camera model"): none before a camera_info,
// then the model of the one held for the images' size.
TEST(CameraInfoCheck, TheCameraModelIsNamedForDiagnostics) {
  CalibrationHolder holder;
  EXPECT_EQ(cameraModelName(holder, {640, 480}), "none");
  sensor_msgs::CameraInfo info = cameraInfo({-0.3, 0.1, 0, 0, 0});
  info.P = {450, 0, 300, 0, 0, 460, 230, 0, 0, 0, 1, 0};
  const cv::Size size(static_cast<int>(info.width), static_cast<int>(info.height));
  CameraIntrinsics camera;
  ASSERT_EQ(intrinsicsFromCameraInfo(info, false, camera), "");
  holder.offer(camera);
  EXPECT_EQ(cameraModelName(holder, size), "raw (K, D)");
  EXPECT_EQ(cameraModelName(holder, {size.width / 2, size.height / 2}),
            "not used: camera_info for another image size");
  ASSERT_EQ(intrinsicsFromCameraInfo(info, true, camera), "");
  holder.offer(camera);
  EXPECT_EQ(cameraModelName(holder, size), "rectified (P)");
  ASSERT_EQ(intrinsicsFromCameraInfo(cameraInfo({0.05, -0.01, 0.002, -0.0005}, "equidistant"),
                                     false, camera),
            "");
  holder.offer(camera);
  EXPECT_EQ(cameraModelName(holder, size), "equidistant (K, D via cv::fisheye)");
}

// Equidistant: the tracks are moved to the pinhole image of the same K with cv::fisheye;
// points beyond it are dropped; other models are refused with one clear error.
TEST(CameraInfoCheck, EquidistantThroughCvFisheye) {
  const std::vector<double> k = {0.05, -0.01, 0.002, -0.0005};
  CameraIntrinsics camera;
  ASSERT_EQ(intrinsicsFromCameraInfo(cameraInfo(k, "equidistant"), false, camera), "");
  ASSERT_EQ(camera.fisheye_D.total(), 4u);
  EXPECT_TRUE(camera.D.empty());
  EXPECT_NE(intrinsicsFromCameraInfo(cameraInfo({0.1, 0.1, 0.1}, "equidistant"), false, camera)
                .find("4 coefficients"),
            std::string::npos);
  const std::string other =
      intrinsicsFromCameraInfo(cameraInfo({0, 0, 0, 0, 0}, "kannala"), false, camera);
  EXPECT_NE(other.find("'kannala' is not supported"), std::string::npos) << other;
  ASSERT_EQ(intrinsicsFromCameraInfo(cameraInfo(k, "equidistant"), false, camera), "");
  // Points in front of the camera, seen by the fisheye and by the pinhole of the same K.
  std::vector<cv::Point3d> points;
  for (double x = -0.5; x <= 0.5; x += 0.25)
    for (double y = -0.35; y <= 0.35; y += 0.175) points.emplace_back(x, y, 1.0);
  points.emplace_back(0.7, 0.0, 1.0);  // in the fisheye image, beyond the pinhole one
  std::vector<cv::Point2d> fisheye, pinhole;
  const cv::Mat D(k, true);
  cv::fisheye::projectPoints(points, fisheye, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera.K,
                             D.reshape(1, 1));
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera.K, cv::Mat(), pinhole);
  TrackFrame frame;
  frame.size = {640, 480};
  for (size_t i = 0; i < points.size(); ++i) {
    frame.ids.push_back(i + 1);
    frame.pixels.push_back(fisheye[i]);
    frame.target_corner.push_back(i == 0);
  }
  ASSERT_EQ(validateTrackFrame(frame), "");
  undistortFisheye(frame, camera);
  ASSERT_EQ(frame.ids.size(), points.size() - 1);  // the far point is gone
  for (size_t i = 0; i < frame.ids.size(); ++i)
    EXPECT_LT(cv::norm(frame.pixels[i] - pinhole[frame.ids[i] - 1]), 0.01) << i;
  EXPECT_TRUE(frame.target_corner[0]);
}

// A camera_info's width, height, K and P are the sensor's; binning and ROI say which part
// of it the images hold, at what scale (image_geometry): K, P and the image size follow.
TEST(CameraInfoCheck, BinningAndRegionOfInterestScaleAndShiftTheCamera) {
  sensor_msgs::CameraInfo info = cameraInfo({-0.3, 0.1, 0, 0, 0});
  info.width = 1280;
  info.height = 960;
  info.K = {1000, 0, 640, 0, 1000, 480, 0, 0, 1};
  info.P = {900, 0, 630, 0, 0, 900, 470, 0, 0, 0, 1, 0};
  CameraIntrinsics camera;
  ASSERT_EQ(intrinsicsFromCameraInfo(info, false, camera), "");
  EXPECT_EQ(camera.size, cv::Size(1280, 960));
  EXPECT_EQ(camera.K(0, 0), 1000);
  info.binning_x = info.binning_y = 2;  // images of 640x480
  ASSERT_EQ(intrinsicsFromCameraInfo(info, false, camera), "");
  EXPECT_EQ(camera.size, cv::Size(640, 480));
  EXPECT_EQ(camera.K(0, 0), 500);
  EXPECT_EQ(camera.K(1, 1), 500);
  EXPECT_EQ(camera.K(0, 2), 320);
  EXPECT_EQ(camera.D.total(), 5u);  // (distortion is of normalised coordinates: unchanged)
  ASSERT_EQ(intrinsicsFromCameraInfo(info, true, camera), "");  // rectified: P, halved
  EXPECT_EQ(camera.size, cv::Size(640, 480));
  EXPECT_EQ(camera.K(0, 0), 450);
  EXPECT_EQ(camera.K(0, 2), 315);
  info.roi.x_offset = 100;  // and a 640x480 window of the sensor from (100, 50)
  info.roi.y_offset = 50;
  info.roi.width = 640;
  info.roi.height = 480;
  ASSERT_EQ(intrinsicsFromCameraInfo(info, false, camera), "");
  EXPECT_EQ(camera.size, cv::Size(320, 240));
  EXPECT_EQ(camera.K(0, 2), 270);  // (640 - 100) / 2
  EXPECT_EQ(camera.K(1, 2), 215);  // (480 - 50) / 2
  info.D.clear();                  // no distortion: the same K (it was taken unbinned)
  ASSERT_EQ(intrinsicsFromCameraInfo(info, false, camera), "");
  EXPECT_EQ(camera.K(0, 2), 270);
  EXPECT_TRUE(camera.D.empty());
  info.distortion_model = "equidistant";  // the fisheye path too
  info.D = {0.05, -0.01, 0.002, -0.0005};
  ASSERT_EQ(intrinsicsFromCameraInfo(info, false, camera), "");
  EXPECT_EQ(camera.K(0, 0), 500);
  EXPECT_EQ(camera.K(1, 2), 215);
  // The tracker judges a binned camera's images by their own size: no "info size" warning.
  info = cameraInfo({});
  info.width = 1280;
  info.height = 960;
  info.K = {1000, 0, 640, 0, 1000, 480, 0, 0, 1};
  info.binning_x = info.binning_y = 2;
  TrackerFrontEnd front{TrackerNodeParams()};
  ASSERT_EQ(front.setCameraInfo(info), "");
  EXPECT_EQ(front.process(image(textured({640, 480}), 100)).info_mismatch, "");
  EXPECT_EQ(front.infoMismatch(), "");
  info.binning_x = info.binning_y = 1;  // the sensor's full size: not these images
  ASSERT_EQ(front.setCameraInfo(info), "");
  const TrackerOutput other = front.process(image(textured({640, 480}), 100, 33000000));
  // (The binned one before it still is: CalibrationHolder.)
  EXPECT_EQ(other.info_mismatch, infoSizeMismatch({1280, 960}, {640, 480}, true));
  EXPECT_EQ(front.infoMismatch(), other.info_mismatch);  // the state, for diagnostics
  EXPECT_EQ(front.counts().info_size_mismatch, 1);
  EXPECT_TRUE(front.hasCalibrationForImages());
  TrackerFrontEnd fresh{TrackerNodeParams()};  // only the sensor's: none for the images
  ASSERT_EQ(fresh.setCameraInfo(info), "");
  EXPECT_EQ(fresh.process(image(textured({640, 480}), 100)).info_mismatch,
            infoSizeMismatch({1280, 960}, {640, 480}));
  EXPECT_FALSE(fresh.hasCalibrationForImages());
  info.binning_x = info.binning_y = 2;  // right again: at once, before the next image
  ASSERT_EQ(front.setCameraInfo(info), "");
  EXPECT_EQ(front.infoMismatch(), "");
  // What both nodelets say: both sizes and what to do.
  const std::string text = infoSizeMismatch({1280, 960}, {640, 480});
  EXPECT_NE(text.find("camera_info is for 1280x960 images but the images are 640x480"),
            std::string::npos);
  EXPECT_NE(text.find("binning_x/y or ROI"), std::string::npos);
  EXPECT_NE(text.find("a calibration made at 640x480"), std::string::npos);
  EXPECT_NE(text.find("planes stay in image space"), std::string::npos);
  EXPECT_NE(infoSizeMismatch({1280, 960}, {640, 480}, true)
                .find("the last camera_info of their size still is"),
            std::string::npos);
  EXPECT_EQ(infoSizeMismatch({640, 480}, {640, 480}), "");
  // A 1279x959 camera through resize_scale 0.5: a 640x480 image, a 639x479 camera_info.
  EXPECT_NE(infoSizeMismatch({639, 479}, {640, 480}).find("image_proc/resize"),
            std::string::npos);
  EXPECT_EQ(text.find("image_proc/resize"), std::string::npos);
}

// A stray camera_info of another size (a second driver on the topic) does not take the
// calibration from the images: the last one of their size stays, the mismatch is named.
// The camera_info's frame against the images': tf names (a leading '/' is the same
// frame), an empty name on either side says nothing.
TEST(CameraInfoCheck, AnotherFramesCameraInfoIsNamed) {
  sensor_msgs::CameraInfo info = cameraInfo({});
  info.header.frame_id = "/left_camera_optical";
  CameraIntrinsics camera;
  ASSERT_EQ(intrinsicsFromCameraInfo(info, false, camera), "");
  EXPECT_EQ(camera.frame_id, "left_camera_optical");
  EXPECT_EQ(infoFrameMismatch(camera, "left_camera_optical"), "");
  EXPECT_EQ(infoFrameMismatch(camera, "/left_camera_optical"), "");
  EXPECT_EQ(infoFrameMismatch(camera, ""), "");
  const std::string other = infoFrameMismatch(camera, "right_camera_optical");
  EXPECT_NE(other.find("camera_info is of frame 'left_camera_optical', the images of "
                       "'right_camera_optical'"),
            std::string::npos)
      << other;
  camera.frame_id.clear();
  EXPECT_EQ(infoFrameMismatch(camera, "right_camera_optical"), "");
}

TEST(CalibrationHolder, TheLastCameraInfoOfTheImagesSizeIsUsed) {
  CameraIntrinsics vga, sensor, vga2;
  vga.size = {640, 480};
  vga.K = cv::Matx33d(500, 0, 320, 0, 500, 240, 0, 0, 1);
  sensor.size = {1280, 960};
  sensor.K = cv::Matx33d(1000, 0, 640, 0, 1000, 480, 0, 0, 1);
  vga2 = vga;
  vga2.K(0, 0) = vga2.K(1, 1) = 510;
  CalibrationHolder holder;
  std::string mismatch = "x";
  EXPECT_EQ(holder.forImages({640, 480}, mismatch), nullptr);  // none yet
  EXPECT_EQ(mismatch, "");
  EXPECT_EQ(holder.mismatch({640, 480}), "");
  holder.offer(sensor);  // only another size's: not used, named, nothing earlier kept
  EXPECT_EQ(holder.forImages({640, 480}, mismatch), nullptr);
  EXPECT_EQ(mismatch, infoSizeMismatch({1280, 960}, {640, 480}));
  holder.offer(vga);
  const CameraIntrinsics* used = holder.forImages({640, 480}, mismatch);
  ASSERT_NE(used, nullptr);
  EXPECT_EQ(used->K(0, 0), 500);
  EXPECT_EQ(mismatch, "");
  holder.offer(sensor);  // the stray one: the VGA calibration stays, the ERROR says so
  used = holder.forImages({640, 480}, mismatch);
  ASSERT_NE(used, nullptr);
  EXPECT_EQ(used->K(0, 0), 500);
  EXPECT_EQ(mismatch, infoSizeMismatch({1280, 960}, {640, 480}, true));
  EXPECT_EQ(holder.mismatch({640, 480}), mismatch);
  ASSERT_NE(holder.heldFor({640, 480}), nullptr);
  EXPECT_EQ(holder.heldFor({320, 240}), nullptr);
  // Images of the sensor's size now: its own camera_info describes them.
  used = holder.forImages({1280, 960}, mismatch);
  ASSERT_NE(used, nullptr);
  EXPECT_EQ(used->K(0, 0), 1000);
  EXPECT_EQ(mismatch, "");
  holder.offer(vga2);  // a new calibration of the images' size replaces the old one
  used = holder.forImages({640, 480}, mismatch);
  ASSERT_NE(used, nullptr);
  EXPECT_EQ(used->K(0, 0), 510);
  EXPECT_EQ(holder.mismatch({0, 0}), "");      // no images yet: nothing to compare
  ASSERT_NE(holder.heldFor({0, 0}), nullptr);  // and the last camera_info is the one held
  EXPECT_EQ(holder.heldFor({0, 0})->K(0, 0), 510);
  EXPECT_EQ(CalibrationHolder().heldFor({0, 0}), nullptr);
}

// The target's wait counts the stretches of the stream, not a pause or a jump between them.
TEST(StretchedWait, CountsTheStretchesNotTheJumps) {
  StretchedWait wait;
  EXPECT_EQ(wait.seconds(), 0.0);
  for (int k = 0; k <= 20; ++k) wait.seen(100 + 0.1 * k);  // 2 s
  EXPECT_NEAR(wait.seconds(), 2.0, 1e-9);
  wait.closeStretch();  // a jump of 1e8 s
  wait.closeStretch();  // (twice: no change)
  EXPECT_NEAR(wait.seconds(), 2.0, 1e-9);
  for (int k = 0; k <= 10; ++k) wait.seen(1e8 + 0.1 * k);  // 1 s more
  EXPECT_NEAR(wait.seconds(), 3.0, 1e-6);
  wait.reset();
  EXPECT_EQ(wait.seconds(), 0.0);
  wait.seen(5);
  EXPECT_EQ(wait.seconds(), 0.0);  // one message: no time yet
}

// What went wrong lately: one log per kind and period, and every kind still recent with
// its last text, newest first (diagnostics show each: one never hides another).
// A user at the robot sees every problem, each under its own key, the worst as the summary.
TEST(StatusProblems, EveryProblemHasItsKeyAndTheWorstIsTheSummary) {
  auto value = [](const diagnostic_updater::DiagnosticStatusWrapper& s, const std::string& key) {
    for (const auto& kv : s.values)
      if (kv.key == key) return kv.value;
    return std::string("(none)");
  };
  StatusProblems problems;
  problems.add(diagnostic_msgs::DiagnosticStatus::WARN, "odometry", "odometry stopped");
  problems.add(diagnostic_msgs::DiagnosticStatus::ERROR, "camera_info", "camera_info size");
  problems.add(diagnostic_msgs::DiagnosticStatus::ERROR, "tracks", "bad tracks");
  diagnostic_updater::DiagnosticStatusWrapper status;
  problems.report(status, "mapping");
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::ERROR);
  EXPECT_EQ(status.message, "camera_info size");  // the first of the worst
  EXPECT_EQ(value(status, "problems now"), "3");
  EXPECT_EQ(value(status, "problem: odometry"), "WARN: odometry stopped");
  EXPECT_EQ(value(status, "problem: tracks"), "ERROR: bad tracks");
  diagnostic_updater::DiagnosticStatusWrapper fine;
  StatusProblems().report(fine, "mapping");
  EXPECT_EQ(fine.level, diagnostic_msgs::DiagnosticStatus::OK);
  EXPECT_EQ(fine.message, "mapping");
  EXPECT_EQ(value(fine, "problems now"), "0");
  // Lists of warnings (recent events, the stream's health) with their keys' prefix.
  StatusProblems listed;
  listed.addWarnings({{"images missing", "12 of 300"}, {"time", "went back 3 times"}});
  listed.addWarnings({{"camera_info rejected", "K is zero"}}, "last 10 s, ");
  diagnostic_updater::DiagnosticStatusWrapper warned;
  listed.report(warned, "tracking");
  EXPECT_EQ(warned.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(value(warned, "problems now"), "3");
  EXPECT_EQ(value(warned, "problem: time"), "WARN: went back 3 times");
  EXPECT_EQ(value(warned, "problem: last 10 s, camera_info rejected"), "WARN: K is zero");
}

namespace {
std::string statusValue(const diagnostic_updater::DiagnosticStatusWrapper& s,
                        const std::string& key) {
  for (const auto& kv : s.values)
    if (kv.key == key) return kv.value;
  return "(none)";
}

diagnostic_updater::DiagnosticStatusWrapper planeStatus(const PlaneRunState& run,
                                                        const PlaneStatusView& view) {
  diagnostic_updater::DiagnosticStatusWrapper status;
  reportPlaneStatus(run, view, status);
  return status;
}

PlaneRunState planeRun(PipelineState state, const std::string& status) {
  PlaneRunState run;
  run.state = state;
  run.status = status;
  return run;
}

PlaneStatusView planeView() {
  PlaneStatusView view;
  view.map_frame = "plane_map";
  view.metric_source_param = "target";
  view.camera_model = "raw (K, D)";
  view.map_up = "held to it (0.2 deg)";
  return view;
}
}  // namespace

// The plane nodelet's diagnostics when all is well: OK with the pipeline's status, and
// its totals under their names.
TEST(PlaneStatus, AllWellIsTheStatusWithTheTotals) {
  PlaneRunState run = planeRun(PipelineState::kTracking, "tracking (target)");
  run.metric_source = "target";
  run.tf_edge = "plane_map -> camera_estimate";
  run.frames = 120;
  run.resets = 2;
  run.backwards_resets = 1;
  run.observed = 3;
  PlaneStatusView view = planeView();
  view.map_planes = 5;
  view.landmarks = 80;
  const auto status = planeStatus(run, view);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::OK);
  EXPECT_EQ(status.message, "tracking (target)");
  const std::pair<const char*, const char*> expected[] = {
      {"problems now", "0"},
      {"state", "tracking (target)"},
      {"images processed", "120"},
      {"resets (total)", "2"},
      {"resets: time went backwards (total)", "1"},
      {"tf", "plane_map -> camera_estimate"},
      {"metric source", "target"},
      {"camera model", "raw (K, D)"},
      {"map up (map/up_sigma_deg)", "held to it (0.2 deg)"},
      {"planes in this image", "3"},
      {"planes in the map", "5"},
      {"landmarks", "80"},
      {"odometry waited for in vain (total)", "(none)"},  // only with odom_frame
  };
  for (const auto& [key, value] : expected) EXPECT_EQ(statusValue(status, key), value) << key;
  // Before any tracks: said so, the configured source named, nothing published.
  PlaneStatusView before = planeView();
  before.publish_tf = true;
  const auto fresh = planeStatus(PlaneRunState(), before);
  EXPECT_EQ(fresh.level, diagnostic_msgs::DiagnosticStatus::OK);
  EXPECT_EQ(fresh.message, "no tracks yet");
  EXPECT_EQ(statusValue(fresh, "metric source"), "none yet (target)");
  EXPECT_EQ(statusValue(fresh, "tf"), "nothing published yet");
  EXPECT_EQ(statusValue(fresh, "landmarks"), "(none)");
  before.publish_tf = false;
  EXPECT_EQ(statusValue(planeStatus(PlaneRunState(), before), "tf"), "off");
}

// Each problem under its key with its level; the worst, first added, is the summary.
TEST(PlaneStatus, EachProblemHasItsLevelAndTheWorstIsTheSummary) {
  using diagnostic_msgs::DiagnosticStatus;
  PlaneRunState run = planeRun(PipelineState::kLost, "lost: 0.8 s without tracks");
  run.map_frame_shared = "plane_map -> odom";
  PlaneStatusView view = planeView();
  view.camera_info_overdue = true;
  auto status = planeStatus(run, view);
  EXPECT_EQ(status.level, DiagnosticStatus::WARN);
  EXPECT_EQ(status.message, mapFrameSharedText("plane_map", "plane_map -> odom"));
  EXPECT_EQ(statusValue(status, "problems now"), "3");
  EXPECT_EQ(statusValue(status, "problem: tracking"), "WARN: tracking lost: 0.8 s without tracks");
  EXPECT_EQ(statusValue(status, "problem: camera_info"),
            "WARN: tracks arrive but no usable camera_info");
  EXPECT_EQ(statusValue(status, "state"), "lost: 0.8 s without tracks");  // also then
  // A tf conflict is an ERROR and hides the shared map frame (one key each).
  run.tf_conflict = "camera_link already has the parent base_link";
  status = planeStatus(run, view);
  EXPECT_EQ(status.level, DiagnosticStatus::ERROR);
  EXPECT_EQ(status.message, "tf conflict: camera_link already has the parent base_link");
  EXPECT_EQ(statusValue(status, "tf"), "refused: camera_link already has the parent base_link");
  EXPECT_EQ(statusValue(status, "problems now"), "3");  // (the shared map frame not listed)
  // A configuration that gives no metres is an ERROR; refused values are then not listed.
  run = PlaneRunState();
  view = planeView();
  view.refused_params = {"planes/max_groups = -3 is below 1: 100 used"};
  status = planeStatus(run, view);
  EXPECT_EQ(status.level, DiagnosticStatus::WARN);
  EXPECT_NE(statusValue(status, "problem: configuration").find("max_groups"), std::string::npos);
  view.config_blocked = "metric_source odometry needs odom_frame";
  status = planeStatus(run, view);
  EXPECT_EQ(status.level, DiagnosticStatus::ERROR);
  EXPECT_EQ(statusValue(status, "problem: configuration"),
            "ERROR: metric_source odometry needs odom_frame");
  EXPECT_EQ(statusValue(status, "problems now"), "1");  // (the refused values not listed)
  // Exceptions, the stream and recent refusals: WARNs with their keys.
  view = planeView();
  view.exceptions = 2;
  view.last_exception = "tracks: bad_alloc";
  view.stream_problems = {{"tracks missing", "40 of 300 tracks missing"}};
  view.recent_problems = {{"camera_info rejected", "camera_info rejected: K is zero"}};
  status = planeStatus(run, view);
  EXPECT_EQ(status.level, DiagnosticStatus::WARN);
  EXPECT_EQ(statusValue(status, "problems now"), "3");
  EXPECT_EQ(statusValue(status, "problem: exceptions"), "WARN: exceptions caught");
  EXPECT_EQ(statusValue(status, "last exception"), "tracks: bad_alloc");
  EXPECT_EQ(statusValue(status, "problem: tracks missing"), "WARN: 40 of 300 tracks missing");
  EXPECT_EQ(statusValue(status, "problem: last 10 s, camera_info rejected"),
            "WARN: camera_info rejected: K is zero");
}

// The odometry's problems: one at a time, the most telling; what the map does without it
// depends on the metric source.
TEST(PlaneStatus, OdometryProblemsSayWhatToLookAt) {
  using diagnostic_msgs::DiagnosticStatus;
  PlaneRunState run = planeRun(PipelineState::kTracking, "tracking (odometry)");
  run.metric_source = "odometry";
  PlaneStatusView view = planeView();
  view.odom_frame = "odom";
  view.odom_waits_in_vain = 4;
  run.odometry_stopped = true;
  auto status = planeStatus(run, view);
  EXPECT_EQ(status.level, DiagnosticStatus::WARN);
  EXPECT_EQ(status.message,
            "odometry (odom) stopped, or more than odom_wait_s (0.25 s) behind the images: "
            "camera pose from vision only");
  EXPECT_EQ(statusValue(status, "odometry waited for in vain (total)"), "4");
  // Another publisher's link lags: it is named; with the target as the source no map <->
  // odom link is published for these images.
  run.metric_source = "target";
  run.odom_stale_link = "base_link -> camera_link";
  status = planeStatus(run, view);
  EXPECT_NE(status.message.find("tf base_link -> camera_link (between the camera and "
                                "odom_frame 'odom')"),
            std::string::npos);
  EXPECT_NE(status.message.find("no plane_map <-> odom tf for these images"), std::string::npos);
  // The odometry's own link lags: the odometry stopped.
  run.odom_stale_link = "odom -> base_link";
  EXPECT_EQ(planeStatus(run, view).message.rfind("odometry (odom) stopped", 0), 0u);
  // Disagreeing with the images is an ERROR, and so is a rigid odom_frame.
  view.odometry_mismatch = "the odometry does not move the camera as its images show";
  status = planeStatus(run, view);
  EXPECT_EQ(status.level, DiagnosticStatus::ERROR);
  EXPECT_EQ(status.message, view.odometry_mismatch);
  run.odom_tf_problem = "odom_frame 'base_link' is rigid with the camera";
  run.odom_rigid = true;
  status = planeStatus(run, view);
  EXPECT_EQ(status.level, DiagnosticStatus::ERROR);
  EXPECT_EQ(status.message, "no odometry: odom_frame 'base_link' is rigid with the camera");
  run.odom_rigid = false;  // not linked at all: a WARN
  EXPECT_EQ(planeStatus(run, view).level, DiagnosticStatus::WARN);
}

// The metric start that does not come: after target_timeout_s, with what to do; the
// target start that cannot finish: at once when the target left, after the timeout when
// the camera does not move.
TEST(PlaneStatus, AMetricStartThatDoesNotComeSaysWhatToDo) {
  PlaneRunState run = planeRun(PipelineState::kWaitingForTarget, "waiting for the start-up target");
  PlaneStatusView view = planeView();
  view.target_waited_s = 29;
  EXPECT_EQ(planeStatus(run, view).level, diagnostic_msgs::DiagnosticStatus::OK);
  view.target_waited_s = 31;
  auto status = planeStatus(run, view);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(status.message.rfind("start-up target not seen for 31 s: show it to the camera", 0),
            0u);
  view.metric_source_param = "camera_height";
  run.status = "waiting for the floor";
  EXPECT_EQ(planeStatus(run, view).message, "no metric start (waiting for the floor) for 31 s");
  // The tracker saw the target before camera_info: show it again.
  run.target_missed = true;
  EXPECT_NE(statusValue(planeStatus(run, view), "problem: start-up target")
                .find("before camera_info came"),
            std::string::npos);
  run.target_mismatch = "the tracker's target is 0.297 x 0.21 m, ours 0.2 x 0.2 m";
  status = planeStatus(run, view);
  EXPECT_EQ(status.level, diagnostic_msgs::DiagnosticStatus::ERROR);
  EXPECT_EQ(status.message, "start-up target: " + run.target_mismatch);
  // Initialising: the target gone for over 2 s, or no parallax for target_timeout_s.
  run = planeRun(PipelineState::kInitialising, "initialising");
  view = planeView();
  run.start_target_unseen_s = 1.5;
  run.start_wait_s = 10;
  EXPECT_EQ(planeStatus(run, view).level, diagnostic_msgs::DiagnosticStatus::OK);
  run.start_target_unseen_s = 2.5;
  EXPECT_EQ(planeStatus(run, view).message.rfind("the start-up target left the view 2.5 s ago", 0),
            0u);
  run.start_target_unseen_s = 0;
  run.start_wait_s = 31;
  EXPECT_EQ(planeStatus(run, view).message.rfind("the start has waited 31 s for parallax", 0), 0u);
}

// The map's up: whether loose planes are held to it, and why not.
TEST(PlaneStatus, MapUpSaysWhetherItHoldsAndWhyNot) {
  PipelineParams params;
  EXPECT_EQ(mapUpText(PlanePipeline(params), "target"),
            "not decided yet (at the first image placed in metres)");
  params.map.up_sigma_deg = 0;
  EXPECT_EQ(mapUpText(PlanePipeline(params), "target"), "off");
  params.map.up_sigma_deg = 0.2;
  params.map.structure_sigmas = 0;
  EXPECT_EQ(mapUpText(PlanePipeline(params), "target"), "off (map/structure_sigmas 0)");
  params.map.structure_sigmas = 3;
  params.map.up_sigma_deg = params.map.max_normal_sigma_deg + 0.5;
  EXPECT_EQ(mapUpText(PlanePipeline(params), "target"),
            "no effect: not below map/max_normal_sigma_deg");
}

// The input rate: a moment's wait for the first input after the start or a (lazy)
// subscription is not a warning; a whole window without any is; after a resubscription
// the rate counts afresh (it said "no input for the last window", then "frequency too
// low", for the first seconds of every resubscription).
TEST(WallRateStatus, WaitsAWindowForTheFirstInputAndCountsAfreshOnEachSubscription) {
  const ros::WallTime t0 = ros::WallTime::now();
  auto at = [&](double s) { return t0 + ros::WallDuration(s); };
  WallRateStatus rate(20, 40, 5.0);
  auto report = [&](double s) {
    diagnostic_updater::DiagnosticStatusWrapper status;
    rate.run(status, at(s));
    return std::make_pair(static_cast<int>(status.level), status.message);
  };
  using diagnostic_msgs::DiagnosticStatus;
  auto is = [](int level, const std::string& text) { return std::make_pair(level, text); };
  EXPECT_EQ(report(1), is(DiagnosticStatus::OK, "waiting for the first input"));
  EXPECT_EQ(report(6), is(DiagnosticStatus::WARN, "no input yet"));
  double t = 6;
  for (; t < 11; t += 1.0 / 30) rate.tick(at(t));
  EXPECT_EQ(report(11), is(DiagnosticStatus::OK, "desired frequency met"));
  rate.setIdle(true, at(12));
  EXPECT_EQ(report(13).first, static_cast<int>(DiagnosticStatus::OK));
  EXPECT_EQ(report(13).second.rfind("idle", 0), 0u);
  rate.setIdle(false, at(20));
  EXPECT_EQ(report(21), is(DiagnosticStatus::OK, "waiting for the first input"));
  for (t = 21.5; t < 22.5; t += 1.0 / 30) rate.tick(at(t));
  EXPECT_EQ(report(22.5), is(DiagnosticStatus::OK, "desired frequency met"));
  EXPECT_EQ(report(30), is(DiagnosticStatus::WARN, "no input for the last window"));
  rate.setIdle(true, at(31));
  rate.setIdle(false, at(32));
  EXPECT_EQ(report(38), is(DiagnosticStatus::WARN, "no input yet"));
  for (t = 38; t < 44; t += 1.0 / 5) rate.tick(at(t));  // 5 Hz for a whole window
  EXPECT_EQ(report(44), is(DiagnosticStatus::WARN, "frequency too low"));
  // Two messages 4 ms apart after a resubscription are no 500 Hz.
  rate.setIdle(true, at(45));
  rate.setIdle(false, at(46));
  rate.tick(at(46.5));
  rate.tick(at(46.504));
  EXPECT_EQ(report(46.508).first, static_cast<int>(DiagnosticStatus::OK)) << report(46.508).second;
}

TEST(PlaneMessages, DeleteAllMarkerClearsEveryPlaneInTheGivenFrame) {
  std_msgs::Header header;
  header.frame_id = "robot1/plane_map";
  header.stamp = ros::Time(12.5);
  const visualization_msgs::Marker clear = deleteAllMarker(header);
  EXPECT_EQ(clear.action, visualization_msgs::Marker::DELETEALL);
  EXPECT_EQ(clear.header.frame_id, "robot1/plane_map");
  EXPECT_EQ(clear.header.stamp, ros::Time(12.5));
}

TEST(WindowCounts, SumsTheLastWindowOnly) {
  WindowCounts counts(0.3);
  counts.add(1, 0);
  counts.add(1, 2);
  EXPECT_EQ(counts.sums(), std::make_pair(2L, 2L));
  ros::WallDuration(0.4).sleep();
  counts.add(1, 1);
  EXPECT_EQ(counts.sums(), std::make_pair(1L, 1L));  // the first two are out of the window
  ros::WallDuration(0.4).sleep();
  EXPECT_EQ(counts.sums(), std::make_pair(0L, 0L));
}

TEST(WindowCounts, AMissingShareOverATenthIsAProblem) {
  EXPECT_EQ(missingShareText(300, 2, "images", "why"), "");   // fewer than 3
  EXPECT_EQ(missingShareText(300, 30, "images", "why"), "");  // a tenth at most
  EXPECT_EQ(missingShareText(270, 30, "images", "why"), "");  // exactly a tenth
  EXPECT_EQ(missingShareText(269, 31, "images", "queue full"),
            "31 of 300 images missing in the last 10 s (queue full)");
  EXPECT_EQ(missingShareText(0, 3, "tracks", "why"),
            "3 of 3 tracks missing in the last 10 s (why)");
}

TEST(StreamHealth, MissingShareAndAFloodOfTimeJumps) {
  StreamHealth health;
  for (int k = 0; k < 20; ++k) health.received(k % 4 == 0 ? 1 : 0);  // 5 of 25 missing
  health.wentBackwards();
  health.wentBackwards();  // two loops: no flood
  auto problems = health.problems("images", "why", "tracking starting over", "image");
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].first, "images missing");
  EXPECT_EQ(problems[0].second, "5 of 25 images missing in the last 10 s (why)");
  health.wentBackwards();
  problems = health.problems("images", "why", "tracking starting over", "image");
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[1].first, "time");
  EXPECT_EQ(problems[1].second,
            "time went backwards 3 times in the last 10 s, tracking starting over each time: "
            "two publishers on one image topic, or two /clock sources?");
  EXPECT_TRUE(StreamHealth().problems("tracks", "", "", "tracks").empty());
  health.forget();  // the stream gone (the last listener left)
  EXPECT_TRUE(health.problems("images", "why", "tracking starting over", "image").empty());
}

TEST(RecentEvents, LogsOncePerKindAndTellsWhatHappenedLately) {
  using Recent = std::vector<std::pair<std::string, std::string>>;
  RecentEvents events;
  EXPECT_EQ(events.recent(10), Recent());
  EXPECT_TRUE(events.note("switch", "tracks mix cameras", 5));
  EXPECT_FALSE(events.note("switch", "tracks mix cameras again", 5));  // within its period
  ros::WallDuration(0.002).sleep();
  EXPECT_TRUE(events.note("size", "camera_info is for 1280x960 images", 5));  // another kind
  EXPECT_EQ(events.recent(10), (Recent{{"size", "camera_info is for 1280x960 images"},
                                       {"switch", "tracks mix cameras again"}}));
  ros::WallDuration(0.05).sleep();
  EXPECT_EQ(events.recent(0.01), Recent());  // none within the last 10 ms
}

// A burst: rare events each worth a line (a bag loop's reset) are logged up to `burst`
// times per period, a flood of them no more; the diagnostics still see the last one.
TEST(RecentEvents, ABurstLogsSeveralPerPeriodAndNoMore) {
  RecentEvents events;
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(events.note("backwards", "loop", 0.2, 3)) << k;
  EXPECT_FALSE(events.note("backwards", "loop 4", 0.2, 3));
  EXPECT_FALSE(events.note("backwards", "loop 5", 0.2, 3));
  EXPECT_EQ(events.recent(10).front().second, "loop 5");
  ros::WallDuration(0.25).sleep();  // the period over: the next ones are logged again
  EXPECT_TRUE(events.note("backwards", "loop 6", 0.2, 3));
  // Burst 1 (the default) is one per period.
  EXPECT_TRUE(events.note("gap", "pause", 0.2));
  EXPECT_FALSE(events.note("gap", "pause", 0.2));
  // The tracker's backwards event asks for the rare events' burst.
  TrackerFrontEnd front;
  const cv::Mat grey = textured({320, 240});
  ASSERT_TRUE(front.process(image(grey, 100)).tracks);
  const TrackerOutput back = front.process(image(grey, 99));
  ASSERT_FALSE(back.warnings.empty());
  EXPECT_EQ(back.warnings[0].kind, "backwards");
  EXPECT_EQ(back.warnings[0].burst, kRareEventBurst);
}

// Issue 15, case 1: secs = 4000000000 after 100: ros::Duration threw out of the callback.
TEST(TrackerFrontEnd, StampsBeyondTwoToThe31SecondsAreCompared) {
  TrackerFrontEnd front;
  const cv::Mat grey = textured({320, 240});
  EXPECT_TRUE(front.process(image(grey, 100)).tracks);
  const TrackerOutput out = front.process(image(grey, 4000000000u));
  ASSERT_TRUE(out.tracks) << out.dropped;
  ASSERT_FALSE(out.warnings.empty());
  EXPECT_EQ(out.warnings[0].kind, "gap");  // a pause: tracking starts over
  const TrackerOutput back = front.process(image(grey, 100, 500));
  ASSERT_TRUE(back.tracks);
  ASSERT_FALSE(back.warnings.empty());
  EXPECT_EQ(back.warnings[0].kind, "backwards");
}

// Issue 15, case 6: cornerSubPix asserted on a textured image under 11 px on a side.
TEST(TrackerFrontEnd, ImagesSmallerThanTheWindowsAreDropped) {
  TrackerFrontEnd front;
  uint32_t secs = 10;
  for (const cv::Size size : {cv::Size(10, 10), cv::Size(640, 6), cv::Size(8, 40)}) {
    const TrackerOutput out = front.process(image(textured(size), ++secs));
    EXPECT_FALSE(out.tracks) << size;
    EXPECT_TRUE(out.dropped_is_error);
    EXPECT_NE(out.dropped.find("smaller than the 11 px"), std::string::npos) << out.dropped;
  }
  EXPECT_EQ(front.counts().dropped, 3);
  EXPECT_TRUE(front.process(image(textured({11, 11}), ++secs)).tracks);
  // The limit follows the parameter.
  TrackerNodeParams params;
  params.tracker.reanchor_window_px = 10;
  TrackerFrontEnd wide(params);
  EXPECT_FALSE(wide.process(image(textured({24, 24}), 1)).tracks);
  EXPECT_TRUE(wide.process(image(textured({25, 25}), 2)).tracks);
}

// Issue 15, case 5: out-of-range parameters never reach OpenCV.
TEST(TrackerFrontEnd, OutOfRangeParametersAreReplacedBeforeTracking) {
  TrackerNodeParams params;
  params.tracker.min_distance_px = -5;
  params.tracker.reanchor_window_px = 1000;
  params.tracker.window_size_px = 2001;
  TrackerFrontEnd front(params);
  EXPECT_EQ(front.params().tracker.reanchor_window_px, 3);
  const cv::Mat grey = textured({320, 240});
  for (int k = 0; k < 12; ++k) EXPECT_TRUE(front.process(image(grey, 100 + k)).tracks);
}

// Issue 15, case 15: two cameras on one topic are reported, not silent.
TEST(TrackerFrontEnd, StreamMixingCamerasIsCounted) {
  TrackerFrontEnd front;
  const cv::Mat a = textured({320, 240}), b = textured({160, 120});
  for (int k = 0; k < 6; ++k) {
    const TrackerOutput out =
        front.process(image(k % 2 ? b : a, 100, k * 33000000, k % 2 ? "right" : "left"));
    ASSERT_TRUE(out.tracks);
    if (k > 0) {
      ASSERT_FALSE(out.warnings.empty());
      EXPECT_EQ(out.warnings[0].kind, "camera switch");
    }
  }
  EXPECT_EQ(front.counts().camera_switches, 5);
}

// Issue 15, case 16: images the queue (or the driver) dropped are counted by stamp gaps.
TEST(TrackerFrontEnd, ImagesMissingFromTheStreamAreCounted) {
  TrackerFrontEnd front;
  const cv::Mat grey = textured({320, 240});
  long expected_missing = 0;
  for (int k = 0; k < 58; ++k) {  // the last image, 57, arrives
    if (k >= 20 && k % 3 != 0) {  // from the 20th on two of three never arrive
      ++expected_missing;
      continue;
    }
    ASSERT_TRUE(front.process(image(grey, 100, k * 10000000)).tracks);
  }
  EXPECT_EQ(front.counts().missing, expected_missing);
  EXPECT_EQ(front.counts().dropped, 0);
}

// A stream with bad phases (hostile new-user try: a driver sending 32FC1 now and then):
// a bad image arrived, so it is dropped, not missing; images that never arrive among
// them are still missing.
TEST(TrackerFrontEnd, ImagesDroppedAsBadAreNotAlsoMissing) {
  TrackerFrontEnd front;
  const cv::Mat grey = textured({320, 240});
  cv::Mat depth(grey.size(), CV_32FC1, cv::Scalar(1.5f));
  long expected_missing = 0, expected_dropped = 0;
  for (int k = 0; k < 91; ++k) {  // the last, 90, arrives (bad): 89 is counted missing
    const uint32_t nsecs = static_cast<uint32_t>(k) * 10000000;
    if (k >= 60 && k % 4 == 1) {  // the last phase: one image in four never arrives
      ++expected_missing;
      continue;
    }
    if (k >= 20 && k % 2 == 0) {  // from the 20th on every other image is bad
      std_msgs::Header header;
      header.stamp = ros::Time(100, nsecs);
      header.frame_id = "camera";
      const TrackerOutput out =
          front.process(cv_bridge::CvImage(header, "32FC1", depth).toImageMsg());
      EXPECT_FALSE(out.tracks);
      ++expected_dropped;
      continue;
    }
    const TrackerOutput out = front.process(image(grey, 100, nsecs));
    ASSERT_TRUE(out.tracks);
    for (const LogEvent& e : out.warnings) EXPECT_NE(e.kind, "gap") << e.text;
  }
  EXPECT_EQ(front.counts().dropped, expected_dropped);
  EXPECT_EQ(front.counts().missing, expected_missing);
}

// Bad messages that are not of the tracked stream's rhythm (another camera's on the same
// topic, a broken clock's: earlier or far later) neither restart tracking nor hide the
// images missing from it.
TEST(TrackerFrontEnd, BadMessagesOfAnotherCameraOrClockLeaveTheRhythm) {
  TrackerFrontEnd front;
  const cv::Mat grey = textured({320, 240});
  const cv::Mat depth(grey.size(), CV_32FC1, cv::Scalar(1.5f));
  auto bad = [&](const ros::Time& stamp, const std::string& frame) {
    std_msgs::Header header;
    header.stamp = stamp;
    header.frame_id = frame;
    EXPECT_FALSE(front.process(cv_bridge::CvImage(header, "32FC1", depth).toImageMsg()).tracks);
  };
  long expected_missing = 0;
  Tracks::_id_type ids_at_10;
  for (int k = 0; k < 61; ++k) {
    const uint32_t nsecs = static_cast<uint32_t>(k) * 10000000;
    if (k > 10 && k % 7 == 0) {  // never arrives
      ++expected_missing;
      continue;
    }
    const TrackerOutput out = front.process(image(grey, 100, nsecs));
    ASSERT_TRUE(out.tracks);
    for (const LogEvent& e : out.warnings) EXPECT_NE(e.kind, "gap") << k << ": " << e.text;
    if (k == 10) ids_at_10 = out.tracks->id;
    bad(ros::Time(100, nsecs + 3000000), "depth");             // another camera
    if (k % 5 == 0) bad(ros::Time(95, nsecs), "camera");       // 5 s early
    if (k % 9 == 0) bad(ros::Time(4000000000u, 0), "camera");  // a clock far off
  }
  EXPECT_EQ(front.counts().missing, expected_missing);
  // Still the same tracks: no restart (most of image 10's points are still there).
  const TrackerOutput last = front.process(image(grey, 100, 610000000));
  ASSERT_TRUE(last.tracks);
  int kept = 0;
  for (auto id : ids_at_10) kept += std::count(last.tracks->id.begin(), last.tracks->id.end(), id);
  EXPECT_GT(kept, static_cast<int>(ids_at_10.size()) / 2);
}

// A 1 Hz camera (or bag): one second between images is its rhythm from the first image
// (before its period is known a pause is over 3 x max_gap_s; the first three restarted
// tracking with a WARN each before), the tracks go on (ids kept); four seconds is a pause.
TEST(TrackerFrontEnd, LowRateStreamKeepsTrackingOnceItsPeriodIsKnown) {
  TrackerFrontEnd front;
  const cv::Mat grey = textured({320, 240});
  std::vector<bool> gap;
  Tracks::_id_type first_ids;
  for (int k = 0; k < 8; ++k) {
    const TrackerOutput out = front.process(image(grey, 100 + k, k * 20000000));
    ASSERT_TRUE(out.tracks);
    bool warned = false;
    for (const LogEvent& e : out.warnings) warned |= e.kind == "gap";
    gap.push_back(warned);
    if (k == 4) first_ids = out.tracks->id;
  }
  EXPECT_EQ(gap, std::vector<bool>(8, false));
  const TrackerOutput last = front.process(image(grey, 108, 160000000));
  ASSERT_TRUE(last.tracks);
  EXPECT_EQ(last.tracks->id, first_ids);  // still the same tracks
  const TrackerOutput paused = front.process(image(grey, 112, 160000000));
  bool warned = false;
  for (const LogEvent& e : paused.warnings) warned |= e.kind == "gap";
  EXPECT_TRUE(warned);
  EXPECT_EQ(front.counts().missing, 0);
}

// Two nodelets configured apart (a letter sheet set for the tracker only) would fix a
// wrong scale: the plane nodelet names both targets; a recording without the fields, or
// the same target, passes.
TEST(PlaneMessages, TargetOfAnotherSizeIsNamed) {
  TargetParams own;  // A4 sheet
  Tracks msg;
  EXPECT_EQ(targetMismatch(msg, own), "");  // not said (an older recording)
  TrackerFrontEnd front;                    // what our tracker says: its own target/*
  const TrackerOutput out = front.process(image(textured({320, 240}), 100));
  ASSERT_TRUE(out.tracks);
  EXPECT_EQ(out.tracks->target_type, "sheet");
  EXPECT_EQ(targetMismatch(*out.tracks, own), "");
  msg = *out.tracks;
  msg.target_width_m = 0.2794f;  // US letter
  msg.target_height_m = 0.2159f;
  const std::string why = targetMismatch(msg, own);
  EXPECT_NE(why.find("0.2794 x 0.2159"), std::string::npos) << why;
  EXPECT_NE(why.find("0.297 x 0.21"), std::string::npos) << why;
  EXPECT_NE(why.find("config/target.yaml"), std::string::npos) << why;
  TargetParams marker;
  marker.target_type = "aruco";
  EXPECT_NE(targetMismatch(*out.tracks, marker), "");
  msg.target_type = "aruco";
  msg.target_width_m = msg.target_height_m = 0.15f;
  EXPECT_EQ(targetMismatch(msg, marker), "");
}

// Issue 15, case 7: an infinite translation passed tf2; a 100 m jump was accepted.
TEST(OdometryCheck, NonFiniteOrJumpingOdometryIsRefused) {
  Pose odom;
  odom.t = {1, 2, 0};
  EXPECT_EQ(odometryError(odom, std::nullopt, 1.0), "");
  Pose next = odom;
  next.t[0] += 0.2;
  EXPECT_EQ(odometryError(next, odom, 1.0), "");
  Pose infinite = odom;
  infinite.t[1] = std::numeric_limits<double>::infinity();
  EXPECT_NE(odometryError(infinite, odom, 1.0).find("not finite"), std::string::npos);
  EXPECT_NE(odometryError(infinite, std::nullopt, 1.0), "");
  Pose far = odom;
  far.t[0] += 100;
  EXPECT_NE(odometryError(far, odom, 1.0).find("moved 100 m"), std::string::npos);
  Pose nan_rotation = odom;
  nan_rotation.R(0, 0) = std::nan("");
  EXPECT_NE(odometryError(nan_rotation, odom, 1.0), "");
}

// Issue 12, bad input: a target that is never found. Images keep being tracked; after
// target_timeout_s of image stamps the front end warns with the detector's reason, and
// the diagnostics' state (targetOverdue, targetReason) says it.
TEST(TrackerFrontEnd, NoTargetWarnsAfterTheTimeoutWithTheReason) {
  TrackerNodeParams params;
  params.target_timeout_s = 2.0;
  TrackerFrontEnd front(params);
  const cv::Mat grey = textured({320, 240});
  bool warned_early = false, warned = false;
  for (int k = 0; k <= 30; ++k) {  // 10 Hz, 3 s
    const TrackerOutput out = front.process(image(grey, 100 + k / 10, (k % 10) * 100000000));
    ASSERT_TRUE(out.tracks) << out.dropped;
    for (const LogEvent& e : out.warnings) {
      if (e.kind != "target timeout") continue;
      (k <= 20 ? warned_early : warned) = true;
      EXPECT_NE(e.text.find(front.targetReason()), std::string::npos) << e.text;
      // What to show the camera, in plain words (a new user does not know the parameters).
      EXPECT_NE(e.text.find("(a white sheet 0.297 x 0.21 m on a darker surface)"),
                std::string::npos)
          << e.text;
    }
    EXPECT_EQ(front.targetOverdue(), k > 20) << k;
  }
  EXPECT_FALSE(warned_early);
  EXPECT_TRUE(warned);
  EXPECT_FALSE(front.targetFound());
  EXPECT_FALSE(front.targetReason().empty());
  EXPECT_NEAR(front.targetWaitS(), 3.0, 1e-6);
  front.reset();  // nobody listens: the wait starts again
  EXPECT_FALSE(front.targetOverdue());
  EXPECT_EQ(front.targetWaitS(), 0.0);
  // One image stamped 1000 s (a bad driver clock), then the real stamps again: the jumps
  // are no waiting (hostile try: "no start-up target for 1796233216.6 s", for good).
  for (int k = 0; k <= 10; ++k) front.process(image(grey, 100 + k / 10, (k % 10) * 100000000));
  front.process(image(grey, 1000, 0));
  front.process(image(grey, 1000, 100000000));
  for (int k = 0; k <= 10; ++k) front.process(image(grey, 102 + k / 10, (k % 10) * 100000000));
  EXPECT_NEAR(front.targetWaitS(), 1.0 + 0.1 + 1.0, 1e-6);
  EXPECT_TRUE(front.targetOverdue());  // 2.1 s of images searched, over the 2 s
  params.target.target_type = "aruco";
  EXPECT_EQ(TrackerFrontEnd(params).targetDescription(), "ArUco marker DICT_4X4_50 id 0, 0.15 m");
}

// A bag looped: the target found in each loop after 1.5 s of images without it. The wait
// is for a target not seen since it was last found: 1.5 s in every loop, never overdue
// at a timeout of 2 s (it added up over the loops: 3 s in the second).
TEST(TrackerFrontEnd, TheTargetWaitStartsOverOnceTheTargetIsFound) {
  TrackerNodeParams params;
  params.target_timeout_s = 2.0;
  TrackerFrontEnd front(params);
  EXPECT_EQ(front.setCameraInfo(cameraInfo({0, 0, 0, 0, 0})), "");
  const cv::Mat grey = textured({640, 480});
  cv::Mat sheet(480, 640, CV_8UC1, cv::Scalar(30));
  sheet(cv::Rect(200, 150, 212, 150)).setTo(230);
  for (int loop = 0; loop < 3; ++loop) {
    for (int k = 0; k <= 15; ++k) {  // 10 Hz, 1.5 s without the target
      front.process(image(grey, 100 + k / 10, (k % 10) * 100000000));
      EXPECT_FALSE(front.targetOverdue()) << "loop " << loop << " image " << k;
    }
    EXPECT_NEAR(front.targetWaitS(), 1.5, 1e-6) << "loop " << loop;
    for (int k = 16; k < 22 && !front.targetFound(); ++k)
      front.process(image(sheet, 100 + k / 10, (k % 10) * 100000000));
    ASSERT_TRUE(front.targetFound()) << "loop " << loop << ": " << front.targetReason();
    EXPECT_EQ(front.targetWaitS(), 0.0);
  }
}

// The focal length from camera_info reaches the detector: a square seen head-on is not an
// A4 sheet once the focal length is known (without it, some focal length would make it
// one seen obliquely).
TEST(TrackerFrontEnd, TargetFoundAndConfirmedWithTheCameraInfo) {
  TrackerNodeParams params;
  TrackerFrontEnd front(params);
  EXPECT_EQ(front.setCameraInfo(cameraInfo({0, 0, 0, 0, 0})), "");
  cv::Mat sheet(480, 640, CV_8UC1, cv::Scalar(30));
  sheet(cv::Rect(200, 150, 212, 150)).setTo(230);
  int found_at = -1;
  for (int k = 0; k < 5 && found_at < 0; ++k) {
    const TrackerOutput out = front.process(image(sheet, 100, k * 100000000));
    ASSERT_TRUE(out.tracks);
    if (front.targetFound()) found_at = k;
  }
  EXPECT_EQ(found_at, params.target.confirm_frames - 1);
  TrackerFrontEnd square_front(params);
  square_front.setCameraInfo(cameraInfo({0, 0, 0, 0, 0}));
  cv::Mat square(480, 640, CV_8UC1, cv::Scalar(30));
  square(cv::Rect(220, 140, 200, 200)).setTo(230);
  for (int k = 0; k < 5; ++k) square_front.process(image(square, 100, k * 100000000));
  EXPECT_FALSE(square_front.targetFound());
  EXPECT_NE(square_front.targetReason().find("rectified width/height"), std::string::npos)
      << square_front.targetReason();
  EXPECT_NE(square_front.targetRejections().find("aspect ratio "), std::string::npos)
      << square_front.targetRejections();
}

// A camera_info for another image size (1280x720, principal point 640, 360) is not the
// images' camera: the sheet is searched as in a photo (focal length unknown), not with
// those intrinsics, which make an oblique A4 sheet 2.19 wide after rectification.
TEST(TrackerFrontEnd, TargetNotJudgedWithTheIntrinsicsOfAnotherImageSize) {
  cv::Mat sheet(480, 640, CV_8UC1, cv::Scalar(30));
  std::vector<cv::Point> corners;  // A4 0.8 m ahead, tilted 45 deg about x, 30 deg about y
  const double tilt = 45 * CV_PI / 180, pan = 30 * CV_PI / 180;
  for (const auto& c : targetCornersInMap(TargetParams())) {
    const cv::Vec3d t(c.x, std::cos(tilt) * c.y, std::sin(tilt) * c.y);
    const cv::Vec3d x(std::cos(pan) * t[0] + std::sin(pan) * t[2], t[1],
                      0.8 - std::sin(pan) * t[0] + std::cos(pan) * t[2]);
    corners.emplace_back(cvRound(320 + 500 * x[0] / x[2]), cvRound(240 + 500 * x[1] / x[2]));
  }
  cv::fillConvexPoly(sheet, corners, 230);
  sensor_msgs::CameraInfo other = cameraInfo({-0.3, 0.08, 0, 0, 0});  // a wide lens
  other.width = 1280;
  other.height = 720;
  other.K = {500, 0, 640, 0, 500, 360, 0, 0, 1};
  other.P = {500, 0, 640, 0, 0, 500, 360, 0, 0, 0, 1, 0};
  TrackerNodeParams params;
  TrackerFrontEnd front(params);
  EXPECT_EQ(front.setCameraInfo(other), "");
  for (int k = 0; k < 5 && !front.targetFound(); ++k)
    front.process(image(sheet, 100, k * 100000000));
  EXPECT_TRUE(front.targetFound()) << front.targetReason();
}

// Issue 18: `planes` lists tentative map planes too; `confirmed` (the map's own rule:
// observations from viewpoints apart, a normal its points fix) tells them apart, in the
// message, the saved YAML and the rviz labels.
TEST(PlaneMessages, ConfirmedPlanesAreFlagged) {
  PlaneMap map;
  auto wall = [](unsigned seed, std::uint64_t first_id) {  // the wall z = 2, from 2 m
    PlaneObservation obs;
    obs.viewpoint = {0.3 * seed, 0, 0};
    for (int i = 0; i < 30; ++i) {
      obs.ids.push_back(first_id + i);
      obs.points.push_back({-1.0 + 0.07 * i, -0.5 + (i * 7 % 10) * 0.1, 2.0});
    }
    return obs;
  };
  auto floor = [](std::uint64_t first_id) {  // y = 0.8, seen once
    PlaneObservation obs;
    obs.viewpoint = {0, 0, 0};
    for (int i = 0; i < 30; ++i) {
      obs.ids.push_back(first_id + i);
      obs.points.push_back({-1.0 + 0.07 * i, 0.8, 1.0 + (i * 7 % 10) * 0.1});
    }
    return obs;
  };
  for (unsigned k = 0; k < 5; ++k) map.update({wall(k, 100)}, 10.0 + k);
  map.update({floor(500)}, 15.0);
  ASSERT_EQ(map.planes().size(), 2u);
  std_msgs::Header header;
  header.frame_id = "plane_map";
  const PlaneArrayPtr msg = toMapPlanes(header, PipelineResult{}, map);
  ASSERT_EQ(msg->planes.size(), 2u);
  int confirmed = 0, tentative = 0;
  for (const PlaneEstimate& p : msg->planes) {
    const bool is_wall = p.observations >= 3;
    EXPECT_EQ(p.confirmed, is_wall) << "plane " << p.id << ", " << p.observations << " views";
    (p.confirmed ? confirmed : tentative) += 1;
  }
  EXPECT_EQ(confirmed, 1);
  EXPECT_EQ(tentative, 1);
  for (auto& p : msg->planes) p.metric = true;  // as in a metric image
  const std::string yaml = planesYaml(*msg);
  EXPECT_NE(yaml.find("confirmed: true"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("confirmed: false"), std::string::npos) << yaml;
  std::set<int> shown;
  int tentative_labels = 0;
  const visualization_msgs::MarkerArrayPtr markers = toMarkers(header, map, shown);
  for (const auto& m : markers->markers)
    if (m.ns == "labels") tentative_labels += m.text.find("tentative") != std::string::npos;
  EXPECT_EQ(tentative_labels, 1);
}

namespace {

// A fresh folder under gtest's temporary directory; removed with what is in it, and the
// working directory given back, however the test ends.
struct ScratchDir {
  std::string path, cwd;
  ScratchDir() {
    std::string pattern = testing::TempDir();
    if (pattern.empty() || pattern.back() != '/') pattern += '/';
    pattern += "mpd_map_file_XXXXXX";
    if (mkdtemp(pattern.data()) != nullptr) path = pattern;
    if (char* const here = getcwd(nullptr, 0)) {
      cwd = here;
      std::free(here);
    }
  }
  ~ScratchDir() {
    if (!cwd.empty() && chdir(cwd.c_str()) != 0) std::perror("chdir back");
    std::error_code error;
    if (!path.empty()) std::filesystem::remove_all(path, error);
  }
};

}  // namespace

// ~save_map's file (writeMapFile): the YAML of the planes, metric planes counted; a
// relative path answered with the whole path (the manager's working directory is not
// the caller's); nothing written (no folder, a full disk, no path, no map) names why.
TEST(MapFile, WritesThePlanesAndSaysWhere) {
  PlaneArray planes;
  planes.header.frame_id = "plane_map";
  planes.planes.resize(3);
  planes.planes[0].metric = planes.planes[1].metric = true;  // the third: image space only
  planes.planes[0].label = PlaneEstimate::LABEL_FLOOR;
  const ScratchDir scratch;
  ASSERT_FALSE(scratch.path.empty());
  ASSERT_FALSE(scratch.cwd.empty());
  const std::string& dir = scratch.path;
  const std::string path = dir + "/map.yaml";
  const MapFileResult written = writeMapFile(&planes, path);
  ASSERT_TRUE(written.success) << written.message;
  EXPECT_EQ(written.planes, 2);
  EXPECT_EQ(written.message, "wrote 2 planes to " + path);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), planesYaml(planes));

  ASSERT_EQ(chdir(dir.c_str()), 0);
  const MapFileResult relative = writeMapFile(&planes, "relative.yaml");
  ASSERT_EQ(chdir(scratch.cwd.c_str()), 0);
  EXPECT_TRUE(relative.success) << relative.message;
  EXPECT_EQ(relative.message, "wrote 2 planes to " + dir + "/relative.yaml");
  EXPECT_TRUE(std::ifstream(dir + "/relative.yaml").good());

  const MapFileResult nowhere = writeMapFile(&planes, dir + "/no_such_dir/map.yaml");
  EXPECT_FALSE(nowhere.success);
  EXPECT_EQ(nowhere.message,
            "cannot write " + dir + "/no_such_dir/map.yaml (No such file or directory)");
  // Opened, but the writing fails (a full disk).
  if (std::ifstream("/dev/full").good()) {
    const MapFileResult full = writeMapFile(&planes, "/dev/full");
    EXPECT_FALSE(full.success);
    EXPECT_EQ(full.message, "cannot write /dev/full (write failed)");
  }
  // An empty path is refused first, map or not.
  for (const PlaneArray* map : std::initializer_list<const PlaneArray*>{&planes, nullptr}) {
    const MapFileResult no_path = writeMapFile(map, "");
    EXPECT_FALSE(no_path.success);
    EXPECT_EQ(no_path.message, "no path given");
  }
  const MapFileResult no_map = writeMapFile(nullptr, dir + "/unwritten.yaml");
  EXPECT_FALSE(no_map.success);
  EXPECT_EQ(no_map.message, "no map yet");
  EXPECT_FALSE(std::ifstream(dir + "/unwritten.yaml").good());
}

// rviz lights a triangle by the normal of its winding (the light comes from the viewer): a
// wall seen from behind was drawn nearly black. Every surface triangle comes twice, first
// wound away from the side its plane was seen from (the marker's normal arrow), then
// towards it, for walls seen from either side and the floor.
TEST(PlaneMessages, SurfacesFaceTheSideTheyWereSeenFrom) {
  PlaneMap map;
  auto wall = [](double z, double viewer_z, std::uint64_t first_id, unsigned k) {
    PlaneObservation obs;
    obs.viewpoint = {0.3 * k, 0, viewer_z};
    for (int i = 0; i < 30; ++i) {
      obs.ids.push_back(first_id + i);
      obs.points.push_back({-1.0 + 0.07 * i, -0.5 + (i * 7 % 10) * 0.1, z});
    }
    return obs;
  };
  auto floor = [](std::uint64_t first_id, unsigned k) {  // y = 0.8 (core frame: y down)
    PlaneObservation obs;
    obs.viewpoint = {0.3 * k, 0, 0};
    for (int i = 0; i < 30; ++i) {
      obs.ids.push_back(first_id + i);
      obs.points.push_back({-1.0 + 0.07 * i, 0.8, 1.0 + (i * 7 % 10) * 0.1});
    }
    return obs;
  };
  for (unsigned k = 0; k < 5; ++k)
    map.update({wall(2.0, 0.0, 100, k), wall(-2.0, 0.0, 300, k), floor(500, k)}, 10.0 + k);
  ASSERT_EQ(map.planes().size(), 3u);
  std_msgs::Header header;
  header.frame_id = "plane_map";
  std::set<int> shown;
  const visualization_msgs::MarkerArrayPtr markers = toMarkers(header, map, shown);
  std::map<int, cv::Vec3d> normal_of;
  for (const auto& m : markers->markers)
    if (m.ns == "normals")
      normal_of[m.id] = cv::Vec3d(m.points[1].x - m.points[0].x, m.points[1].y - m.points[0].y,
                                  m.points[1].z - m.points[0].z);
  int triangles = 0;
  for (const auto& m : markers->markers) {
    if (m.ns != "planes") continue;
    ASSERT_TRUE(normal_of.count(m.id));
    ASSERT_EQ(m.points.size() % 6, 0u);
    auto v = [&](size_t i) { return cv::Vec3d(m.points[i].x, m.points[i].y, m.points[i].z); };
    auto facing = [&](size_t t) {
      return (v(t + 1) - v(t)).cross(v(t + 2) - v(t)).dot(normal_of[m.id]);
    };
    for (size_t t = 0; t < m.points.size(); t += 6) {
      EXPECT_LT(facing(t), 0) << "plane " << m.id << ", triangle " << t / 3;
      EXPECT_GT(facing(t + 3), 0) << "plane " << m.id << ", triangle " << t / 3 + 1;
      ++triangles;
    }
  }
  EXPECT_GE(triangles, 9);
  // Wall labels above their top edge (the floor's label stood on the wall's in rviz).
  int walls = 0;
  for (const auto& m : markers->markers) {
    if (m.ns != "labels") continue;
    const bool is_wall = m.text.rfind("wall", 0) == 0;
    double top = -1e9;
    for (const auto& s : markers->markers)
      if (s.ns == "planes" && s.id == m.id)
        for (const auto& v : s.points) top = std::max(top, v.z);
    if (is_wall) {
      EXPECT_GT(m.pose.position.z, top + 0.5 * m.scale.z) << m.text;
      EXPECT_LT(m.pose.position.z, top + 2 * m.scale.z) << m.text;
    } else {  // (flat: its top is its height; 0.35 m off it along its normal)
      EXPECT_NEAR(std::abs(m.pose.position.z - top), 0.35, 1e-6) << m.text;
    }
    walls += is_wall;
  }
  EXPECT_EQ(walls, 2);
}

// dynamic_reconfigure's way in: the tracker's new values are taken (the next image's
// tracks follow them) or refused with the reason and nothing changed.
TEST(TrackerFrontEnd, TrackerParamsChangeBetweenImagesOrAreRefused) {
  TrackerFrontEnd front;
  const cv::Mat grey = textured({320, 240});
  const TrackerOutput first = front.process(image(grey, 100));
  ASSERT_TRUE(first.tracks);
  ASSERT_GT(first.tracks->id.size(), 10u);
  TrackerParams fewer = front.params().tracker;
  fewer.max_features = 10;
  EXPECT_EQ(front.setTrackerParams(fewer), "");
  EXPECT_EQ(front.params().tracker.max_features, 10);
  const TrackerOutput next = front.process(image(grey, 100, 100000000));
  ASSERT_TRUE(next.tracks) << next.dropped;
  EXPECT_EQ(next.tracks->id.size(), 10u);
  TrackerParams other_pyramid = fewer;
  other_pyramid.pyramid_levels = 2;
  EXPECT_NE(front.setTrackerParams(other_pyramid), "");
  EXPECT_EQ(front.params().tracker.pyramid_levels, TrackerParams().pyramid_levels);
}

// Tracks -> TrackFrame: the flags the pipeline uses (the target's corners; re-identified
// points, which are no sign of a tracker that started over).
TEST(PlaneMessages, TracksFlagsReachTheFrame) {
  Tracks msg;
  msg.header.stamp = ros::Time(10, 0);
  msg.width = 640;
  msg.height = 480;
  msg.id = {3, 8, 9};
  msg.u = {10, 20, 30};
  msg.v = {40, 50, 60};
  msg.flags = {Tracks::FLAG_TRACKED, Tracks::FLAG_TARGET_CORNER | Tracks::FLAG_TRACKED,
               Tracks::FLAG_REIDENTIFIED | Tracks::FLAG_NEW};
  msg.prev_index = {0, 1, -1};
  msg.age = {5, 5, 0};
  std::string error;
  const TrackFrame frame = toTrackFrame(msg, error);
  EXPECT_EQ(error, "");
  EXPECT_EQ(frame.target_corner, (std::vector<bool>{false, true, false}));
  EXPECT_EQ(frame.reidentified, (std::vector<bool>{false, false, true}));
  EXPECT_EQ(frame.ids, (std::vector<std::uint64_t>{3, 8, 9}));
  EXPECT_EQ(frame.tracker_run, 0u);  // not said
  msg.tracker_run = 1234;
  EXPECT_EQ(toTrackFrame(msg, error).tracker_run, 1234u);
}

// Every message of one tracker says the same run, never 0; another tracker another
// (a reloaded or respawned nodelet), also after ~reset the same.
TEST(TrackerFrontEnd, TracksSayTheTrackersRun) {
  TrackerFrontEnd front, other;
  const cv::Mat grey = textured({320, 240});
  const TrackerOutput a = front.process(image(grey, 100));
  const TrackerOutput b = front.process(image(grey, 100, 100000000));
  ASSERT_TRUE(a.tracks && b.tracks);
  EXPECT_NE(a.tracks->tracker_run, 0u);
  EXPECT_EQ(a.tracks->tracker_run, b.tracks->tracker_run);
  EXPECT_EQ(a.tracks->tracker_run, front.run());
  front.reset();
  const TrackerOutput c = front.process(image(grey, 101));
  ASSERT_TRUE(c.tracks);
  EXPECT_EQ(c.tracks->tracker_run, a.tracks->tracker_run);
  EXPECT_NE(other.run(), front.run());  // (2^-32 by chance)
}
