// Drives PlaneNodelet with Tracks of a known room and motion, and with bad input;
// checks planes, markers, map points, tf and the debug image.
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <dynamic_reconfigure/Reconfigure.h>
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <nodelet/NodeletLoad.h>
#include <nodelet/NodeletUnload.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

#include "mono_plane_detection/PlaneArray.h"
#include "mono_plane_detection/SaveMap.h"
#include "mono_plane_detection/Tracks.h"
#include "mono_plane_detection/geometry/plane_fit.h"
#include "mono_plane_detection/ros/map_frame.h"
#include "mono_plane_detection/ros/pose_msg.h"
#include "support/diagnostics_probe.h"
#include "support/synthetic_tracks.h"
#include "support/temp_path.h"
#include "support/test_timeouts.h"

using namespace mono_plane_detection;

namespace {

// Both ends linked: an answer published before our subscriber is connected is lost (seen
// once with both cores busy: the first image "not answered").
::testing::AssertionResult linked(const ros::Publisher& tracks, const ros::Subscriber& answers) {
  spinUntil([&] { return tracks.getNumSubscribers() > 0 && answers.getNumPublishers() > 0; }, 10.0);
  if (tracks.getNumSubscribers() == 0)
    return ::testing::AssertionFailure() << tracks.getTopic() << ": nobody listens";
  if (answers.getNumPublishers() == 0)
    return ::testing::AssertionFailure() << answers.getTopic() << ": nobody publishes";
  return ::testing::AssertionSuccess();
}

// One of the launch file's other plane nodelets (topics tracks_<name>, planes_<name>): its
// tracks publisher and its answers by stamp (ns). Not copyable: the subscription holds it.
struct OtherNodelet {
  OtherNodelet(ros::NodeHandle& nh, const std::string& name, uint32_t tracks_queue,
               uint32_t planes_queue)
      : tracks(nh.advertise<Tracks>("tracks_" + name, tracks_queue)),
        planes(nh.subscribe<PlaneArray>(
            "planes_" + name, planes_queue,
            [this](const PlaneArrayConstPtr& m) { answers[m->header.stamp.toNSec()] = m; })),
        diagnostics(nh, "plane_detector_" + name + ": planes") {}
  OtherNodelet(const OtherNodelet&) = delete;
  OtherNodelet& operator=(const OtherNodelet&) = delete;

  std::map<uint64_t, PlaneArrayConstPtr> answers;
  ros::Publisher tracks;
  ros::Subscriber planes;
  DiagnosticsProbe diagnostics;  // its task's status
};

TracksPtr toTracks(const TrackFrame& f) {
  TracksPtr msg(new Tracks);
  msg->header.stamp = ros::Time(f.stamp);
  msg->header.frame_id = "camera_optical";
  msg->width = static_cast<uint32_t>(f.size.width);
  msg->height = static_cast<uint32_t>(f.size.height);
  for (size_t i = 0; i < f.ids.size(); ++i) {
    msg->id.push_back(f.ids[i]);
    msg->u.push_back(static_cast<float>(f.pixels[i].x));
    msg->v.push_back(static_cast<float>(f.pixels[i].y));
    msg->prev_index.push_back(-1);
    msg->flags.push_back(Tracks::FLAG_TRACKED |
                         (f.target_corner[i] ? Tracks::FLAG_TARGET_CORNER : 0));
    msg->age.push_back(0);
  }
  return msg;
}

sensor_msgs::CameraInfo cameraInfo(const CameraModel& camera) {
  sensor_msgs::CameraInfo info;
  info.header.frame_id = "camera_optical";
  info.width = static_cast<uint32_t>(camera.size.width);
  info.height = static_cast<uint32_t>(camera.size.height);
  info.distortion_model = "plumb_bob";
  info.D = {camera.k1, camera.k2, 0, 0, 0};
  const cv::Matx33d K = camera.K();
  for (int i = 0; i < 9; ++i) info.K[i] = K.val[i];
  return info;
}

class PlaneNodeletTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { world_ = new SyntheticTracks("wheeled"); }
  static void TearDownTestSuite() { delete world_; }

  void SetUp() override {
    tracks_pub_ = nh_.advertise<Tracks>("tracks", 20);
    info_pub_ = nh_.advertise<sensor_msgs::CameraInfo>("camera_info", 2, true);
    image_pub_ = nh_.advertise<sensor_msgs::Image>("image", 20);
    planes_sub_ = nh_.subscribe("planes", 50, &PlaneNodeletTest::onPlanes, this);
    image_planes_sub_ = nh_.subscribe("image_planes", 50, &PlaneNodeletTest::onImagePlanes, this);
    no_info_sub_ = nh_.subscribe("planes_no_info", 50, &PlaneNodeletTest::onNoInfo, this);
    // Every topic is a connection of its own: an answer published before its subscriber
    // is linked is lost (A_ missed its image_planes once in CI).
    spinUntil(
        [&] {
          return tracks_pub_.getNumSubscribers() > 0 && planes_sub_.getNumPublishers() > 0 &&
                 image_planes_sub_.getNumPublishers() > 0 && no_info_sub_.getNumPublishers() > 0;
        },
        20.0);
    ASSERT_GT(tracks_pub_.getNumSubscribers(), 0u) << "plane nodelets never subscribed";
  }

  void onPlanes(const PlaneArrayConstPtr& msg) { planes_[msg->header.stamp.toNSec()] = msg; }
  void onImagePlanes(const PlaneArrayConstPtr& msg) {
    image_planes_[msg->header.stamp.toNSec()] = msg;
  }
  void onNoInfo(const PlaneArrayConstPtr& msg) { no_info_[msg->header.stamp.toNSec()] = msg; }

  template <typename T>
  T waitFor(const std::map<uint64_t, T>& store, uint64_t key, double timeout = 10.0) {
    if (!spinUntil([&] { return store.count(key) > 0; }, timeout)) return nullptr;
    return store.at(key);
  }

  // Publishes and waits for the planes of this stamp; null when none came.
  PlaneArrayConstPtr send(const TracksPtr& msg, double timeout = 10.0) {
    tracks_pub_.publish(msg);
    return waitFor(planes_, msg->header.stamp.toNSec(), timeout);
  }

  // The room from t0 for `frames` images at 30 Hz, stamps shifted by `offset`.
  PlaneArrayConstPtr drive(double t0, int frames, double offset) {
    PlaneArrayConstPtr last;
    for (int k = 0; k < frames; ++k) {
      TrackFrame f = world_->frame(t0 + k / 30.0);
      f.stamp += offset;
      last = send(toTracks(f));
      if (!last) return nullptr;
    }
    return last;
  }

  static SyntheticTracks* world_;
  ros::NodeHandle nh_;
  ros::Publisher tracks_pub_, info_pub_, image_pub_;
  ros::Subscriber planes_sub_, image_planes_sub_, no_info_sub_;
  std::map<uint64_t, PlaneArrayConstPtr> planes_, image_planes_, no_info_;
  visualization_msgs::MarkerArrayConstPtr markers_;
  sensor_msgs::PointCloud2ConstPtr cloud_;
};

SyntheticTracks* PlaneNodeletTest::world_ = nullptr;

// Runs first: the nodelet has no camera_info yet. One frame per topic: the map's planes
// (none yet) in the map frame, this image's planes in the camera's.
TEST_F(PlaneNodeletTest, A_ImageSpacePlanesUntilCameraInfo) {
  const PlaneArrayConstPtr map = drive(0, 10, 0);
  ASSERT_TRUE(map);
  EXPECT_FALSE(map->metric);
  EXPECT_EQ(map->header.frame_id, "plane_map");
  EXPECT_TRUE(map->planes.empty());
  const PlaneArrayConstPtr last = waitFor(image_planes_, map->header.stamp.toNSec());
  ASSERT_TRUE(last);
  EXPECT_EQ(last->header.frame_id, "camera_optical");
  EXPECT_FALSE(last->metric);
  EXPECT_EQ(last->status, "no camera intrinsics: image-space planes only");
  ASSERT_FALSE(last->planes.empty());
  EXPECT_FALSE(last->planes[0].metric);
  EXPECT_TRUE(last->planes[0].observed);
  EXPECT_GE(last->planes[0].inlier_ids.size(), 8u);
  EXPECT_NE(last->planes[0].homography[8], 0.0);
  EXPECT_GT(last->reference_stamp, 0);
}

TEST_F(PlaneNodeletTest, B_ZeroIntrinsicsAreRejected) {
  sensor_msgs::CameraInfo zero = cameraInfo(world_->camera);
  zero.K.fill(0.0);
  info_pub_.publish(zero);
  scaledWait(0.5).sleep();
  const PlaneArrayConstPtr last = drive(0, 3, 100);  // 100 s later: a pause, not a problem
  ASSERT_TRUE(last);
  EXPECT_FALSE(last->metric);
  EXPECT_EQ(last->status, "no camera intrinsics: image-space planes only");
  sensor_msgs::CameraInfo nan = cameraInfo(world_->camera);
  nan.K[2] = std::numeric_limits<double>::quiet_NaN();
  info_pub_.publish(nan);
  scaledWait(0.5).sleep();
  const PlaneArrayConstPtr after_nan = drive(3 / 30.0, 3, 100);
  ASSERT_TRUE(after_nan);
  EXPECT_EQ(after_nan->status, "no camera intrinsics: image-space planes only");
}

