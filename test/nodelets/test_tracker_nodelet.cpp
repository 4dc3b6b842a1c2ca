// Drives TrackerNodelet with images of known motion and bad input; checks `tracks`.
#include <cv_bridge/cv_bridge.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <gtest/gtest.h>
#include <nodelet/NodeletList.h>
#include <nodelet/NodeletLoad.h>
#include <nodelet/NodeletUnload.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_srvs/Empty.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <map>
#include <opencv2/imgproc.hpp>
#include <set>

#include "mono_plane_detection/Tracks.h"
#include "mono_plane_detection/sim/scene_renderer.h"
#include "mono_plane_detection/sim/synthetic_views.h"
#include "support/diagnostics_probe.h"
#include "support/test_timeouts.h"

using namespace mono_plane_detection;

namespace {

const cv::Size kView(640, 480);
const cv::Point2d kCentred(-180, -160);

class TrackerNodeletTest : public ::testing::Test {
 protected:
  void SetUp() override {
    image_pub_ = nh_.advertise<sensor_msgs::Image>("image", 10);
    tracks_sub_ = nh_.subscribe("tracks", 50, &TrackerNodeletTest::onTracks, this);
    // The nodelet subscribes lazily: wait until our listener made it subscribe.
    spinUntil([&] { return image_pub_.getNumSubscribers() > 0; }, 20.0);
    ASSERT_GT(image_pub_.getNumSubscribers(), 0u) << "tracker never subscribed to image";
  }

  void onTracks(const TracksConstPtr& msg) { received_[msg->header.stamp.toNSec()] = msg; }

  sensor_msgs::ImagePtr makeImage(const cv::Mat& image, const std::string& encoding, double stamp) {
    std_msgs::Header header;
    header.stamp = ros::Time(stamp);
    header.frame_id = "camera_optical";
    return cv_bridge::CvImage(header, encoding, image).toImageMsg();
  }

  // Publishes and waits for the Tracks of this stamp; null when none came.
  TracksConstPtr send(const sensor_msgs::ImagePtr& msg, double timeout = 5.0) {
    image_pub_.publish(msg);
    const auto key = msg->header.stamp.toNSec();
    if (!spinUntil([&] { return received_.count(key) > 0; }, timeout)) return nullptr;
    return received_.at(key);
  }

  cv::Mat view(const cv::Point2d& shift) {
    static const cv::Mat texture = makeCornerTexture({1000, 800}, 42);
    return warpView(texture, similarity(0, {}, kCentred + shift), kView);
  }