TEST_F(PlaneNodeletTest, C_MetricPlanesOfTheRoom) {
  info_pub_.publish(cameraInfo(world_->camera));
  scaledWait(0.5).sleep();
  ros::Subscriber markers = nh_.subscribe<visualization_msgs::MarkerArray>(
      "plane_markers", 10,
      [this](const visualization_msgs::MarkerArrayConstPtr& m) { markers_ = m; });
  ros::Subscriber cloud = nh_.subscribe<sensor_msgs::PointCloud2>(
      "map_points", 10, [this](const sensor_msgs::PointCloud2ConstPtr& c) { cloud_ = c; });
  geometry_msgs::PoseStampedConstPtr pose;
  ros::Subscriber pose_sub = nh_.subscribe<geometry_msgs::PoseStamped>(
      "camera_pose", 10, [&](const geometry_msgs::PoseStampedConstPtr& m) { pose = m; });
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  const PlaneArrayConstPtr last = drive(0, 240, 200);
  ASSERT_TRUE(last);
  EXPECT_TRUE(last->metric);
  EXPECT_EQ(last->header.frame_id, "plane_map");
  EXPECT_EQ(last->status.rfind("tracking", 0), 0u) << last->status;
  {
    // The sheet upright on the wall, the camera upright: the map's up holds the planes.
    DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
    ASSERT_TRUE(diagnostics.waitFresh());
    EXPECT_EQ(diagnostics.value("map up (map/up_sigma_deg)"), "held to it (0.2 deg)");
  }
  // REP 103, z up: the front wall (the target's: x = 0, normal towards the camera, -x)
  // and the floor (0.8 m below the target: z = -0.8, so d = 0.8 in a x + b y + c z + d = 0).
  bool wall = false, floor = false;
  for (const auto& p : last->planes) {
    if (!p.metric || !p.confirmed) continue;
    const cv::Vec3d n(p.normal.x, p.normal.y, p.normal.z);
    const bool is_wall = normalAngleDeg(n, {-1, 0, 0}) < 5 && std::abs(p.d) < 0.1;
    const bool is_floor = normalAngleDeg(n, {0, 0, 1}) < 5 && std::abs(p.d - 0.8) < 0.1;
    if (is_wall) {
      EXPECT_EQ(p.label, PlaneEstimate::LABEL_WALL);
    }
    if (is_floor) {
      EXPECT_EQ(p.label, PlaneEstimate::LABEL_FLOOR);
    }
    wall |= is_wall;
    floor |= is_floor;
    EXPECT_GE(p.polygon.size(), 3u);
    EXPECT_GT(p.confidence, 0.0);
    for (const auto& v : p.polygon)  // the polygon lies on its plane
      EXPECT_NEAR(n.dot(cv::Vec3d(v.x, v.y, v.z)) + p.d, 0.0, 0.15);
  }
  EXPECT_TRUE(wall);
  EXPECT_TRUE(floor);
  if (!wall || !floor)
    for (const auto& p : last->planes)
      std::printf("plane %d: n (%.2f %.2f %.2f) d %.2f, %u obs\n", p.id, p.normal.x, p.normal.y,
                  p.normal.z, p.d, p.observations);
  // The camera pose in the message and on its own topic against the truth (z up).
  const Pose truth = rosMapFromTarget() * world_->truthMapFromCamera(239 / 30.0);
  EXPECT_NEAR(last->camera_pose.position.x, truth.t[0], 0.1);
  EXPECT_NEAR(last->camera_pose.position.y, truth.t[1], 0.1);
  EXPECT_NEAR(last->camera_pose.position.z, truth.t[2], 0.1);
  spinUntil([&] { return pose && pose->header.stamp == last->header.stamp; }, 5.0);
  ASSERT_TRUE(pose);
  EXPECT_EQ(pose->header.frame_id, "plane_map");
  EXPECT_NEAR(pose->pose.position.z, truth.t[2], 0.1);
  // Markers, map points and tf were published.
  const ros::WallTime deadline = ros::WallTime::now() + scaledWait(3.0);
  while ((!markers_ || !cloud_) && ros::WallTime::now() < deadline) {
    drive(240 / 30.0, 1, 200);
    ros::spinOnce();
  }
  ASSERT_TRUE(markers_);
  ASSERT_TRUE(cloud_);
  EXPECT_GT(cloud_->width, 50u);
  int polygons = 0;
  for (const auto& m : markers_->markers)
    polygons += m.ns == "planes" && m.action == visualization_msgs::Marker::ADD;
  EXPECT_GE(polygons, 2);
  // Without odometry the estimate is a frame of its own, never the camera's (a URDF
  // gives that one its parent).
  EXPECT_TRUE(buffer.canTransform("plane_map", "camera_optical_estimate", ros::Time(0),
                                  ros::Duration(2.0 * timeoutScale())));
  std::string parent;
  EXPECT_FALSE(buffer._getParent("camera_optical", ros::Time(0), parent)) << parent;
}

TEST_F(PlaneNodeletTest, D_BadTracksAreDroppedAndTheMapSurvives) {
  TrackFrame good = world_->frame(241 / 30.0);
  good.stamp += 200;
  auto bad = [&](auto change) {
    TracksPtr msg = toTracks(good);
    msg->header.stamp += ros::Duration(0.001);  // a stamp of its own
    change(*msg);
    EXPECT_FALSE(send(msg, 1.0)) << "a malformed message got an answer";
  };
  bad([](Tracks& m) { m.u.pop_back(); });
  bad([](Tracks& m) { m.flags.clear(); });
  bad([](Tracks& m) { m.v[3] = std::numeric_limits<float>::quiet_NaN(); });
  bad([](Tracks& m) { m.u[2] = std::numeric_limits<float>::infinity(); });
  bad([](Tracks& m) { m.id[1] = m.id[0]; });
  bad([](Tracks& m) { m.u[0] = 5000; });
  bad([](Tracks& m) { m.width = 0; });
  // Still alive, the map intact.
  const PlaneArrayConstPtr after = send(toTracks(good));
  ASSERT_TRUE(after);
  EXPECT_TRUE(after->metric);
  EXPECT_GE(after->planes.size(), 2u);
}

TEST_F(PlaneNodeletTest, E_FewOrVeryManyPointsAreAnswered) {
  double stamp = 1000 + 200 + 242 / 30.0;
  for (int n = 0; n <= 4; ++n) {
    TrackFrame f;
    f.stamp = stamp += 0.033;
    f.size = world_->camera.size;
    for (int i = 0; i < n; ++i) {
      f.ids.push_back(900000 + i);
      f.pixels.emplace_back(100 + 50 * i, 200);
      f.target_corner.push_back(false);
    }
    const PlaneArrayConstPtr r = send(toTracks(f));
    ASSERT_TRUE(r) << n << " points";
    for (const auto& p : r->planes) EXPECT_FALSE(p.observed);  // the map's, if it has any
    // Five points make the smallest group: fewer have no plane in the image.
    const PlaneArrayConstPtr image = waitFor(image_planes_, r->header.stamp.toNSec());
    ASSERT_TRUE(image) << n << " points";
    EXPECT_TRUE(image->planes.empty()) << n << " points";
  }
  // 10 000 points: groups are capped, so the answer comes in bounded time.
  TrackFrame many;
  many.size = world_->camera.size;
  cv::RNG rng(3);
  for (int i = 0; i < 10000; ++i) {
    many.ids.push_back(2000000 + i);
    many.pixels.emplace_back(rng.uniform(0.0, 639.0), rng.uniform(0.0, 479.0));
    many.target_corner.push_back(false);
  }
  // Enough images for a reference with parallax: half the points move right, half left,
  // 1 px per image (one shift for all would be a rotation: no planes, issue 18).
  double slowest = 0;
  size_t observed = 0;
  for (int k = 0; k < 8; ++k) {
    many.stamp = stamp += 0.033;
    for (size_t i = 0; i < many.pixels.size(); ++i)
      many.pixels[i].x = std::min(639.0, std::max(0.0, many.pixels[i].x + (i % 2 ? 1.0 : -1.0)));
    const ros::WallTime start = ros::WallTime::now();
    const PlaneArrayConstPtr r = send(toTracks(many), 60.0);
    ASSERT_TRUE(r);
    slowest = std::max(slowest, (ros::WallTime::now() - start).toSec());
    const PlaneArrayConstPtr image = waitFor(image_planes_, r->header.stamp.toNSec());
    ASSERT_TRUE(image);
    for (const auto& p : image->planes) observed += p.observed;
  }
  EXPECT_GT(observed, 0u);  // two shifts, two homographies: it was really searched
  std::printf("10000 points: slowest answer %.0f ms\n", slowest * 1e3);
}

TEST_F(PlaneNodeletTest, F_TimeGoingBackwardsStartsTheMapOver) {
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  ASSERT_TRUE(diagnostics.waitFresh());
  const long resets = diagnostics.number("resets (total)");
  const PlaneArrayConstPtr r = drive(0, 3, 0);  // stamps back at 1000 s: a bag loop
  ASSERT_TRUE(r);
  // Counted with the resets (it counted ~reset calls only).
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("resets: time went backwards (total)"), 1);
  EXPECT_EQ(diagnostics.number("resets (total)"), resets + 1);
  EXPECT_FALSE(r->metric);  // the start needs the target and motion again
  EXPECT_TRUE(r->planes.empty() || !r->planes[0].metric);
  const PlaneArrayConstPtr later = drive(3 / 30.0, 60, 0);
  ASSERT_TRUE(later);
  EXPECT_TRUE(later->metric);
}

// Issue 12: the tracker says it looks for a US letter sheet, this nodelet has A4 (two
// nodelets configured apart): the flagged corners would fix a wrong scale, so they are
// not used and the diagnostics say why; the same target starts the map as in F.
TEST_F(PlaneNodeletTest, F2_ATargetOfAnotherSizeDoesNotStartTheMap) {
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  const auto run = [&](float width_m, float height_m) {
    PlaneArrayConstPtr last;
    for (int k = 0; k < 63; ++k) {  // stamps back at 1000 s: the map starts over first
      TracksPtr msg = toTracks(world_->frame(k / 30.0));
      msg->target_type = "sheet";
      msg->target_width_m = width_m;
      msg->target_height_m = height_m;
      last = send(msg);
      if (!last) break;
    }
    return last;
  };
  const PlaneArrayConstPtr letter = run(0.2794f, 0.2159f);
  ASSERT_TRUE(letter);
  EXPECT_FALSE(letter->metric);
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR);
  EXPECT_NE(diagnostics.message().find("start-up target"), std::string::npos)
      << diagnostics.message();
  EXPECT_NE(diagnostics.message().find("0.2794 x 0.2159"), std::string::npos)
      << diagnostics.message();
  planes_.clear();  // the same stamps again: wait for the new answers
  const PlaneArrayConstPtr a4 = run(0.297f, 0.21f);
  ASSERT_TRUE(a4);
  EXPECT_TRUE(a4->metric);
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR);
}

TEST_F(PlaneNodeletTest, G_DebugImageWhileWatched) {
  sensor_msgs::ImageConstPtr drawn;
  ros::Subscriber debug = nh_.subscribe<sensor_msgs::Image>(
      "debug_image", 2, [&](const sensor_msgs::ImageConstPtr& m) { drawn = m; });
  spinUntil([&] { return image_pub_.getNumSubscribers() > 0; }, 10.0);
  ASSERT_GT(image_pub_.getNumSubscribers(), 0u) << "the nodelet did not subscribe to the image";
  for (int k = 0; k < 20 && !drawn; ++k) {
    TrackFrame f = world_->frame(2.0 + k / 30.0);
    const cv::Mat grey(f.size, CV_8UC1, cv::Scalar(100));
    std_msgs::Header header;
    header.stamp = ros::Time(f.stamp);
    header.frame_id = "camera_optical";
    image_pub_.publish(cv_bridge::CvImage(header, "mono8", grey).toImageMsg());
    ros::WallDuration(0.05).sleep();
    send(toTracks(f));
    ros::WallDuration(0.05).sleep();
    ros::spinOnce();
  }
  ASSERT_TRUE(drawn);
  EXPECT_EQ(drawn->encoding, "bgr8");
  EXPECT_EQ(drawn->width, 640u);
  debug.shutdown();
}

TEST_F(PlaneNodeletTest, H_WithoutCameraInfoThePlanesStayInTheImage) {
  // Eight images on a time line after G's, with the target in view: the nodelet without
  // camera_info finds planes in the image (frame_gap, 5, images apart) but maps none and
  // places no camera, however long it runs (its `planes` topic is the map's).
  ASSERT_TRUE(drive(2.0, 8, 400));
  TrackFrame last = world_->frame(2.0 + 7 / 30.0);
  last.stamp += 400;
  const PlaneArrayConstPtr r = waitFor(no_info_, ros::Time(last.stamp).toNSec());
  ASSERT_TRUE(r);
  EXPECT_FALSE(r->metric);
  EXPECT_EQ(r->status, "no camera intrinsics: image-space planes only");
  EXPECT_TRUE(r->planes.empty());
  // Its diagnostics say so, once camera_info's grace (5 s of tracks) is over (the tests
  // before ran longer); the first tracks of a bag often come before camera_info.
  DiagnosticsProbe diagnostics(nh_, "plane_detector_no_info: planes");
  const std::string warn = "WARN: tracks arrive but no usable camera_info";
  // (Alone this test starts within the grace: wait for it to end, up to 8 s.)
  for (int k = 0; k < 8 && diagnostics.value("problem: camera_info") != warn; ++k)
    ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.value("problem: camera_info"), warn);
}

// The robot's odometry: tf odom -> camera_optical for every image (the true pose seen
// from an odometry origin 1 m aside and turned). The nodelet must take the pose from it
// once the start has fixed map -> odom, and publish map -> odom.
TEST_F(PlaneNodeletTest, I_OdometryFromTf) {
  OtherNodelet other(nh_, "odom", 20, 50);
  ros::Publisher& tracks = other.tracks;
  std::map<uint64_t, PlaneArrayConstPtr>& answers = other.answers;
  tf2_ros::TransformBroadcaster broadcaster;
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  ASSERT_TRUE(linked(other.tracks, other.planes));
  std::vector<std::string> logged;  // INFO lines on /rosout (only this instance gets tracks)
  ros::Subscriber rosout =
      nh_.subscribe<rosgraph_msgs::Log>("/rosout", 200, [&](const rosgraph_msgs::LogConstPtr& m) {
        if (m->level == rosgraph_msgs::Log::INFO) logged.push_back(m->msg);
      });
  // The manager's publisher besides this node's own.
  ASSERT_TRUE(spinUntil([&] { return rosout.getNumPublishers() >= 2; }, 10.0));
  ros::WallDuration(0.3).sleep();
  const Pose odom_from_map{cameraOrientation(0.3, 0, 0), {1, 0, 0}};
  PlaneArrayConstPtr last;
  for (int k = 0; k < 90; ++k) {
    const double t = k / 30.0;
    TrackFrame f = world_->frame(t);
    f.stamp += 500;  // its own time line
    const Pose odom = odom_from_map * world_->truthMapFromCamera(t);
    geometry_msgs::TransformStamped tf;
    tf.header.stamp = ros::Time(f.stamp);
    tf.header.frame_id = "odom";
    tf.child_frame_id = "camera_optical";
    tf.transform = toTransformMsg(odom);
    broadcaster.sendTransform(tf);
    ros::WallDuration(0.02).sleep();  // let tf arrive before the tracks
    tracks.publish(toTracks(f));
    last = waitFor(answers, ros::Time(f.stamp).toNSec());
    ASSERT_TRUE(last) << "image " << k;
  }
  EXPECT_EQ(last->status, "tracking (odometry)");
  // Every change of the status is logged once (hostile try: "tracking (target)" ->
  // "tracking (odometry)" went unsaid; the remark after ';' is not a change).
  spinUntil([] { return false; }, 0.5);
  std::string previous;
  int changes = 0;
  for (const auto& [stamp, answer] : answers) {
    if (stamp < ros::Time(world_->frame(0).stamp + 500).toNSec()) continue;  // this test's
    const std::string key = answer->status.substr(0, answer->status.find(';'));
    if (key == previous) continue;
    previous = key;
    ++changes;
    EXPECT_NE(std::find(logged.begin(), logged.end(), answer->status), logged.end())
        << "not logged: " << answer->status;
  }
  EXPECT_GE(changes, 2);
  const Pose truth = world_->truthMapFromCamera(89 / 30.0);
  const Pose in_ros_map = targetFromRosMap(fromPoseMsg(last->camera_pose));
  EXPECT_NEAR(in_ros_map.t[0], truth.t[0], 0.1);
  EXPECT_NEAR(in_ros_map.t[1], truth.t[1], 0.1);
  EXPECT_NEAR(in_ros_map.t[2], truth.t[2], 0.1);
  ASSERT_TRUE(buffer.canTransform("map_odom_test", "camera_optical", ros::Time(0),
                                  ros::Duration(2.0 * timeoutScale())));
  // map -> odom (ours) then odom -> camera (the robot's): the camera where it truly is.
  const Pose through_tf = fromTransformMsg(
      buffer.lookupTransform("map_odom_test", "camera_optical", ros::Time(0)).transform);
  const Pose ros_truth = rosMapFromTarget() * truth;
  EXPECT_LT(cv::norm(through_tf.t - ros_truth.t), 0.1);
  std::string parent;
  ASSERT_TRUE(buffer._getParent("odom", ros::Time(0), parent));
  EXPECT_EQ(parent, "map_odom_test");
}