  ros::NodeHandle nh_;
  ros::Publisher image_pub_;
  ros::Subscriber tracks_sub_;
  std::map<uint64_t, TracksConstPtr> received_;
  double stamp_ = 100.0;
};

TEST_F(TrackerNodeletTest, TracksFollowKnownMotion) {
  const cv::Point2d step(1.5, -0.5);
  std::map<uint64_t, cv::Point2d> texture_of;  // id -> shift-free position at birth
  std::set<uint64_t> first_ids;
  double error_sum = 0;
  int error_count = 0;
  for (int k = 0; k < 20; ++k) {
    const cv::Point2d shift = k * step;
    auto tracks = send(makeImage(view(shift), "mono8", stamp_ += 0.1));
    ASSERT_TRUE(tracks) << "no tracks for frame " << k;
    EXPECT_EQ(tracks->header.frame_id, "camera_optical");
    EXPECT_EQ(tracks->width, 640u);
    EXPECT_EQ(tracks->height, 480u);
    const size_t n = tracks->id.size();
    ASSERT_EQ(tracks->u.size(), n);
    ASSERT_EQ(tracks->v.size(), n);
    ASSERT_EQ(tracks->flags.size(), n);
    ASSERT_EQ(tracks->prev_index.size(), n);
    ASSERT_EQ(tracks->age.size(), n);
    if (k == 0) {
      EXPECT_EQ(n, 50u);
      EXPECT_TRUE(tracks->searched);
    }
    for (size_t i = 0; i < n; ++i) {
      const cv::Point2d uv(tracks->u[i], tracks->v[i]);
      if (k == 0) first_ids.insert(tracks->id[i]);
      auto it = texture_of.find(tracks->id[i]);
      if (it == texture_of.end()) {
        EXPECT_TRUE(tracks->flags[i] & Tracks::FLAG_NEW);
        EXPECT_EQ(tracks->prev_index[i], -1);
        texture_of[tracks->id[i]] = uv - shift;
        continue;
      }
      EXPECT_TRUE(tracks->flags[i] & Tracks::FLAG_TRACKED);
      EXPECT_GE(tracks->prev_index[i], 0);
      error_sum += cv::norm(it->second + shift - uv);
      ++error_count;
    }
  }
  ASSERT_GT(error_count, 500);
  EXPECT_LT(error_sum / error_count, 0.2);
  auto last = received_.rbegin()->second;
  int kept = 0;
  for (auto id : last->id) kept += first_ids.count(id);
  EXPECT_GE(kept, 45);
}

TEST_F(TrackerNodeletTest, AcceptsColourBayerAndSixteenBitImages) {
  cv::Mat bgr;
  cv::cvtColor(view({0, 0}), bgr, cv::COLOR_GRAY2BGR);
  auto tracks = send(makeImage(bgr, "bgr8", stamp_ += 0.1));
  ASSERT_TRUE(tracks);
  EXPECT_EQ(tracks->id.size(), 50u);

  cv::Mat rgba;
  cv::cvtColor(view({0, 0}), rgba, cv::COLOR_GRAY2RGBA);
  tracks = send(makeImage(rgba, "rgba8", stamp_ += 0.1));
  ASSERT_TRUE(tracks);
  EXPECT_EQ(tracks->id.size(), 50u);

  cv::Mat wide;
  view({0, 0}).convertTo(wide, CV_16U, 256.0);
  tracks = send(makeImage(wide, "mono16", stamp_ += 0.1));
  ASSERT_TRUE(tracks);
  EXPECT_EQ(tracks->id.size(), 50u);

  tracks = send(makeImage(view({0, 0}), "bayer_rggb8", stamp_ += 0.1));
  ASSERT_TRUE(tracks);
  EXPECT_GT(tracks->id.size(), 20u);
}

TEST_F(TrackerNodeletTest, BadImagesAreDroppedAndTrackingGoesOn) {
  auto good = send(makeImage(view({0, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(good);

  // Unsupported encoding: dropped, nothing published. A depth image (16UC1) is named as
  // what it is in plain words (it was cv_bridge's "is not a color format ... does not make
  // sense"), in diagnostics as a problem of its own.
  cv::Mat floats(480, 640, CV_32FC1, cv::Scalar(0.5));
  EXPECT_FALSE(send(makeImage(floats, "32FC1", stamp_ += 0.1), 1.0));
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(1200));
  EXPECT_FALSE(send(makeImage(depth, "16UC1", stamp_ += 0.1), 1.0));
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  ASSERT_TRUE(diagnostics.waitFresh());
  const std::string said = diagnostics.value("problem: last 10 s, unsupported encoding '16UC1'");
  EXPECT_NE(said.find("depth or other single-value images (16UC1) are not supported; use the "
                      "camera's grey or colour image (mono8/mono16 or bgr8)"),
            std::string::npos)
      << said;
  EXPECT_FALSE(diagnostics.value("problem: last 10 s, unsupported encoding '32FC1'").empty());
  auto weird = makeImage(view({0, 0}), "mono8", stamp_ += 0.1);
  weird->encoding = "no_such_encoding";
  EXPECT_FALSE(send(weird, 1.0));

  // 0x0 image and a buffer shorter than step x height: dropped.
  auto empty = boost::make_shared<sensor_msgs::Image>();
  empty->header.stamp = ros::Time(stamp_ += 0.1);
  empty->encoding = "mono8";
  EXPECT_FALSE(send(empty, 1.0));
  auto truncated = makeImage(view({0, 0}), "mono8", stamp_ += 0.1);
  truncated->data.resize(1000);
  EXPECT_FALSE(send(truncated, 1.0));

  // A good image after all that: the same points are still tracked.
  auto after = send(makeImage(view({1, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(after);
  std::set<uint64_t> before(good->id.begin(), good->id.end());
  int kept = 0;
  for (auto id : after->id) kept += before.count(id);
  EXPECT_GE(kept, 45);
}

TEST_F(TrackerNodeletTest, BlackTinyAndResizedImages) {
  auto black = send(makeImage(cv::Mat(480, 640, CV_8UC1, cv::Scalar(0)), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(black);
  EXPECT_TRUE(black->id.empty());

  // Smaller than the tracker's windows (11 px with the defaults): dropped with an error.
  EXPECT_FALSE(send(makeImage(cv::Mat(1, 1, CV_8UC1, cv::Scalar(7)), "mono8", stamp_ += 0.1), 1.0));

  cv::Mat small;
  cv::resize(view({0, 0}), small, {320, 240}, 0, 0, cv::INTER_AREA);
  auto resized = send(makeImage(small, "mono8", stamp_ += 0.1));
  ASSERT_TRUE(resized);
  EXPECT_EQ(resized->width, 320u);
  ASSERT_FALSE(resized->id.empty());
  for (auto f : resized->flags) EXPECT_TRUE(f & Tracks::FLAG_NEW);
}

TEST_F(TrackerNodeletTest, WhiteOddHugeAndBigEndianImages) {
  // All white and saturated: no corners, an empty answer.
  auto white = send(makeImage(cv::Mat(480, 640, CV_8UC1, cv::Scalar(255)), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(white);
  EXPECT_TRUE(white->id.empty());
  // An odd size.
  cv::Mat odd;
  cv::resize(view({0, 0}), odd, {641, 479});
  auto odd_tracks = send(makeImage(odd, "mono8", stamp_ += 0.1));
  ASSERT_TRUE(odd_tracks);
  EXPECT_EQ(odd_tracks->width, 641u);
  EXPECT_FALSE(odd_tracks->id.empty());
  // A huge frame is still answered (slowly).
  cv::Mat huge;
  cv::resize(view({0, 0}), huge, {4096, 3072}, 0, 0, cv::INTER_LINEAR);
  const ros::WallTime start = ros::WallTime::now();
  auto huge_tracks = send(makeImage(huge, "mono8", stamp_ += 0.1), 30.0);
  ASSERT_TRUE(huge_tracks);
  EXPECT_EQ(huge_tracks->width, 4096u);
  EXPECT_FALSE(huge_tracks->id.empty());
  std::printf("4096x3072: answered in %.0f ms\n", (ros::WallTime::now() - start).toSec() * 1e3);
  // Big-endian mono16: the bytes of each pixel swapped, the same view.
  cv::Mat wide;
  view({0, 0}).convertTo(wide, CV_16U, 256.0);
  auto big = makeImage(wide, "mono16", stamp_ += 0.1);
  big->is_bigendian = 1;
  for (size_t i = 0; i + 1 < big->data.size(); i += 2) std::swap(big->data[i], big->data[i + 1]);
  auto big_tracks = send(big);
  ASSERT_TRUE(big_tracks);
  auto little_tracks = send(makeImage(wide, "mono16", stamp_ += 0.1));
  ASSERT_TRUE(little_tracks);
  // Read right, the big-endian image is the same view: its points are tracked on.
  int tracked = 0;
  for (auto f : little_tracks->flags) tracked += (f & Tracks::FLAG_TRACKED) != 0;
  EXPECT_GE(tracked, 45);
}

TEST_F(TrackerNodeletTest, DuplicateStampsGapsAndEmptyFrameIds) {
  auto first = send(makeImage(view({0, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(first);
  // The same stamp again: dropped.
  received_.clear();
  auto again = makeImage(view({0.5, 0}), "mono8", stamp_);
  EXPECT_FALSE(send(again, 1.0));
  // After a 4 s pause: tracking starts over (every point new; over 3 x max_gap_s, a pause
  // also while the stream's period is not known yet).
  auto after_gap = send(makeImage(view({0.5, 0}), "mono8", stamp_ += 4.0));
  ASSERT_TRUE(after_gap);
  ASSERT_GE(after_gap->flags.size(), 45u);
  for (auto f : after_gap->flags) EXPECT_TRUE(f & Tracks::FLAG_NEW);
  // An empty frame_id is passed on (with a warning), tracking goes on.
  auto unnamed = makeImage(view({1, 0}), "mono8", stamp_ += 0.1);
  unnamed->header.frame_id.clear();
  auto tracks = send(unnamed);
  ASSERT_TRUE(tracks);
  EXPECT_EQ(tracks->header.frame_id, "");
  int tracked = 0;
  for (auto f : tracks->flags) tracked += (f & Tracks::FLAG_TRACKED) != 0;
  EXPECT_GE(tracked, 45);
}

TEST_F(TrackerNodeletTest, TimeGoingBackwardsStartsOver) {
  ASSERT_TRUE(send(makeImage(view({0, 0}), "mono8", stamp_ += 0.1)));
  auto same = send(makeImage(view({0.5, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(same);
  ASSERT_GE(same->flags.size(), 45u);
  for (auto f : same->flags) EXPECT_TRUE(f & Tracks::FLAG_TRACKED);
  auto looped = send(makeImage(view({1, 0}), "mono8", stamp_ - 50.0));
  ASSERT_TRUE(looped);
  ASSERT_GE(looped->flags.size(), 45u);
  ASSERT_EQ(looped->prev_index.size(), looped->flags.size());
  for (auto f : looped->flags) EXPECT_TRUE(f & Tracks::FLAG_NEW);
  for (auto p : looped->prev_index) EXPECT_EQ(p, -1);
  // Counted with the resets (it counted ~reset calls only).
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_GE(diagnostics.number("resets: time went backwards (total)"), 1);
  EXPECT_GE(diagnostics.number("resets (total)"),
            diagnostics.number("resets: time went backwards (total)"));
}

// A camera_info for another image size (1280x720, no binning) is not the images' camera:
// not used, an ERROR in diagnostics that names both sizes and what to do, counted; one
// for the images' size is used from the next image on (it said "camera_info: ok").
TEST_F(TrackerNodeletTest, BadOrMismatchedCameraInfoDoesNotStopTracking) {
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  ros::Publisher info_pub = nh_.advertise<sensor_msgs::CameraInfo>("camera_info", 1, true);
  sensor_msgs::CameraInfo zero;  // all-zero intrinsics
  zero.width = 640;
  zero.height = 480;
  info_pub.publish(zero);
  scaledWait(0.3).sleep();
  auto tracks = send(makeImage(view({0, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(tracks);
  EXPECT_EQ(tracks->id.size(), 50u);

  sensor_msgs::CameraInfo other_size;  // valid, but for another image size
  other_size.width = 1280;
  other_size.height = 720;
  other_size.K = {525, 0, 640, 0, 525, 360, 0, 0, 1};
  other_size.K[2] = std::nan("");
  info_pub.publish(other_size);
  other_size.K[2] = 640;
  info_pub.publish(other_size);
  scaledWait(0.3).sleep();
  tracks = send(makeImage(view({0.5, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(tracks);
  EXPECT_GE(tracks->id.size(), 45u);
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << diagnostics.message();
  EXPECT_NE(diagnostics.message().find("camera_info is for 1280x720 images but the images are "
                                       "640x480: not used"),
            std::string::npos)
      << diagnostics.message();
  EXPECT_NE(diagnostics.message().find("binning_x/y or ROI"), std::string::npos);
  EXPECT_EQ(diagnostics.value("camera_info"), "for another image size: not used");
  EXPECT_GE(diagnostics.number("images with camera_info of another size (total)"), 1);
  EXPECT_FALSE(diagnostics.value("problem: camera_info").empty());

  sensor_msgs::CameraInfo right = other_size;  // the images' own size: used at once
  right.width = 640;
  right.height = 480;
  right.K = {525, 0, 320, 0, 525, 240, 0, 0, 1};
  info_pub.publish(right);
  scaledWait(0.3).sleep();
  ASSERT_TRUE(send(makeImage(view({1.0, 0}), "mono8", stamp_ += 0.1)));
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << diagnostics.message();
  EXPECT_EQ(diagnostics.value("camera_info"), "ok");
  EXPECT_EQ(diagnostics.value("problem: camera_info"), "");
  // An unusable one after it is ignored: the last usable camera_info stays in use (it is
  // latched for the later tests).
  info_pub.publish(zero);
  scaledWait(0.3).sleep();
  ASSERT_TRUE(send(makeImage(view({1.5, 0}), "mono8", stamp_ += 0.1)));
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.value("camera_info"), "ok");
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN) << diagnostics.message();
  EXPECT_EQ(diagnostics.message().rfind("camera_info unusable", 0), 0u) << diagnostics.message();
}

// A camera_info of another frame than the images' (another camera's, through a remap
// gone wrong) is used all the same, but counted and said.
TEST_F(TrackerNodeletTest, CameraInfoOfAnotherFrameIsCounted) {
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  ros::Publisher info_pub = nh_.advertise<sensor_msgs::CameraInfo>("camera_info", 1, true);
  ASSERT_TRUE(diagnostics.waitFresh());
  const long before = diagnostics.number("images with camera_info of another frame_id (total)");
  ASSERT_GE(before, 0);
  sensor_msgs::CameraInfo left;
  left.header.frame_id = "left_camera_optical";
  left.width = 640;
  left.height = 480;
  left.K = {525, 0, 320, 0, 525, 240, 0, 0, 1};
  info_pub.publish(left);
  scaledWait(0.3).sleep();
  for (int k = 0; k < 3; ++k)
    ASSERT_TRUE(send(makeImage(view({0.5 * k, 0}), "mono8", stamp_ += 0.1)));  // camera_optical
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("images with camera_info of another frame_id (total)") - before, 3);
  EXPECT_EQ(diagnostics.value("camera_info"), "ok");  // used all the same
  sensor_msgs::CameraInfo own = left;  // its own frame: no more counted
  own.header.frame_id = "camera_optical";
  info_pub.publish(own);
  scaledWait(0.3).sleep();
  ASSERT_TRUE(send(makeImage(view({1.5, 0}), "mono8", stamp_ += 0.1)));
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("images with camera_info of another frame_id (total)") - before, 3);
}

TEST_F(TrackerNodeletTest, DebugImageWhileSubscribed) {
  sensor_msgs::ImageConstPtr debug;
  ros::Subscriber sub = nh_.subscribe<sensor_msgs::Image>(
      "debug_image", 5, [&](const sensor_msgs::ImageConstPtr& m) { debug = m; });
  spinUntil([&] { return sub.getNumPublishers() > 0; }, 5.0);
  ASSERT_GT(sub.getNumPublishers(), 0u);
  scaledWait(0.3).sleep();  // let the nodelet see its new subscriber
  const double stamp = stamp_ += 0.1;
  ASSERT_TRUE(send(makeImage(view({0, 0}), "mono8", stamp)));
  spinUntil([&] { return debug != nullptr; }, 5.0);
  ASSERT_TRUE(debug);
  EXPECT_EQ(debug->encoding, "bgr8");
  EXPECT_EQ(debug->width, 640u);
  EXPECT_EQ(debug->height, 480u);
  EXPECT_DOUBLE_EQ(debug->header.stamp.toSec(), ros::Time(stamp).toSec());
  // Points are drawn in colour on a grey image: some pixels are not grey.
  const cv::Mat drawn = cv_bridge::toCvShare(debug)->image;
  int coloured = 0;
  for (int y = 0; y < drawn.rows; ++y)
    for (int x = 0; x < drawn.cols; ++x) {
      const cv::Vec3b p = drawn.at<cv::Vec3b>(y, x);
      coloured += (p[0] != p[1] || p[1] != p[2]);
    }
  EXPECT_GT(coloured, 500);
}

// Last: the target's corners stay tracked for the rest of the node's life.
// The target's corners join the tracks once it has been seen in confirm_frames (3)
// consecutive images: flagged from the third image on, new there, tracked after, and
// re-anchored to the target found again in each image (redetect_tracked): no drift.
TEST_F(TrackerNodeletTest, StartUpTargetCornersAreFlaggedAndTracked) {
  const IndoorScene scene = makeRoom(RoomParams());
  const CameraModel camera;
  const SceneRenderer renderer(scene, camera, RenderOptions());
  TrajectoryParams path;
  double worst = 0;
  for (int k = 0; k < 20; ++k) {
    const Pose pose = trajectoryPose(path, k / 30.0);
    auto tracks = send(makeImage(renderer.render(pose), "mono8", stamp_ += 1.0 / 30));
    ASSERT_TRUE(tracks);
    std::vector<cv::Point2d> flagged;
    for (size_t i = 0; i < tracks->id.size(); ++i) {
      if (!(tracks->flags[i] & Tracks::FLAG_TARGET_CORNER)) continue;
      flagged.emplace_back(tracks->u[i], tracks->v[i]);
      EXPECT_TRUE(tracks->flags[i] & (k == 2 ? Tracks::FLAG_NEW : Tracks::FLAG_TRACKED));
    }
    if (k < 2) {
      EXPECT_TRUE(flagged.empty()) << "image " << k << ": confirmed too early";
      continue;
    }
    ASSERT_EQ(flagged.size(), 4u) << "image " << k;
    for (int c = 0; c < 4; ++c) {
      const cv::Point2d truth = camera.project(pose.inverse().apply(scene.target.corners[c]));
      worst = std::max(worst, cv::norm(flagged[c] - truth));
      EXPECT_LT(cv::norm(flagged[c] - truth), 0.5) << "corner " << c << " image " << k;
    }
  }
  std::printf("target corners over 18 images: worst %.3f px from the truth\n", worst);
  // Measured: 0.105 px re-anchored; 0.281 px with target/redetect_tracked false (drift).
  EXPECT_LT(worst, 0.2);
  // A user sees that it works: "N of M images with its four corners tracked ...".
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  ASSERT_TRUE(diagnostics.waitFresh());
  const std::string moved = diagnostics.value("target: corners re-detected");
  ASSERT_FALSE(moved.empty());
  EXPECT_GE(std::stoi(moved), 15) << moved;  // of the 17 images after confirmation
}

// Issue 12, bad input: images without a target for longer than target_timeout_s (1 s in
// tracker_nodelet.test): diagnostics go WARN and say why, tracking goes on.
TEST_F(TrackerNodeletTest, NoTargetGoesWarnWithTheReason) {
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  // Back in time: the tracker starts over and searches for the target again.
  stamp_ -= 50;
  for (int k = 0; k < 16; ++k)
    ASSERT_TRUE(send(makeImage(view({0.5 * k, 0}), "mono8", stamp_ += 0.1))) << k;
  ASSERT_TRUE(diagnostics.waitFresh());
  // (The summary names the first of the causes: earlier tests mixed cameras.)
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(diagnostics.value("start-up target"), "waiting");
  EXPECT_EQ(diagnostics.value("target: overdue"), "True");
  EXPECT_FALSE(diagnostics.value("target: last rejection").empty());
  EXPECT_GT(std::stod(diagnostics.value("target: waiting (s)")), 1.0);
}

// Issue 15, case 1: secs = 4000000000 after 100 s (a driver with an uninitialised
// clock): ros::Duration threw in the image callback and the manager died.
TEST_F(TrackerNodeletTest, StampMoreThanTwoToThe31SecondsLaterIsAnswered) {
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  ASSERT_TRUE(send(makeImage(view({0, 0}), "mono8", stamp_ += 0.1)));
  auto far = makeImage(view({1, 0}), "mono8", 0);
  far->header.stamp = ros::Time(4000000000u, 0);
  auto tracks = send(far);
  ASSERT_TRUE(tracks) << "no answer to the image 2^31 s later (manager gone?)";
  EXPECT_EQ(tracks->header.stamp.sec, 4000000000u);
  EXPECT_TRUE(tracks->searched);  // a pause that long is a restart
  ASSERT_TRUE(send(makeImage(view({0, 0}), "mono8", stamp_ += 0.1))) << "manager gone";
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("exceptions caught (total)"), 0);
}

// Issue 15, case 6: textured images under 11 px on a side made cornerSubPix assert.
TEST_F(TrackerNodeletTest, TexturedImagesSmallerThanTheWindowsAreDropped) {
  for (const cv::Size size : {cv::Size(10, 10), cv::Size(640, 6), cv::Size(8, 40)}) {
    const cv::Mat small = view({0, 0})(cv::Rect(cv::Point(0, 200), size)).clone();
    EXPECT_FALSE(send(makeImage(small, "mono8", stamp_ += 0.1), 1.0)) << size;
  }
  auto after = send(makeImage(view({0, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(after) << "no answer after the small images (manager gone?)";
  EXPECT_EQ(after->id.size(), 50u);
}

// Issue 15, cases 5 and 8: min_distance_px -5 and reanchor_window_px 1000 made OpenCV
// assert on the first image; window_size_px 2001 took 8 s per image. The nodelet
// tracker_bad_params (tracker_nodelet.test) has them; the defaults are used instead.
TEST_F(TrackerNodeletTest, OutOfRangeParametersAreReplacedByDefaults) {
  ros::Publisher images = nh_.advertise<sensor_msgs::Image>("image_bad_params", 10);
  std::map<uint64_t, TracksConstPtr> answers;
  ros::Subscriber sub = nh_.subscribe<Tracks>(
      "tracks_bad_params", 10, [&](const TracksConstPtr& m) { answers[m->header.stamp.toNSec()] = m; });
  ASSERT_TRUE(spinUntil([&] { return images.getNumSubscribers() > 0; }, 20.0));
  double slowest = 0;
  for (int k = 0; k < 12; ++k) {  // the 11th image searches again (re-anchoring)
    auto msg = makeImage(view({0.5 * k, 0}), "mono8", stamp_ += 0.1);
    const ros::WallTime start = ros::WallTime::now();
    images.publish(msg);
    ASSERT_TRUE(spinUntil([&] { return answers.count(msg->header.stamp.toNSec()) > 0; }, 5.0))
        << "no tracks for image " << k << " (manager gone or stalled?)";
    slowest = std::max(slowest, (ros::WallTime::now() - start).toSec());
    EXPECT_GE(answers[msg->header.stamp.toNSec()]->id.size(), 45u);  // max_features "many": 50
  }
  std::printf("bad parameters: slowest answer %.0f ms\n", slowest * 1e3);
  // A user at the robot sees it in diagnostics too, not only in the log at start.
  DiagnosticsProbe diagnostics(nh_, "tracker_bad_params: tracking");
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN) << diagnostics.message();
  const std::string said = diagnostics.value("problem: configuration");
  EXPECT_EQ(said.rfind("WARN: 4 parameters refused, defaults used (see the log): ", 0), 0u) << said;
}

// Issue 15, case 15: two cameras alternating on one image topic are reported (WARN and
// a count in diagnostics) and each image is still answered.
TEST_F(TrackerNodeletTest, TwoCamerasOnOneTopicAreReported) {
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  ASSERT_TRUE(diagnostics.waitFresh());
  const long before = diagnostics.number("camera switches (total)");
  ASSERT_GE(before, 0);
  cv::Mat small;
  cv::resize(view({0, 0}), small, {320, 240}, 0, 0, cv::INTER_AREA);
  for (int k = 0; k < 6; ++k) {
    auto msg = makeImage(k % 2 ? small : view({0, 0}), "mono8", stamp_ += 0.05);
    msg->header.frame_id = k % 2 ? "right_camera" : "left_camera";
    ASSERT_TRUE(send(msg)) << k;
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_GE(diagnostics.number("camera switches (total)") - before, 5);
  // (The half-size images have no camera_info of their size: that is an ERROR of its own.)
  EXPECT_GE(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(diagnostics.value("problem: last 10 s, camera switch"), "WARN: image stream mixes cameras")
      << diagnostics.message();
}

// Issue 15, case 16: at 300 Hz the subscriber queue drops images; diagnostics count the
// images missing from the stream (by stamp gaps against the stream's period).
TEST_F(TrackerNodeletTest, ImagesDroppedUnderLoadAreCounted) {
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  ASSERT_TRUE(diagnostics.waitFresh());
  const long before = diagnostics.number("images missing from the stream (total)");
  ASSERT_GE(before, 0);
  stamp_ = 50;  // before the previous test's images: a fresh start of the stream
  const double period = 1.0 / 300;
  // A lead-in answered one by one fixes the stream's period for the gap counter: a
  // loaded machine answers so few burst images that none of them come in a row.
  for (int k = 0; k < 8; ++k)
    ASSERT_TRUE(send(makeImage(view({0, 0}), "mono8", stamp_ += period))) << "lead-in " << k;
  std::vector<sensor_msgs::ImagePtr> burst;
  for (int k = 0; k < 300; ++k) burst.push_back(makeImage(view({0.1 * k, 0}), "mono8", stamp_ += period));
  const size_t received_before = received_.size();
  // Published as fast as this node can: more than the tracker takes, so the subscriber
  // queue (5) drops images.
  for (const auto& msg : burst) {
    image_pub_.publish(msg);
    ros::spinOnce();
  }
  spinUntil([&] { return received_.count(burst.back()->header.stamp.toNSec()) > 0; }, 5.0);
  scaledWait(1.0).sleep();
  ros::spinOnce();
  const long received = static_cast<long>(received_.size() - received_before);
  // One more image, sent when the queue is empty, reveals the images dropped at the end.
  ASSERT_TRUE(send(makeImage(view({0, 0}), "mono8", stamp_ += period)));
  ASSERT_TRUE(diagnostics.waitFresh());
  const long missing = diagnostics.number("images missing from the stream (total)") - before;
  std::printf("300 Hz: %ld of 300 images answered, %ld counted missing\n", received, missing);
  ASSERT_LT(received, 300) << "nothing was dropped: the test does not load the tracker";
  // Every image not answered is counted missing. The counter's period is the second
  // smallest recent interval, so at most a few early gaps can be counted short.
  EXPECT_GE(missing, (300 - received) * 9 / 10);
  EXPECT_LE(missing, 300 - received);
  // And it is a WARN while recent (a hostile try saw 291 of 600 lost with the status OK).
  EXPECT_NE(diagnostics.value("problem: images missing").find("images missing in the last 10 s"),
            std::string::npos)
      << diagnostics.value("problem: images missing");
  // Stamps back and forth (two sources on one topic): tracking starts over each time.
  const double base = stamp_;
  for (int k = 0; k < 8; ++k)
    ASSERT_TRUE(send(makeImage(view({0, 0}), "mono8", base + (k % 2 ? 0.5 : 100.0) + 0.01 * k)))
        << k;
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.value("problem: time").find("time went backwards"), std::string::npos)
      << diagnostics.value("problem: time");
  stamp_ = base + 200;  // after these for the tests that follow
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_tracker_nodelet");
  ros::NodeHandle nh;
  readTimeoutScale();
  return RUN_ALL_TESTS();
}

// Issue 14: ~reset starts every track over (ids keep increasing, so no listener takes a
// new point for an old one), and the reset is counted in diagnostics.
TEST_F(TrackerNodeletTest, ResetStartsEveryTrackOver) {
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  stamp_ += 1000;  // after every earlier test's stamps
  TracksConstPtr before;
  for (int k = 0; k < 5; ++k) before = send(makeImage(view({1.0 * k, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(before);
  ASSERT_FALSE(before->id.empty());
  size_t tracked = 0;
  for (uint8_t f : before->flags) tracked += (f & Tracks::FLAG_TRACKED) != 0;
  EXPECT_GT(tracked, before->id.size() / 2);
  const uint64_t newest = *std::max_element(before->id.begin(), before->id.end());
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::call("/tracker/reset", reset));
  const TracksConstPtr after = send(makeImage(view({5.0, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(after);
  ASSERT_FALSE(after->id.empty());
  for (size_t i = 0; i < after->id.size(); ++i) {
    EXPECT_EQ(after->prev_index[i], -1);
    EXPECT_GT(after->id[i], newest);
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("resets (total)") -
                diagnostics.number("resets: time went backwards (total)"),
            1);
}

// Issue 14: images and no usable camera_info for more than 5 s: WARN, with the reason.
TEST_F(TrackerNodeletTest, ImagesWithoutCameraInfoAreAWarning) {
  ros::Publisher images = nh_.advertise<sensor_msgs::Image>("image_no_info", 10);
  std::map<uint64_t, TracksConstPtr> got;
  ros::Subscriber tracks = nh_.subscribe<Tracks>(
      "tracks_no_info", 10, [&](const TracksConstPtr& m) { got[m->header.stamp.toNSec()] = m; });
  ASSERT_TRUE(spinUntil([&] { return images.getNumSubscribers() > 0; }, 20.0));
  DiagnosticsProbe diagnostics(nh_, "tracker_no_info: tracking");
  const ros::WallTime start = ros::WallTime::now();
  double stamp = 10;
  while ((ros::WallTime::now() - start).toSec() < 6.5) {
    images.publish(makeImage(view({0, 0}), "mono8", stamp += 0.1));
    spinUntil([] { return false; }, 0.1);
  }
  EXPECT_GT(got.size(), 10u);  // tracking goes on in pixels
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(diagnostics.message(), "images but no usable camera_info");
  EXPECT_EQ(diagnostics.value("camera_info"), "none or unusable");
}

// The hostile new-user try: with lazy subscription the missing transport showed only
// when a listener came, as "exception in the connect callback: message dropped", then
// nothing. Now an ERROR that names the transport, and diagnostics say it until fixed.
TEST_F(TrackerNodeletTest, ALazySubscriptionThatFailsIsReported) {
  ros::param::set("/tracker_lazy_no_transport/image_transport", "no_such_transport");
  nodelet::NodeletLoad load;
  load.request.name = "/tracker_lazy_no_transport";
  load.request.type = "mono_plane_detection/TrackerNodelet";
  load.request.remap_source_args = {"tracks", "image"};
  load.request.remap_target_args = {"tracks_lazy_no_transport", "image_lazy_no_transport"};
  ASSERT_TRUE(ros::service::call("/manager/load_nodelet", load) && load.response.success);
  DiagnosticsProbe diagnostics(nh_, "tracker_lazy_no_transport: tracking");
  DiagnosticsProbe rate(nh_, "tracker_lazy_no_transport: input rate");
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::OK) << diagnostics.message();
  EXPECT_EQ(diagnostics.message(), "idle: nobody listens, nothing tracked (lazy)");
  // Nobody listens: no input is expected (it was WARN "no input yet" on an idle robot).
  ASSERT_TRUE(rate.waitFresh());
  EXPECT_EQ(rate.level(), diagnostic_msgs::DiagnosticStatus::OK) << rate.message();
  EXPECT_EQ(rate.message().rfind("idle", 0), 0u) << rate.message();
  {
    ros::Subscriber listener = nh_.subscribe<Tracks>(
        "/tracks_lazy_no_transport", 1,
        boost::function<void(const TracksConstPtr&)>([](const TracksConstPtr&) {}));
    spinUntil([&] { return listener.getNumPublishers() > 0; }, 10.0);
    ASSERT_TRUE(diagnostics.waitFresh());
    ASSERT_TRUE(diagnostics.waitFresh());
    EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR);
    EXPECT_NE(diagnostics.message().find("image_transport 'no_such_transport'"),
              std::string::npos)
        << diagnostics.message();
    EXPECT_EQ(diagnostics.number("exceptions caught (total)"), 0);
    spinUntil([] { return false; }, 5.5);  // (a window's grace for the first image)
    ASSERT_TRUE(rate.waitFresh());  // someone listens and nothing comes: WARN
    EXPECT_EQ(rate.level(), diagnostic_msgs::DiagnosticStatus::WARN) << rate.message();
  }
  nodelet::NodeletUnload unload;
  unload.request.name = "/tracker_lazy_no_transport";
  EXPECT_TRUE(ros::service::call("/manager/unload_nodelet", unload) && unload.response.success);
}

// Subscribed and no image (before the first one, and once the stream stopped): WARN "no
// images on <topic>", not OK "tracking".
TEST_F(TrackerNodeletTest, NoImagesIsAWarningNotTracking) {
  ros::param::set("/tracker_silent/detect_target", false);
  nodelet::NodeletLoad load;
  load.request.name = "/tracker_silent";
  load.request.type = "mono_plane_detection/TrackerNodelet";
  load.request.remap_source_args = {"tracks", "image", "camera_info"};
  load.request.remap_target_args = {"tracks_silent", "image_silent", "camera_info_silent"};
  ASSERT_TRUE(ros::service::call("/manager/load_nodelet", load) && load.response.success);
  ros::Publisher images = nh_.advertise<sensor_msgs::Image>("image_silent", 10);
  std::map<uint64_t, TracksConstPtr> got;
  ros::Subscriber tracks = nh_.subscribe<Tracks>(
      "tracks_silent", 10, [&](const TracksConstPtr& m) { got[m->header.stamp.toNSec()] = m; });
  ASSERT_TRUE(spinUntil([&] { return images.getNumSubscribers() > 0; }, 20.0));
  DiagnosticsProbe diagnostics(nh_, "tracker_silent: tracking");
  const ros::WallTime subscribed = ros::WallTime::now();
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  // A moment without images after the subscription is no problem (a driver's first image
  // takes a while): it was a WARN on every resubscription.
  if ((ros::WallTime::now() - subscribed).toSec() < 4) {
    EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::OK) << diagnostics.message();
    EXPECT_EQ(diagnostics.message(), "waiting for the first image on /image_silent");
  }
  spinUntil([&] { return (ros::WallTime::now() - subscribed).toSec() > 6; }, 10.0);
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN) << diagnostics.message();
  EXPECT_EQ(diagnostics.message().rfind("no images on /image_silent yet", 0), 0u)
      << diagnostics.message();
  double stamp = 10;
  for (int k = 0; k < 10; ++k) {
    images.publish(makeImage(view({0.5 * k, 0}), "mono8", stamp += 0.1));
    spinUntil([] { return false; }, 0.1);
  }
  EXPECT_GT(got.size(), 5u);
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.message(), "tracking");
  spinUntil([] { return false; }, 6.5);  // the stream stopped
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN);
  EXPECT_EQ(diagnostics.message().rfind("no images on /image_silent for ", 0), 0u)
      << diagnostics.message();
  nodelet::NodeletUnload unload;
  unload.request.name = "/tracker_silent";
  EXPECT_TRUE(ros::service::call("/manager/unload_nodelet", unload) && unload.response.success);
}

// A tracker whose start throws (an image_transport plugin that is not installed,
// subscribed at once with lazy: false) is refused by the manager, and the manager and
// its other nodelets go on. It used to take the whole manager down (segfault: its
// diagnostics timer and publishers were destroyed after the nodelet's callback queue).
TEST_F(TrackerNodeletTest, AFailedStartLeavesTheManagerRunning) {
  ros::param::set("/tracker_no_transport/image_transport", "no_such_transport");
  ros::param::set("/tracker_no_transport/lazy", false);
  nodelet::NodeletLoad load;
  load.request.name = "/tracker_no_transport";
  load.request.type = "mono_plane_detection/TrackerNodelet";
  // (nodelet's load service answers false when the nodelet is refused.)
  EXPECT_FALSE(ros::service::call("/manager/load_nodelet", load) && load.response.success);
  scaledWait(1.0).sleep();
  nodelet::NodeletList list;
  ASSERT_TRUE(ros::service::call("/manager/list", list)) << "the manager died";
  const auto& names = list.response.nodelets;
  EXPECT_NE(std::find(names.begin(), names.end(), "/tracker"), names.end());
  EXPECT_EQ(std::find(names.begin(), names.end(), "/tracker_no_transport"), names.end());
  // The tracker already in the manager still tracks.
  stamp_ += 2000;
  TracksConstPtr tracks;
  for (int k = 0; k < 3; ++k) tracks = send(makeImage(view({1.0 * k, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(tracks);
  EXPECT_FALSE(tracks->id.empty());
}

// dynamic_reconfigure (cfg/Tracker.cfg): max_features 20 leaves the 20 oldest points on the
// next image, tracked on with their ids; back to 40, the next search fills up to it. A NaN
// quality_level is refused: the value in use (0.02) is kept and reported, diagnostics name
// it.
TEST_F(TrackerNodeletTest, ZReconfigureChangesTheNextImages) {
  auto set = [&](const std::string& name, double value, bool integer) {
    dynamic_reconfigure::Reconfigure srv;
    if (integer) {
      dynamic_reconfigure::IntParameter p;
      p.name = name;
      p.value = static_cast<int>(value);
      srv.request.config.ints.push_back(p);
    } else {
      dynamic_reconfigure::DoubleParameter p;
      p.name = name;
      p.value = value;
      srv.request.config.doubles.push_back(p);
    }
    EXPECT_TRUE(ros::service::call("/tracker/set_parameters", srv));
    return srv.response.config;
  };
  stamp_ += 3000;  // after every earlier test's stamps
  TracksConstPtr before;
  double x = 0;
  for (int k = 0; k < 3; ++k) before = send(makeImage(view({x += 1.0, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(before);
  ASSERT_EQ(before->id.size(), 50u);  // config/tracker.yaml
  const std::set<uint64_t> earlier(before->id.begin(), before->id.end());

  set("max_features", 20, true);
  const TracksConstPtr fewer = send(makeImage(view({x += 1.0, 0}), "mono8", stamp_ += 0.1));
  ASSERT_TRUE(fewer);
  EXPECT_EQ(fewer->id.size(), 20u);
  for (size_t i = 0; i < fewer->id.size(); ++i) {
    EXPECT_TRUE(earlier.count(fewer->id[i])) << "id " << fewer->id[i];
    EXPECT_TRUE(fewer->flags[i] & Tracks::FLAG_TRACKED);
  }

  set("max_features", 40, true);
  size_t most = 0;
  for (int k = 0; k < 11; ++k) {
    const TracksConstPtr t = send(makeImage(view({x += 1.0, 0}), "mono8", stamp_ += 0.1));
    ASSERT_TRUE(t);
    most = std::max(most, t->id.size());
  }
  EXPECT_EQ(most, 40u);

  set("quality_level", 0.02, false);
  const auto answer = set("quality_level", std::numeric_limits<double>::quiet_NaN(), false);
  bool reported = false;
  for (const auto& d : answer.doubles)
    if (d.name == "quality_level") {
      reported = true;
      EXPECT_EQ(d.value, 0.02);  // the value in use, not the default 0.01
    }
  EXPECT_TRUE(reported);
  EXPECT_TRUE(send(makeImage(view({x += 1.0, 0}), "mono8", stamp_ += 0.1)));  // tracking goes on
  DiagnosticsProbe diagnostics(nh_, "tracker: tracking");
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.value("problem: configuration").find("reconfigure: quality_level = nan"),
            std::string::npos)
      << diagnostics.value("problem: configuration");
  EXPECT_NE(diagnostics.value("problem: configuration").find("keeping 0.02"), std::string::npos)
      << diagnostics.value("problem: configuration");
  EXPECT_EQ(diagnostics.number("reconfigurations (total)"), 4);  // (not the server's start)
  set("quality_level", 0.01, false);
  set("max_features", 50, true);
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.value("problem: configuration"), "");
}