// metric_source odometry without a target (issue 12 part 3): metric from the first
// image, PlaneArray.metric_source says so; a tf that stops leaves the pose to vision
// (no jump) and the diagnostics WARN; the odometry takes over again when it returns.
TEST_F(PlaneNodeletTest, I2_OdometrySourceWithoutTargetAndATfThatStops) {
  OtherNodelet other(nh_, "odom_source", 20, 50);
  ros::Publisher& tracks = other.tracks;
  std::map<uint64_t, PlaneArrayConstPtr>& answers = other.answers;
  DiagnosticsProbe& diagnostics = other.diagnostics;
  tf2_ros::TransformBroadcaster broadcaster;
  ASSERT_TRUE(linked(other.tracks, other.planes));
  std::optional<cv::Vec3d> previous;
  double worst_step = 0;
  int missed_after_pause = 0;
  {  // a new broadcaster: let the nodelet's tf listener connect before the first image
    geometry_msgs::TransformStamped tf;
    tf.header.stamp = ros::Time(world_->frame(0).stamp + 3500 - 1);
    tf.header.frame_id = "odom_source";
    tf.child_frame_id = "camera_optical_source";
    tf.transform = toTransformMsg(rosMapFromTarget() * world_->truthMapFromCamera(0));
    for (int i = 0; i < 10; ++i) {
      broadcaster.sendTransform(tf);
      ros::WallDuration(0.1 * timeoutScale()).sleep();
    }
  }
  for (int k = 0; k < 120; ++k) {
    const double t = k / 30.0;
    TrackFrame f = world_->frame(t);
    for (size_t i = 0; i < f.ids.size(); ++i) f.target_corner[i] = false;  // no target
    f.stamp += 3500;                                                       // its own time line
    TracksPtr msg = toTracks(f);
    msg->header.frame_id = "camera_optical_source";
    tracks.publish(msg);
    // The odometry lags the camera (tf 20 ms after the tracks, as on many robots): the
    // nodelet waits for it. After the pause it must wait for it again (it did not: one
    // wait in vain left every later image without odometry).
    const bool tf_stopped = k >= 70 && k < 100;
    if (!tf_stopped) {
      geometry_msgs::TransformStamped tf;
      tf.header.stamp = ros::Time(f.stamp);
      tf.header.frame_id = "odom_source";
      tf.child_frame_id = "camera_optical_source";  // a camera of its own: one parent each
      tf.transform = toTransformMsg(rosMapFromTarget() * world_->truthMapFromCamera(t));
      ros::WallDuration(0.02).sleep();
      broadcaster.sendTransform(tf);
    }
    const PlaneArrayConstPtr last = waitFor(answers, ros::Time(f.stamp).toNSec());
    ASSERT_TRUE(last) << "image " << k;
    ASSERT_TRUE(last->metric) << "image " << k << ": " << last->status;
    EXPECT_EQ(last->metric_source, "odometry");
    // The map is the odometry frame: the camera where the odometry says.
    const cv::Vec3d at = targetFromRosMap(fromPoseMsg(last->camera_pose)).t;
    EXPECT_LT(cv::norm(at - world_->truthMapFromCamera(t).t), 0.05) << "image " << k;
    if (previous) worst_step = std::max(worst_step, cv::norm(at - *previous));
    previous = at;
    if (k == 69) {
      EXPECT_EQ(last->status, "tracking (odometry)");
    }
    if (k == 99) {
      EXPECT_EQ(last->status, "tracking (landmarks)");
      ASSERT_TRUE(diagnostics.waitFresh());
      EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN);
      EXPECT_NE(diagnostics.message().find("odometry (odom_source) stopped"), std::string::npos)
          << diagnostics.message();
      EXPECT_EQ(diagnostics.value("metric source"), "odometry");
      // The odometry's z is up and the camera upright: the map's up holds the planes.
      EXPECT_EQ(diagnostics.value("map up (map/up_sigma_deg)"), "held to it (0.2 deg)");
    }
    // The first image after the pause goes without (nobody waits yet); then every one
    // has it, but for a wait a loaded machine (helgrind) may miss now and then.
    if (k >= 102 && last->status.rfind("tracking (odometry)", 0) != 0) ++missed_after_pause;
  }
  EXPECT_LE(missed_after_pause, 2) << "of the images after the odometry came back";
  EXPECT_LT(worst_step, 0.05);  // 0.01 m per image
  // The true odometry agrees with the images (odometry_check.h).
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.value("problem: odometry").find("does not move the camera"),
            std::string::npos)
      << diagnostics.value("problem: odometry");
}

// Odometry that turns the camera but never moves it (odom_frame:=base_link on a humanoid,
// whose head turns on joints: a hostile try got an empty map and every status OK): an
// ERROR that names the two configuration errors that do this.
TEST_F(PlaneNodeletTest, I2b_OdometryThatDoesNotMoveTheCameraIsAnError) {
  OtherNodelet other(nh_, "odom_source", 20, 50);
  tf2_ros::TransformBroadcaster broadcaster;
  ASSERT_TRUE(linked(other.tracks, other.planes));
  ros::WallDuration(0.5).sleep();  // the nodelet's tf listener hears the new broadcaster
  const Pose start = rosMapFromTarget() * world_->truthMapFromCamera(0);
  for (int k = 0; k < 200; ++k) {  // (checks at one image in 5 with two planes in view)
    const double t = k / 30.0;
    TrackFrame f = world_->frame(t);
    for (size_t i = 0; i < f.ids.size(); ++i) f.target_corner[i] = false;
    f.stamp += 3510;  // after I2's time line
    geometry_msgs::TransformStamped tf;
    tf.header.stamp = ros::Time(f.stamp);
    tf.header.frame_id = "odom_source";
    tf.child_frame_id = "camera_optical_source";
    Pose turned_only = rosMapFromTarget() * world_->truthMapFromCamera(t);
    turned_only.t = start.t;
    tf.transform = toTransformMsg(turned_only);
    broadcaster.sendTransform(tf);
    ros::WallDuration(0.02).sleep();
    TracksPtr msg = toTracks(f);
    msg->header.frame_id = "camera_optical_source";
    other.tracks.publish(msg);
    ASSERT_TRUE(waitFor(other.answers, msg->header.stamp.toNSec())) << k;
  }
  ASSERT_TRUE(other.diagnostics.waitFresh());
  ASSERT_TRUE(other.diagnostics.waitFresh());
  EXPECT_EQ(other.diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR)
      << other.diagnostics.message();
  const std::string said = other.diagnostics.value("problem: odometry");
  EXPECT_NE(said.find("ERROR: the odometry (tf odom_source -> camera) does not move the camera "
                      "as its images show: its translation 1"),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("is odom_frame the odometry's fixed frame"), std::string::npos) << said;
}

// Odometry that always lags more than odom_wait_s (0.4 s against 0.25 s): after one wait
// in vain the tracks go on without waiting (before: the wait was armed again each time
// tf's odometry passed the stamp that waited, and output stalled 0.25 s every 0.4 s).
TEST_F(PlaneNodeletTest, I3_OdometryLaggingBeyondTheWaitIsNotWaitedForAtEveryImage) {
  OtherNodelet other(nh_, "odom_late", 100, 200);
  ros::Publisher& tracks = other.tracks;
  std::map<uint64_t, PlaneArrayConstPtr>& answers = other.answers;
  DiagnosticsProbe& diagnostics = other.diagnostics;
  tf2_ros::TransformBroadcaster broadcaster;
  ASSERT_TRUE(linked(other.tracks, other.planes));
  auto odometry = [&](int k) {
    geometry_msgs::TransformStamped tf;
    tf.header.stamp = ros::Time(world_->frame(k / 30.0).stamp + 5500);
    tf.header.frame_id = "odom_late";
    tf.child_frame_id = "camera_optical_late";
    tf.transform = toTransformMsg(rosMapFromTarget() * world_->truthMapFromCamera(k / 30.0));
    return tf;
  };
  for (int i = 0; i < 10; ++i) {  // the link exists before the first image (its odometry lags)
    geometry_msgs::TransformStamped tf = odometry(0);
    tf.header.stamp -= ros::Duration(1.0);
    broadcaster.sendTransform(tf);
    ros::WallDuration(0.1 * timeoutScale()).sleep();
  }
  {  // A malformed message is dropped on arrival: it never waits for its odometry (it
     // waited in vain before, and switched the wait off for the good ones).
    TrackFrame f = world_->frame(0);
    f.stamp += 5500 - 0.5;
    TracksPtr msg = toTracks(f);
    msg->header.frame_id = "camera_optical_late";
    msg->u.pop_back();
    tracks.publish(msg);
    spinUntil([&] { return diagnostics.number("tracks messages dropped") >= 1; }, 5.0);
    ros::WallDuration(0.5).sleep();  // twice odom_wait_s: a wait would have ended
    ASSERT_TRUE(diagnostics.waitFresh());
    EXPECT_EQ(diagnostics.number("tracks messages dropped"), 1);
    EXPECT_EQ(diagnostics.number("odometry waited for in vain (total)"), 0);
  }
  const int lag = 12, images = 90;  // 0.4 s at 30 images/s; 3 s of images
  for (int k = 0; k < images + lag; ++k) {
    if (k < images) {
      TrackFrame f = world_->frame(k / 30.0);
      for (size_t i = 0; i < f.ids.size(); ++i) f.target_corner[i] = false;  // no target
      f.stamp += 5500;                                                       // its own time line
      TracksPtr msg = toTracks(f);
      msg->header.frame_id = "camera_optical_late";
      tracks.publish(msg);
    }
    if (k >= lag) broadcaster.sendTransform(odometry(k - lag));
    ros::WallDuration(1.0 / 30).sleep();
    ros::spinOnce();
  }
  spinUntil([&] { return answers.size() >= static_cast<size_t>(images); }, 10.0);
  EXPECT_EQ(answers.size(), static_cast<size_t>(images));
  ASSERT_TRUE(diagnostics.waitFresh());
  const long in_vain = diagnostics.number("odometry waited for in vain (total)");
  std::printf("odometry 0.4 s late: %zu of %d images answered, %ld waited in vain\n",
              answers.size(), images, in_vain);
  EXPECT_GE(in_vain, 1);  // the first wait: it cannot know the lag before
  EXPECT_LE(in_vain, 2);  // (before: one every 0.65 s, 4-5 here)
  EXPECT_NE(diagnostics.message().find("odometry (odom_late) stopped, or more than odom_wait_s ("),
            std::string::npos)
      << diagnostics.message();
}

// Killing the plane nodelet while tracks keep coming, and loading it again: it answers
// at once (image-space planes until it has intrinsics and the start) and becomes metric.
TEST_F(PlaneNodeletTest, J_RestartWhileTracksFlow) {
  nodelet::NodeletUnload unload;
  unload.request.name = "/plane_detector";
  ASSERT_TRUE(ros::service::call("/manager/unload_nodelet", unload));
  ASSERT_TRUE(unload.response.success);
  // Tracks go on with nobody listening on this instance.
  for (int k = 0; k < 5; ++k) tracks_pub_.publish(toTracks(world_->frame(k / 30.0)));
  nodelet::NodeletLoad load;
  load.request.name = "/plane_detector";
  load.request.type = "mono_plane_detection/PlaneNodelet";
  ASSERT_TRUE(ros::service::call("/manager/load_nodelet", load));
  ASSERT_TRUE(load.response.success);
  info_pub_.publish(cameraInfo(world_->camera));  // latched: the new instance gets it
  spinUntil([&] { return planes_sub_.getNumPublishers() > 0; }, 10.0);
  scaledWait(1.0).sleep();
  const PlaneArrayConstPtr first = drive(0, 1, 800);
  ASSERT_TRUE(first) << "the reloaded nodelet does not answer";
  EXPECT_FALSE(first->metric);
  const PlaneArrayConstPtr later = drive(1 / 30.0, 80, 800);
  ASSERT_TRUE(later);
  EXPECT_TRUE(later->metric) << later->status;
}

// Issue 15, cases 2-4: camera_info with D: [] (reshape threw), the same K with 5 then 8
// then 14 coefficients (cv::norm asserted), D of a length OpenCV does not take (accepted,
// then undistortPoints asserted on the target's corners). Each killed the manager.
TEST_F(PlaneNodeletTest, K_CameraInfoDistortionVariants) {
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  ASSERT_TRUE(diagnostics.waitFresh());
  const long rejected = diagnostics.number("camera_info messages rejected");
  double offset = 900;
  auto publishAndDrive = [&](const sensor_msgs::CameraInfo& info) {
    info_pub_.publish(info);
    scaledWait(0.5).sleep();
    offset += 10;
    return drive(0, 15, offset);  // the target is in view: its corners are undistorted
  };
  sensor_msgs::CameraInfo info = cameraInfo(world_->camera);
  info.D.clear();
  PlaneArrayConstPtr last = publishAndDrive(info);
  ASSERT_TRUE(last) << "no answer after D: [] (manager gone?)";
  EXPECT_NE(last->status, "no camera intrinsics: image-space planes only");
  for (size_t n : {5, 8, 14}) {
    info = cameraInfo(world_->camera);
    info.distortion_model = "rational_polynomial";
    info.D.resize(n, 0.0);
    last = publishAndDrive(info);
    ASSERT_TRUE(last) << "no answer after " << n << " coefficients (manager gone?)";
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("camera_info messages rejected"), rejected);
  for (size_t n : {1, 3, 6, 100}) {
    info = cameraInfo(world_->camera);
    info.D.assign(n, 0.0);
    last = publishAndDrive(info);
    ASSERT_TRUE(last) << "no answer after " << n << " coefficients (manager gone?)";
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("camera_info messages rejected"), rejected + 4);
  EXPECT_EQ(diagnostics.number("exceptions caught (total)"), 0);
  // The sensor's camera_info (twice the size and focal length) for binned images: with
  // binning 2 it describes them (image_geometry: no size warning); without, it is another
  // camera's, which diagnostics say.
  sensor_msgs::CameraInfo sensor = cameraInfo(world_->camera);
  sensor.width *= 2;
  sensor.height *= 2;
  for (int i : {0, 2, 4, 5}) sensor.K[i] *= 2;
  for (int i : {0, 2, 5, 6}) sensor.P[i] *= 2;
  const std::string other_size = "camera_info is for " + std::to_string(sensor.width) + "x" +
                                 std::to_string(sensor.height) + " images";
  sensor.binning_x = sensor.binning_y = 2;
  last = publishAndDrive(sensor);
  ASSERT_TRUE(last) << "no answer with binning 2";
  EXPECT_NE(last->status, "no camera intrinsics: image-space planes only");
  ASSERT_TRUE(diagnostics.waitFresh());  // (no size warning before this one)
  EXPECT_EQ(diagnostics.message().find(other_size), std::string::npos) << diagnostics.message();
  // Without binning: another image size. Not used (it made a confirmed false ceiling of a
  // real room); the binned one before it, of the images' size, still is (a stray
  // camera_info does not drop the map: the images stay metric, status below): an ERROR
  // naming both sizes and what to do, counted.
  sensor.binning_x = sensor.binning_y = 1;
  const long mismatched = diagnostics.number("tracks with camera_info of another size (total)");
  info_pub_.publish(sensor);
  scaledWait(0.5).sleep();
  for (int k = 15; k < 30; ++k) {  // the same stretch of images on
    TrackFrame f = world_->frame(k / 30.0);
    f.stamp += offset;
    last = send(toTracks(f));
    ASSERT_TRUE(last) << "no answer with the sensor's camera_info";
  }
  EXPECT_NE(last->status, "no camera intrinsics: image-space planes only");
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << diagnostics.message();
  EXPECT_NE(diagnostics.message().find(other_size + " but the images are 640x480: not used"),
            std::string::npos)
      << diagnostics.message();
  EXPECT_NE(diagnostics.message().find("the last camera_info of their size still is"),
            std::string::npos)
      << diagnostics.message();
  EXPECT_NE(diagnostics.message().find("binning_x/y or ROI"), std::string::npos);
  EXPECT_EQ(diagnostics.value("camera model"), "raw (K, D)");
  EXPECT_EQ(diagnostics.number("tracks with camera_info of another size (total)"), mismatched + 15);
  EXPECT_EQ(diagnostics.number("camera_info messages rejected"), rejected + 4);
  // The right one again: used from the next tracks on, the ERROR gone at once.
  sensor.binning_x = sensor.binning_y = 2;
  last = publishAndDrive(sensor);
  ASSERT_TRUE(last);
  EXPECT_NE(last->status, "no camera intrinsics: image-space planes only");
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << diagnostics.message();
  // A real switch to 320x240 (camera_info and images together) goes on by itself.
  sensor_msgs::CameraInfo small = cameraInfo(world_->camera);
  small.width /= 2;
  small.height /= 2;
  for (int i : {0, 2, 4, 5}) small.K[i] /= 2;
  auto sendSmall = [&](int frames) {
    offset += 10;
    for (int k = 0; k < frames; ++k) {
      TrackFrame f = world_->frame(k / 30.0);
      f.stamp += offset;
      TracksPtr msg = toTracks(f);
      msg->width /= 2;
      msg->height /= 2;
      for (auto& u : msg->u) u /= 2;
      for (auto& v : msg->v) v /= 2;
      last = send(msg);
      if (!last) return;
    }
  };
  info_pub_.publish(small);
  scaledWait(0.5).sleep();
  sendSmall(5);
  ASSERT_TRUE(last);
  EXPECT_NE(last->status, "no camera intrinsics: image-space planes only");
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << diagnostics.message();
  // The sensor's unbinned camera_info again, and images of 640x480: no camera_info of
  // their size is the last one or the last that fitted them: image-space planes.
  sensor.binning_x = sensor.binning_y = 1;
  last = publishAndDrive(sensor);
  ASSERT_TRUE(last);
  EXPECT_FALSE(last->metric);
  EXPECT_EQ(last->status, "no camera intrinsics: image-space planes only");
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << diagnostics.message();
  EXPECT_NE(diagnostics.message().find("planes stay in image space"), std::string::npos)
      << diagnostics.message();
  EXPECT_EQ(diagnostics.value("camera model"), "not used: camera_info for another image size");
  info_pub_.publish(cameraInfo(world_->camera));  // latched: leave a good one
}

// Issue 15, case 7: an infinite odometry translation passes tf2; the nodelet published
// metric: true with a NaN camera pose. A 100 m jump was taken as "tracking (odometry)".
TEST_F(PlaneNodeletTest, L_NonFiniteOrJumpingOdometryIsRefused) {
  OtherNodelet other(nh_, "odom", 20, 50);
  ros::Publisher& tracks = other.tracks;
  std::map<uint64_t, PlaneArrayConstPtr>& answers = other.answers;
  DiagnosticsProbe& diagnostics = other.diagnostics;
  tf2_ros::TransformBroadcaster broadcaster;
  ASSERT_TRUE(linked(other.tracks, other.planes));
  const Pose odom_from_map{cameraOrientation(0.3, 0, 0), {1, 0, 0}};
  PlaneArrayConstPtr last;
  for (int k = 0; k < 96; ++k) {
    const double t = k / 30.0;
    TrackFrame f = world_->frame(t);
    f.stamp += 1500;  // its own time line
    Pose odom = odom_from_map * world_->truthMapFromCamera(t);
    if (k == 92) odom.t[0] = std::numeric_limits<double>::infinity();
    if (k == 94) odom.t[1] += 100;
    geometry_msgs::TransformStamped tf;
    tf.header.stamp = ros::Time(f.stamp);
    tf.header.frame_id = "odom";
    tf.child_frame_id = "camera_optical";
    tf.transform = toTransformMsg(odom);
    broadcaster.sendTransform(tf);
    ros::WallDuration(0.02).sleep();  // let tf arrive before the tracks
    tracks.publish(toTracks(f));
    last = waitFor(answers, ros::Time(f.stamp).toNSec());
    ASSERT_TRUE(last) << "image " << k << " not answered (manager gone?)";
    if (k == 91) {
      EXPECT_EQ(last->status, "tracking (odometry)");
    }
    if (k == 92 || k == 94) {
      EXPECT_NE(last->status, "tracking (odometry)") << "image " << k;
      if (last->metric) {
        EXPECT_TRUE(std::isfinite(last->camera_pose.position.x)) << "image " << k;
        EXPECT_TRUE(std::isfinite(last->camera_pose.position.y)) << "image " << k;
        EXPECT_LT(std::abs(last->camera_pose.position.y), 10.0) << "image " << k;
      }
    }
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  // 92 (infinite), 93 (a jump back from infinity), 94 (100 m), 95 (100 m back).
  EXPECT_GE(diagnostics.number("odometry refused (total)"), 3);
}

// Issue 15, case 15: two cameras alternating on one tracks topic gave 0 planes silently;
// now each switch is counted in diagnostics, which go to WARN.
TEST_F(PlaneNodeletTest, M_TwoCamerasOnOneTracksTopicAreReported) {
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  ASSERT_TRUE(diagnostics.waitFresh());
  const long before = diagnostics.number("camera switches (total)");
  ASSERT_GE(before, 0);
  for (int k = 0; k < 10; ++k) {
    TrackFrame f = world_->frame(k / 30.0);
    f.stamp += 2000;
    TracksPtr msg = toTracks(f);
    if (k % 2) {
      msg->header.frame_id = "right_camera";
      msg->width /= 2;
      msg->height /= 2;
      for (auto& u : msg->u) u /= 2;
      for (auto& v : msg->v) v /= 2;
    }
    ASSERT_TRUE(send(msg)) << k;
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_GE(diagnostics.number("camera switches (total)") - before, 9);
  // The last tracks (half size) are not of camera_info's size: that ERROR is the summary;
  // the switches are a problem of their own while recent (10 s), none hides the other.
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR);
  EXPECT_NE(diagnostics.value("problem: last 10 s, tracks camera switch")
                .find("tracks mix cameras: tracks changed camera"),
            std::string::npos)
      << diagnostics.value("problem: last 10 s, tracks camera switch");
  EXPECT_NE(diagnostics.value("problem: camera_info").find("camera_info is for 640x480"),
            std::string::npos)
      << diagnostics.value("problem: camera_info");
  EXPECT_EQ(diagnostics.number("exceptions caught (total)"), 0);
}

// ~save_map writes the map's planes as YAML; ~reset empties the map and the pose: the
// next answer has no plane and is not metric, and the map comes back with the target.
TEST_F(PlaneNodeletTest, N_SaveMapAndReset) {
  info_pub_.publish(cameraInfo(world_->camera));
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::call("/plane_detector/reset", reset));  // after M's camera mix
  // Planes are confirmed from distinct viewpoints (issue 18): 240 images give floor + wall.
  const int images = 240;
  const PlaneArrayConstPtr before = drive(0, images, 3000);
  ASSERT_TRUE(before);
  ASSERT_TRUE(before->metric) << before->status;
  size_t confirmed = 0;
  for (const auto& p : before->planes) confirmed += p.metric;
  ASSERT_GE(confirmed, 2u);

  SaveMap save;
  save.request.path = tempPath("plane_nodelet_map.yaml");
  ASSERT_TRUE(ros::service::call("/plane_detector/save_map", save));
  EXPECT_TRUE(save.response.success) << save.response.message;
  EXPECT_EQ(save.response.planes, confirmed);
  std::ifstream in(save.request.path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("frame_id: plane_map"), std::string::npos);
  EXPECT_NE(text.str().find("label: floor"), std::string::npos);
  EXPECT_NE(text.str().find("label: wall"), std::string::npos);
  // A relative path: the manager's working directory, not ours; the answer says where.
  SaveMap relative;
  relative.request.path = "plane_nodelet_map_" + std::to_string(getpid()) + ".yaml";
  ASSERT_TRUE(ros::service::call("/plane_detector/save_map", relative));
  ASSERT_TRUE(relative.response.success) << relative.response.message;
  const size_t to = relative.response.message.find(" to /");
  ASSERT_NE(to, std::string::npos) << relative.response.message;
  const std::string written = relative.response.message.substr(to + 4);
  EXPECT_NE(written.find("/" + relative.request.path), std::string::npos) << written;
  EXPECT_TRUE(std::ifstream(written).good()) << written;
  std::remove(written.c_str());
  SaveMap nowhere;
  nowhere.request.path = "/nonexistent_dir/map.yaml";
  ASSERT_TRUE(ros::service::call("/plane_detector/save_map", nowhere));
  EXPECT_FALSE(nowhere.response.success);

  int cleared = 0;  // DELETEALL markers heard: rviz drops the old map's planes at the reset
  ros::Subscriber markers = nh_.subscribe<visualization_msgs::MarkerArray>(
      "plane_markers", 10, [&](const visualization_msgs::MarkerArrayConstPtr& m) {
        for (const auto& marker : m->markers)
          cleared += marker.action == visualization_msgs::Marker::DELETEALL;
      });
  spinUntil([&] { return markers.getNumPublishers() > 0; }, 5.0);
  ASSERT_TRUE(ros::service::call("/plane_detector/reset", reset));
  spinUntil([&] { return cleared > 0; }, 2.0);
  EXPECT_EQ(cleared, 1) << "no DELETEALL on ~reset without further tracks";
  {
    // Before the next tracks (a paused robot): the status is the reset's, not the old map's
    // (hostile try: "tracking (landmarks)" and its tf link stayed).
    DiagnosticsProbe paused(nh_, "plane_detector: planes");
    ASSERT_TRUE(paused.waitFresh());
    EXPECT_EQ(paused.value("state"), "reset: the map starts over with the next tracks");
    EXPECT_EQ(paused.value("tf"), "nothing published yet");
    EXPECT_EQ(paused.value("metric source").rfind("none yet", 0), 0u)
        << paused.value("metric source");
  }
  // The stream goes on (stamps keep increasing): only the reset empties the map.
  const PlaneArrayConstPtr after = drive(images / 30.0, 1, 3000);
  ASSERT_TRUE(after);
  EXPECT_FALSE(after->metric) << after->status;
  EXPECT_TRUE(after->planes.empty());
  const PlaneArrayConstPtr again = drive(0, 90, 3010);
  ASSERT_TRUE(again);
  EXPECT_TRUE(again->metric) << again->status;
  // Its own earlier tf link is no conflict after the reset.
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  drive(90 / 30.0, 40, 3010);
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << diagnostics.message();
  EXPECT_EQ(diagnostics.value("tf"), "plane_map -> camera_optical_estimate");
  EXPECT_GE(diagnostics.number("resets (total)"), 2);
}

// dynamic_reconfigure: planes_max_planes = 1 caps this image's planes at one from the next
// image on (two or more before); back to 8, they come back. Diagnostics count both.
TEST_F(PlaneNodeletTest, O_ReconfigureChangesTheNextImage) {
  auto planesNow = [&](double t0, double offset) {
    size_t most = 0;
    for (int k = 0; k < 10; ++k) {
      const PlaneArrayConstPtr map = drive(t0 + k / 30.0, 1, offset);
      if (!map) return static_cast<size_t>(1000);
      const PlaneArrayConstPtr image = waitFor(image_planes_, map->header.stamp.toNSec());
      if (!image) return static_cast<size_t>(1000);
      most = std::max(most, image->planes.size());
    }
    return most;
  };
  auto setMaxPlanes = [&](int n) {
    dynamic_reconfigure::Reconfigure srv;
    dynamic_reconfigure::IntParameter p;
    p.name = "planes_max_planes";
    p.value = n;
    srv.request.config.ints.push_back(p);
    EXPECT_TRUE(ros::service::call("/plane_detector/set_parameters", srv));
    bool echoed = false;
    for (const auto& i : srv.response.config.ints)
      echoed |= i.name == "planes_max_planes" && i.value == n;
    EXPECT_TRUE(echoed);
  };
  const size_t before = planesNow(4.0, 4000);
  EXPECT_GE(before, 2u);
  EXPECT_LT(before, 1000u);
  setMaxPlanes(1);
  const size_t capped = planesNow(4.5, 4000);
  EXPECT_EQ(capped, 1u);
  setMaxPlanes(8);
  EXPECT_GE(planesNow(5.0, 4000), 2u);
  std::printf("image planes: %zu, with planes_max_planes 1: %zu\n", before, capped);
  // A value the nodelet refuses (NaN) leaves the value in use, and the server reports it,
  // not the one refused.
  dynamic_reconfigure::Reconfigure nan_gap;
  dynamic_reconfigure::DoubleParameter gap;
  gap.name = "max_gap_s";
  gap.value = std::numeric_limits<double>::quiet_NaN();
  nan_gap.request.config.doubles.push_back(gap);
  EXPECT_TRUE(ros::service::call("/plane_detector/set_parameters", nan_gap));
  bool reported = false;
  for (const auto& d : nan_gap.response.config.doubles)
    if (d.name == "max_gap_s") {
      reported = true;
      EXPECT_EQ(d.value, 1.0);  // the value in use (config/planes.yaml)
    }
  EXPECT_TRUE(reported);
  double stored = 0;
  EXPECT_TRUE(ros::param::get("/plane_detector/max_gap_s", stored));
  EXPECT_EQ(stored, 1.0);
  EXPECT_GE(planesNow(5.5, 4000), 2u);  // and the nodelet goes on
  // Diagnostics name the refused value until a reconfigure is accepted.
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.value("problem: configuration").find("reconfigure: max_gap_s = nan"),
            std::string::npos)
      << diagnostics.value("problem: configuration");
  gap.value = 1.0;
  nan_gap.request.config.doubles = {gap};
  EXPECT_TRUE(ros::service::call("/plane_detector/set_parameters", nan_gap));
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.value("problem: configuration"), "");
  // The YAML's nested values were the server's start, not the .cfg defaults.
  int max_groups = 0;
  EXPECT_TRUE(ros::param::get("/plane_detector/planes_groups_max_groups", max_groups));
  EXPECT_EQ(max_groups, 100);  // config/planes.yaml (the .cfg default is 300)
}

// Diagnostics WARN when the start-up target has not been seen for target_timeout_s (30 s
// of tracks stamps), and OK again once it is. The wait counts over the stream's stretches:
// a jump of the stamps is no waiting (it said "not seen for 100000011 s" after a jump).
TEST_F(PlaneNodeletTest, P_TargetNotSeenIsAWarning) {
  std_srvs::Empty reset;
  ASSERT_TRUE(ros::service::call("/plane_detector/reset", reset));
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  auto withoutTarget = [&](double stamp) {  // the room without the target's flags
    TrackFrame f = world_->frame(0);
    f.stamp = stamp;
    f.target_corner.assign(f.target_corner.size(), false);
    return send(toTracks(f)) != nullptr;
  };
  auto waitedS = [&] {
    const std::string said = diagnostics.message();
    const std::string head = "start-up target not seen for ";
    if (said.rfind(head, 0) != 0) return -1L;
    return std::stol(said.substr(head.size()));
  };
  for (int k = 0; k <= 36; ++k) ASSERT_TRUE(withoutTarget(5000 + k)) << k;  // 1 Hz
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());  // a status made after the last tracks
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN) << diagnostics.message();
  const long waited = waitedS();
  // (No pause in it: one second is the stream's rhythm from its first image; it lost
  // its first three seconds to pauses before.)
  EXPECT_GE(waited, 35) << diagnostics.message();
  EXPECT_LE(waited, 36) << diagnostics.message();
  // What to do, in the words of the launch files' arguments.
  EXPECT_NE(diagnostics.message().find("or start the metres without it (metric_source odometry"),
            std::string::npos)
      << diagnostics.message();
  // No map yet: whether its up will hold the planes is decided at its first placed image.
  EXPECT_EQ(diagnostics.value("map up (map/up_sigma_deg)"),
            "not decided yet (at the first image placed in metres)");
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(withoutTarget(1e8 + 5000 + k)) << k;  // a jump
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_GE(waitedS(), waited) << diagnostics.message();
  EXPECT_LE(waitedS(), waited + 3) << diagnostics.message();
  // Time going back (a bag loop, the target not seen in the loop before): the wait goes
  // on, as the tracker's does (it restarted, from a stretch that ran backwards).
  const long before_loop = waitedS();
  ASSERT_GE(before_loop, 31) << diagnostics.message();
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(withoutTarget(4000 + k)) << k;
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::WARN) << diagnostics.message();
  EXPECT_GE(waitedS(), before_loop) << diagnostics.message();
  EXPECT_LE(waitedS(), before_loop + 3) << diagnostics.message();
  const PlaneArrayConstPtr seen = drive(0, 3, 1e8 + 5010);
  ASSERT_TRUE(seen);
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.message().find("start-up target not seen"), std::string::npos)
      << diagnostics.message();
}

// plane_detector_misconfigured (plane_nodelet.test): metric_source odometry without
// odom_frame never gives metres: ERROR in diagnostics while it lasts (it said OK, "waiting
// for odometry", with the reason only in the log at start; hostile try).
TEST_F(PlaneNodeletTest, P2_AMetricSourceThatCannotStartIsAnError) {
  DiagnosticsProbe diagnostics(nh_, "plane_detector_misconfigured: planes");
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << diagnostics.message();
  EXPECT_NE(diagnostics.message().find("metric_source odometry needs odom_frame"),
            std::string::npos)
      << diagnostics.message();
  // The healthy instance has no configuration problem.
  DiagnosticsProbe healthy(nh_, "plane_detector: planes");
  ASSERT_TRUE(healthy.waitFresh());
  EXPECT_EQ(healthy.value("problem: configuration"), "");
}

// Odometry from tf for tracks whose camera frame is not in the tf tree (a driver's frame_id
// against another URDF name): diagnostics name the frame, not "odometry stopped".
TEST_F(PlaneNodeletTest, Q_CameraFrameMissingFromTfIsNamed) {
  OtherNodelet other(nh_, "odom", 20, 50);
  ASSERT_TRUE(linked(other.tracks, other.planes));
  tf2_ros::TransformBroadcaster broadcaster;
  for (int k = 0; k < 10; ++k) {
    TrackFrame f = world_->frame(k / 30.0);
    f.stamp += 6000;
    geometry_msgs::TransformStamped tf;  // the odometry runs (to the robot's camera frame)
    tf.header.stamp = ros::Time(f.stamp);
    tf.header.frame_id = "odom";
    tf.child_frame_id = "camera_optical";
    tf.transform = toTransformMsg(world_->truthMapFromCamera(k / 30.0));
    broadcaster.sendTransform(tf);
    TracksPtr msg = toTracks(f);
    msg->header.frame_id = "camera_not_in_tf";
    other.tracks.publish(msg);
    ASSERT_TRUE(waitFor(other.answers, msg->header.stamp.toNSec())) << k;
  }
  ASSERT_TRUE(other.diagnostics.waitFresh());
  ASSERT_TRUE(other.diagnostics.waitFresh());
  const std::string said = other.diagnostics.value("problem: odometry");
  EXPECT_NE(said.find("camera frame 'camera_not_in_tf' (the images' header.frame_id) is not in "
                      "the tf tree"),
            std::string::npos)
      << said << " / " << other.diagnostics.message();
  EXPECT_NE(said.find("must be a tf frame of the robot"), std::string::npos) << said;
  EXPECT_EQ(other.diagnostics.message().find("stopped"), std::string::npos)
      << other.diagnostics.message();
}

// A head on joints (hostile try, humanoid URDF): odom -> body (odometry), body -> head (a
// joint, robot_state_publisher), head -> camera. Before the joint's first transform the
// camera's chain ends at the head: said so (it blamed the images' frame_id); when the joint
// states stop while the odometry runs, the joint's link is named (it blamed the odometry).
TEST_F(PlaneNodeletTest, Q2_AJointLinkMissingOrStaleIsNamed) {
  OtherNodelet other(nh_, "odom", 20, 50);
  ASSERT_TRUE(linked(other.tracks, other.planes));
  tf2_ros::TransformBroadcaster broadcaster;
  auto link = [](const std::string& parent, const std::string& child, double stamp,
                 const Pose& pose) {
    geometry_msgs::TransformStamped tf;
    tf.header.stamp = ros::Time(stamp);
    tf.header.frame_id = parent;
    tf.child_frame_id = child;
    tf.transform = toTransformMsg(pose);
    return tf;
  };
  const Pose identity{cv::Matx33d::eye(), {0, 0, 0}};
  // Image k: the odometry and the head's mount always, the joint when `joint` is true.
  auto sendImage = [&](int k, bool joint) {
    TrackFrame f = world_->frame(k / 30.0);
    f.stamp += 6100;
    std::vector<geometry_msgs::TransformStamped> out = {
        link("odom", "body_q", f.stamp, world_->truthMapFromCamera(k / 30.0)),
        link("head_q", "camera_head_q", f.stamp, identity)};
    if (joint) out.push_back(link("body_q", "head_q", f.stamp, identity));
    broadcaster.sendTransform(out);
    ros::WallDuration(0.02).sleep();  // let tf arrive before the tracks
    TracksPtr msg = toTracks(f);
    msg->header.frame_id = "camera_head_q";
    other.tracks.publish(msg);
    return waitFor(other.answers, msg->header.stamp.toNSec()) != nullptr;
  };
  auto odometryProblem = [&] {
    other.diagnostics.waitFresh();
    other.diagnostics.waitFresh();
    return other.diagnostics.value("problem: odometry");
  };
  ros::WallDuration(0.5).sleep();  // the nodelet's tf listener hears the new broadcaster
  for (int k = 0; k < 5; ++k) ASSERT_TRUE(sendImage(k, false)) << k;
  std::string said = odometryProblem();
  EXPECT_NE(said.find("is not connected to odom_frame 'odom' on tf (yet): its tf goes up to "
                      "'head_q' only"),
            std::string::npos)
      << said;
  for (int k = 5; k < 10; ++k) ASSERT_TRUE(sendImage(k, true)) << k;
  said = odometryProblem();
  EXPECT_EQ(said, "");
  for (int k = 10; k < 16; ++k) ASSERT_TRUE(sendImage(k, false)) << k;
  said = odometryProblem();
  EXPECT_NE(said.find("tf body_q -> head_q (between the camera and odom_frame 'odom') is more "
                      "than odom_wait_s"),
            std::string::npos)
      << said;
}

// A camera_info of another frame than the tracks' (another camera's, through a remap gone
// wrong) is used all the same but counted and said (a hostile try found it silent).
TEST_F(PlaneNodeletTest, R_CameraInfoOfAnotherFrameIsCounted) {
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  ASSERT_TRUE(diagnostics.waitFresh());
  const long before = diagnostics.number("tracks with camera_info of another frame_id (total)");
  ASSERT_GE(before, 0);
  sensor_msgs::CameraInfo other = cameraInfo(world_->camera);
  other.header.frame_id = "left_camera_optical";
  info_pub_.publish(other);
  ros::WallDuration(0.3).sleep();
  for (int k = 0; k < 5; ++k) {
    TrackFrame f = world_->frame(k / 30.0);
    f.stamp += 7000;
    ASSERT_TRUE(send(toTracks(f))) << k;  // frame camera_optical
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("tracks with camera_info of another frame_id (total)") - before, 5);
  info_pub_.publish(cameraInfo(world_->camera));  // its own again: no more counted
  ros::WallDuration(0.3).sleep();
  for (int k = 5; k < 8; ++k) {
    TrackFrame f = world_->frame(k / 30.0);
    f.stamp += 7000;
    ASSERT_TRUE(send(toTracks(f))) << k;
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("tracks with camera_info of another frame_id (total)") - before, 5);
}

// Last (its WARNs last 10 s): tracks lost before they reach the nodelet (the tracker's
// dropped images, a queue that overflows under load) show only as gaps in the stamps; a
// hostile try saw 134 of 309 lost with the status OK. And stamps going back and forth
// (two bags on one topic) started the map over 30 times a second with the status OK.
TEST_F(PlaneNodeletTest, S_MissingTracksAndAFloodOfTimeJumpsAreWarnings) {
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  ASSERT_TRUE(diagnostics.waitFresh());
  const long before = diagnostics.number("tracks missing from the stream (total)");
  ASSERT_GE(before, 0);
  // 30 Hz with every third image missing: intervals of 1, 1, 2 periods.
  int sent = 0, k = 0;
  while (sent < 40) {
    if (k % 3 != 2) {
      TrackFrame f = world_->frame(k / 30.0);
      f.stamp += 8000;
      ASSERT_TRUE(send(toTracks(f))) << k;
      ++sent;
    }
    ++k;
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  const long missing = diagnostics.number("tracks missing from the stream (total)") - before;
  EXPECT_GE(missing, 17);  // 19 gaps; the period is known after the first intervals
  EXPECT_LE(missing, 20);
  EXPECT_NE(diagnostics.value("problem: tracks missing").find("tracks missing in the last 10 s"),
            std::string::npos)
      << diagnostics.value("problem: tracks missing");
  // Two sources interleaved: stamps back and forth.
  for (int j = 0; j < 8; ++j) {
    TrackFrame f = world_->frame(j / 30.0);
    f.stamp += (j % 2 ? 8100 : 9100) + j / 30.0;
    ASSERT_TRUE(send(toTracks(f))) << j;
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.value("problem: time").find("time went backwards"), std::string::npos)
      << diagnostics.value("problem: time");
}

// After S (the main instance's last test). The start-up target seen while camera_info was
// still missing (plane_detector_no_info), then out of view once camera_info came: the map
// waits for a target the tracker will not report again (it joins it once). A hostile try
// saw "waiting for target" at level OK for the whole bag; now a WARN says what to do.
TEST_F(PlaneNodeletTest, T_ATargetSeenBeforeCameraInfoIsAWarning) {
  DiagnosticsProbe diagnostics(nh_, "plane_detector_no_info: planes");
  for (int k = 0; k < 3; ++k) {  // the target in the tracks, no camera yet
    TrackFrame f = world_->frame(k / 30.0);
    f.stamp += 9500;
    tracks_pub_.publish(toTracks(f));
    ASSERT_TRUE(waitFor(no_info_, ros::Time(f.stamp).toNSec())) << k;
  }
  ros::Publisher late_info =
      nh_.advertise<sensor_msgs::CameraInfo>("never_published_camera_info", 1, true);
  late_info.publish(cameraInfo(world_->camera));
  ASSERT_TRUE(spinUntil([&] { return late_info.getNumSubscribers() > 0; }, 10.0));
  ros::WallDuration(0.3).sleep();
  PlaneArrayConstPtr r;
  for (int k = 3; k < 8; ++k) {  // camera_info now, the target gone from the tracks
    TrackFrame f = withoutTarget(world_->frame(k / 30.0));
    f.stamp += 9500;
    tracks_pub_.publish(toTracks(f));
    r = waitFor(no_info_, ros::Time(f.stamp).toNSec());
    ASSERT_TRUE(r) << k;
  }
  EXPECT_EQ(r->status.rfind("waiting for", 0), 0u) << r->status;
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_NE(diagnostics.value("problem: start-up target")
                .find("the tracker found the start-up target before camera_info came"),
            std::string::npos)
      << diagnostics.value("problem: start-up target") << " / " << diagnostics.message();
}

// Tracks that say the tracker's run (Tracks.tracker_run, as TrackerNodelet's do): another
// run is a reloaded or respawned tracker, even with the same ids, and the map starts over
// once, counted in diagnostics.
TEST_F(PlaneNodeletTest, U_AnotherTrackerRunStartsTheMapOver) {
  DiagnosticsProbe diagnostics(nh_, "plane_detector: planes");
  ASSERT_TRUE(diagnostics.waitFresh());
  const long before = diagnostics.number("resets: the tracker started over (total)");
  for (int k = 0; k < 6; ++k) {
    TrackFrame f = world_->frame(k / 30.0);
    f.stamp += 8500;  // after every earlier test's stamps for this nodelet
    TracksPtr msg = toTracks(f);
    msg->tracker_run = k < 4 ? 11 : 12;
    ASSERT_TRUE(send(msg)) << k;
  }
  ASSERT_TRUE(diagnostics.waitFresh());
  ASSERT_TRUE(diagnostics.waitFresh());
  EXPECT_EQ(diagnostics.number("resets: the tracker started over (total)") - before, 1);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_plane_nodelet");
  ros::NodeHandle nh;
  readTimeoutScale();
  return RUN_ALL_TESTS();
}
