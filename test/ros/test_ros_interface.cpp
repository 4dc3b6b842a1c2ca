// The pipeline as a robot sees it (issue 14), on real messages through the launch files:
//  TwoCameras: cameras in one roscore (plane_detection.launch three times: front and rear
//    in one manager, side in its own), under simulated time; front raw with distortion (K, D),
//    rear rectified (image_rect: P, no distortion) -- the same accuracy; diagnostics OK
//    during the replay and again after a pause.
//  TfTree: a URDF-like static tree (base_link -> camera_optical) plus odometry (odom ->
//    base_link): tf stays a tree, the nodelet publishes plane_map -> odom only, and
//    plane_map -> base_link is where the truth says. With ~localiser, another localiser
//    publishes map -> odom: the nodelet attaches odom -> plane_map instead. A second
//    nodelet told to publish the camera's own frame refuses (ERROR in diagnostics).
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <rosgraph_msgs/Log.h>
#include <sensor_msgs/CameraInfo.h>
#include <std_srvs/Empty.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <map>
#include <memory>
#include <set>
#include <string>

#include "mono_plane_detection/PlaneArray.h"
#include "mono_plane_detection/Tracks.h"
#include "mono_plane_detection/ros/map_frame.h"
#include "mono_plane_detection/ros/pose_msg.h"
#include "support/diagnostics_probe.h"
#include "support/synthetic_tracks.h"
#include "support/test_timeouts.h"

using namespace mono_plane_detection;

namespace {

TracksPtr toTracks(const TrackFrame& f, const std::string& frame_id) {
  TracksPtr msg(new Tracks);
  msg->header.stamp = ros::Time(f.stamp);
  msg->header.frame_id = frame_id;
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

// A raw camera's calibration: K and D of `raw`, and P = `rectified` (what image_proc's
// image_rect is projected with).
sensor_msgs::CameraInfo cameraInfo(const CameraModel& raw, const CameraModel& rectified,
                                   const std::string& frame_id) {
  sensor_msgs::CameraInfo info;
  info.header.frame_id = frame_id;
  info.width = static_cast<uint32_t>(raw.size.width);
  info.height = static_cast<uint32_t>(raw.size.height);
  info.distortion_model = "plumb_bob";
  info.D = {raw.k1, raw.k2, 0, 0, 0};
  const cv::Matx33d K = raw.K();
  for (int i = 0; i < 9; ++i) info.K[i] = K.val[i];
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {rectified.fx, 0, rectified.cx, 0, 0, rectified.fy, rectified.cy, 0, 0, 0, 1, 0};
  return info;
}

// Answers of one planes topic by stamp.
struct Answers {
  std::map<uint64_t, PlaneArrayConstPtr> by_stamp;
  ros::Subscriber sub;
  Answers(ros::NodeHandle& nh, const std::string& topic) {
    sub = nh.subscribe<PlaneArray>(
        topic, 50, [this](const PlaneArrayConstPtr& m) { by_stamp[m->header.stamp.toNSec()] = m; });
  }
  PlaneArrayConstPtr wait(const ros::Time& stamp, double seconds = 10.0) {
    const uint64_t key = stamp.toNSec();
    spinUntil([&] { return by_stamp.count(key) > 0; }, seconds);
    return by_stamp.count(key) ? by_stamp.at(key) : nullptr;
  }
};

double positionError(const PlaneArray& planes, const Pose& truth_target_from_camera) {
  const Pose truth = rosMapFromTarget() * truth_target_from_camera;
  return cv::norm(fromPoseMsg(planes.camera_pose).t - truth.t);
}

TEST(TwoCameras, RawAndRectifiedInOneManagerUnderSimTime) {
  ros::NodeHandle nh;
  ASSERT_TRUE(ros::Time::isSimTime());
  SyntheticTracks front("wheeled"), rear("wheeled");
  front.camera.k1 = -0.15;  // the raw image: barrel distortion
  front.camera.k2 = 0.02;
  rear.camera.fx = rear.camera.fy = 470;  // the rectified image: P's pinhole
  rear.camera.cx = 322;
  rear.camera.cy = 236;
  ros::Publisher clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  ros::Publisher front_tracks = nh.advertise<Tracks>("/front/tracks", 20);
  ros::Publisher rear_tracks = nh.advertise<Tracks>("/rear/tracks", 20);
  ros::Publisher front_info = nh.advertise<sensor_msgs::CameraInfo>("/front/camera_info", 1, true);
  ros::Publisher rear_info = nh.advertise<sensor_msgs::CameraInfo>("/rear/camera_info", 1, true);
  ros::Publisher side_tracks = nh.advertise<Tracks>("/side/tracks", 20);
  ros::Publisher side_info = nh.advertise<sensor_msgs::CameraInfo>("/side/camera_info", 1, true);
  Answers front_planes(nh, "/front/planes"), rear_planes(nh, "/rear/planes"),
      side_planes(nh, "/side/planes");
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  front_info.publish(cameraInfo(front.camera, front.camera, "front_optical"));
  // The rear camera's raw calibration (distorted, other K) with the rectified P.
  rear_info.publish(cameraInfo(front.camera, rear.camera, "rear_optical"));
  side_info.publish(cameraInfo(rear.camera, rear.camera, "side_optical"));
  spinUntil(
      [&] {
        return front_tracks.getNumSubscribers() > 0 && rear_tracks.getNumSubscribers() > 0 &&
               side_tracks.getNumSubscribers() > 0 && front_planes.sub.getNumPublishers() > 0 &&
               rear_planes.sub.getNumPublishers() > 0 && side_planes.sub.getNumPublishers() > 0;
      },
      30.0);
  ASSERT_GT(front_tracks.getNumSubscribers(), 0u);
  ASSERT_GT(rear_tracks.getNumSubscribers(), 0u);
  ASSERT_GT(side_tracks.getNumSubscribers(), 0u);
  // Front and rear in the front camera's manager, side in its own; same names, own namespaces.
  std::vector<std::string> nodes;
  ros::master::getNodes(nodes);
  const std::set<std::string> names(nodes.begin(), nodes.end());
  EXPECT_TRUE(names.count("/front/plane_detection_manager"));
  EXPECT_FALSE(names.count("/rear/plane_detection_manager"));
  EXPECT_TRUE(names.count("/front/plane_detector"));
  EXPECT_TRUE(names.count("/rear/plane_detector"));
  EXPECT_TRUE(names.count("/side/plane_detection_manager"));
  EXPECT_TRUE(names.count("/side/plane_detector"));
  EXPECT_TRUE(names.count("/side/tracker"));
  EXPECT_TRUE(names.count("/front/tracker"));

  std::vector<double> front_errors, rear_errors;
  auto play = [&](int from, int to) {
    for (int k = from; k < to; ++k) {
      const double t = k / 30.0;
      const TrackFrame f = front.frame(t), r = rear.frame(t);
      rosgraph_msgs::Clock now;
      now.clock = ros::Time(f.stamp);
      clock.publish(now);
      front_tracks.publish(toTracks(f, "front_optical"));
      rear_tracks.publish(toTracks(r, "rear_optical"));
      side_tracks.publish(toTracks(r, "side_optical"));
      const PlaneArrayConstPtr a = front_planes.wait(ros::Time(f.stamp));
      const PlaneArrayConstPtr b = rear_planes.wait(ros::Time(r.stamp));
      const PlaneArrayConstPtr c = side_planes.wait(ros::Time(r.stamp));
      if (!a || !b || !c) return false;
      if (k >= 150 && a->metric)
        front_errors.push_back(positionError(*a, front.truthMapFromCamera(t)));
      if (k >= 150 && b->metric)
        rear_errors.push_back(positionError(*b, rear.truthMapFromCamera(t)));
      ros::WallDuration(1.0 / 60).sleep();  // about 30 Hz with the answers' time
    }
    return true;
  };
  ASSERT_TRUE(play(0, 240)) << "an image was not answered";
  const PlaneArrayConstPtr a = front_planes.by_stamp.rbegin()->second;
  const PlaneArrayConstPtr b = rear_planes.by_stamp.rbegin()->second;
  EXPECT_EQ(a->header.frame_id, "front_map");
  EXPECT_EQ(b->header.frame_id, "rear_map");
  EXPECT_TRUE(a->metric) << a->status;
  EXPECT_TRUE(b->metric) << b->status;
  const PlaneArrayConstPtr c = side_planes.by_stamp.rbegin()->second;
  EXPECT_EQ(c->header.frame_id, "side_map");
  EXPECT_TRUE(c->metric) << c->status;
  double front_worst = 0, rear_worst = 0;
  for (double e : front_errors) front_worst = std::max(front_worst, e);
  for (double e : rear_errors) rear_worst = std::max(rear_worst, e);
  std::printf("raw (K, D): %zu poses, worst %.3f m; rectified (P): %zu poses, worst %.3f m\n",
              front_errors.size(), front_worst, rear_errors.size(), rear_worst);
  EXPECT_GE(front_errors.size(), 80u);
  EXPECT_GE(rear_errors.size(), 80u);
  EXPECT_LT(front_worst, 0.1);
  EXPECT_LT(rear_worst, 0.1);
  EXPECT_LT(rear_worst, front_worst + 0.05);  // the same accuracy
  EXPECT_TRUE(
      buffer.canTransform("front_map", "front_optical_estimate", ros::Time(0), ros::Duration(2.0)));
  EXPECT_TRUE(
      buffer.canTransform("rear_map", "rear_optical_estimate", ros::Time(0), ros::Duration(2.0)));

  // Each nodelet says which camera model it uses: raw (K, D) for the front camera, P for
  // the rear (image_rect) and the side (rectified:=true, which reaches both nodelets).
  for (const auto& [camera, model] : std::map<std::string, std::string>{
           {"front", "raw (K, D)"}, {"rear", "rectified (P)"}, {"side", "rectified (P)"}}) {
    DiagnosticsProbe tracker(nh, camera + "/tracker: tracking");
    DiagnosticsProbe planes(nh, camera + "/plane_detector: planes");
    ASSERT_TRUE(tracker.waitFresh()) << camera;
    ASSERT_TRUE(planes.waitFresh()) << camera;
    EXPECT_EQ(tracker.value("camera model"), model) << camera << "'s tracker";
    EXPECT_EQ(planes.value("camera model"), model) << camera << "'s plane detector";
  }

  // Diagnostics under simulated time: the input rate and the node's own status are OK
  // during the replay, a pause shows, and after it they are OK again.
  DiagnosticsProbe rate(nh, "front/plane_detector: input rate");
  DiagnosticsProbe status(nh, "front/plane_detector: planes");
  ASSERT_TRUE(play(240, 300));
  ASSERT_TRUE(rate.waitFresh());
  ASSERT_TRUE(status.waitFresh());
  EXPECT_EQ(rate.level(), diagnostic_msgs::DiagnosticStatus::OK) << rate.message();
  EXPECT_EQ(status.level(), diagnostic_msgs::DiagnosticStatus::OK) << status.message();
  // Each camera's nodelets under their camera's name (an aggregator tells them apart).
  EXPECT_EQ(status.hardwareId(), "/front");
  DiagnosticsProbe rear_status(nh, "rear/plane_detector: planes");
  ASSERT_TRUE(rear_status.waitFresh());
  EXPECT_EQ(rear_status.hardwareId(), "/rear");
  const double hz = std::stod(rate.value("actual frequency (Hz)"));
  // The replay's 30 Hz as the node sees it, on wall time (a loaded CI machine answered
  // 9.4 Hz): far from the 0.03 Hz a rate read on simulated time gave.
  EXPECT_GT(hz, 3.0);
  EXPECT_LT(hz, 60.0);
  ros::WallDuration(6.0).sleep();  // the bag is paused: no clock, no tracks
  ASSERT_TRUE(rate.waitFresh());
  EXPECT_EQ(rate.level(), diagnostic_msgs::DiagnosticStatus::WARN) << rate.message();
  ASSERT_TRUE(play(300, 480));
  ASSERT_TRUE(rate.waitFresh());
  EXPECT_EQ(rate.level(), diagnostic_msgs::DiagnosticStatus::OK) << rate.message();
}

// A bag played in a loop (after the test above, same nodelets): /clock goes back, tracks of
// the previous loop's end may still come, then the loop's own. No tf is published with the
// previous loop's stamps (tf2_ros's listener cleared its buffer at the jump; such a stamp
// made it refuse the new loop's first 2 s: ~60 TF_OLD_DATA warnings per loop), and "the map
// starts over" is said at every loop (a throttle on the simulated clock silenced it after
// the first) and counted with the resets.
TEST(TwoCameras, ABagLoopStartsTheMapOverWithoutTheOldLoopsTf) {
  ros::NodeHandle nh;
  ASSERT_TRUE(ros::Time::isSimTime());
  SyntheticTracks front("wheeled");
  front.camera.k1 = -0.15;  // as above
  front.camera.k2 = 0.02;
  ros::Publisher clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  ros::Publisher tracks = nh.advertise<Tracks>("/front/tracks", 20);
  Answers planes(nh, "/front/planes");
  std::set<uint64_t> tf_stamps;  // of front_map's transforms
  ros::Subscriber tf =
      nh.subscribe<tf2_msgs::TFMessage>("/tf", 100, [&](const tf2_msgs::TFMessageConstPtr& m) {
        for (const auto& t : m->transforms)
          if (t.header.frame_id == "front_map") tf_stamps.insert(t.header.stamp.toNSec());
      });
  int starts_over = 0;
  ros::Subscriber rosout =
      nh.subscribe<rosgraph_msgs::Log>("/rosout", 100, [&](const rosgraph_msgs::LogConstPtr& m) {
        starts_over += m->name.rfind("/front/", 0) == 0 &&
                       m->msg.find("the map starts over") != std::string::npos;
      });
  DiagnosticsProbe status(nh, "front/plane_detector: planes");
  spinUntil(
      [&] {
        return tracks.getNumSubscribers() > 0 && planes.sub.getNumPublishers() > 0 &&
               tf.getNumPublishers() > 0;
      },
      10.0);
  ASSERT_TRUE(status.waitFresh());  // (and /rosout linked meanwhile)
  const long backwards = status.number("resets: time went backwards (total)");
  auto sendAt = [&](int k, double clock_t) {  // tracks of image k, /clock at clock_t
    rosgraph_msgs::Clock now;
    now.clock = ros::Time(front.frame(clock_t).stamp);
    clock.publish(now);
    ros::WallDuration(0.02).sleep();
    const TrackFrame f = front.frame(k / 30.0);
    // A later loop has the same stamps: wait for this answer, not the last loop's.
    planes.by_stamp.erase(ros::Time(f.stamp).toNSec());
    tracks.publish(toTracks(f, "front_optical"));
    return planes.wait(ros::Time(f.stamp));
  };
  // The end of the first loop (the test above stopped at image 480): tf as usual.
  PlaneArrayConstPtr last;
  for (int k = 480; k < 486; ++k) ASSERT_TRUE(last = sendAt(k, k / 30.0)) << k;
  ASSERT_TRUE(last->metric) << last->status;
  spinUntil([&] { return tf_stamps.count(last->header.stamp.toNSec()) > 0; }, 3.0);
  EXPECT_TRUE(tf_stamps.count(last->header.stamp.toNSec())) << "no tf for the loop's images";
  int end = 486;  // the previous loop's last image + 1
  for (int loop = 1; loop <= 2; ++loop) {
    // The clock goes back to the start; tracks of the previous loop's last image come late.
    const PlaneArrayConstPtr late = sendAt(end, 0.0);
    ASSERT_TRUE(late) << "loop " << loop;
    for (int k = 0; k < 10; ++k)
      ASSERT_TRUE(sendAt(k, k / 30.0)) << "loop " << loop << " image " << k;
    spinUntil([&] { return starts_over >= loop; }, 3.0);
    EXPECT_EQ(starts_over, loop) << "\"the map starts over\" in loop " << loop;
    EXPECT_FALSE(tf_stamps.count(late->header.stamp.toNSec()))
        << "tf with the previous loop's stamp, loop " << loop;
    end = 240;  // a loop of 8 s: metric again by its end (the stale tracks above were)
    for (int k = 10; k < end; ++k)
      ASSERT_TRUE(last = sendAt(k, k / 30.0)) << "loop " << loop << " image " << k;
    EXPECT_TRUE(last->metric) << "loop " << loop << ": " << last->status;
    spinUntil([&] { return tf_stamps.count(last->header.stamp.toNSec()) > 0; }, 3.0);
    EXPECT_TRUE(tf_stamps.count(last->header.stamp.toNSec())) << "no tf again in loop " << loop;
  }
  ASSERT_TRUE(status.waitFresh());
  EXPECT_EQ(status.number("resets: time went backwards (total)"), backwards + 2);
}

// Every transform on /tf and /tf_static: the parents of each child, and who sent what.
struct TfRecorder {
  std::map<std::string, std::set<std::string>> parents;             // child -> parents
  std::map<std::string, std::set<std::string>> edges_by_publisher;  // node -> "a -> b"
  ros::Subscriber tf, tf_static;
  explicit TfRecorder(ros::NodeHandle& nh) {
    tf = nh.subscribe("/tf", 100, &TfRecorder::record, this);
    tf_static = nh.subscribe("/tf_static", 100, &TfRecorder::record, this);
  }
  // A MessageEvent member: it carries the publisher's name (connection header).
  void record(const ros::MessageEvent<tf2_msgs::TFMessage const>& event) {
    for (const auto& t : event.getMessage()->transforms) {
      parents[t.child_frame_id].insert(t.header.frame_id);
      edges_by_publisher[event.getPublisherName()].insert(t.header.frame_id + " -> " +
                                                          t.child_frame_id);
    }
  }
};

TEST(TfTree, StaysATreeWithOdometry) {
  ros::NodeHandle nh, pnh("~");
  bool localiser = false, late_localiser = false;
  pnh.param("localiser", localiser, false);
  pnh.param("late_localiser", late_localiser, false);
  TfRecorder recorder(nh);
  SyntheticTracks world("wheeled");
  ros::Publisher tracks = nh.advertise<Tracks>("/camera/tracks", 20);
  ros::Publisher info = nh.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 1, true);
  ros::Publisher conflict_tracks = nh.advertise<Tracks>("/conflict/tracks", 20);
  ros::Publisher conflict_info =
      nh.advertise<sensor_msgs::CameraInfo>("/conflict/camera_info", 1, true);
  ros::Publisher rigid_tracks = nh.advertise<Tracks>("/rigid/tracks", 20);
  ros::Publisher rigid_info = nh.advertise<sensor_msgs::CameraInfo>("/rigid/camera_info", 1, true);
  ros::Publisher duplicate_tracks = nh.advertise<Tracks>("/duplicate/tracks", 20);
  ros::Publisher duplicate_info =
      nh.advertise<sensor_msgs::CameraInfo>("/duplicate/camera_info", 1, true);
  Answers planes(nh, "/camera/planes"), conflict_planes(nh, "/conflict/planes"),
      rigid_planes(nh, "/rigid/planes"), duplicate_planes(nh, "/duplicate/planes");
  tf2_ros::Buffer buffer;
  tf2_ros::TransformListener listener(buffer);
  tf2_ros::TransformBroadcaster broadcaster;
  tf2_ros::StaticTransformBroadcaster urdf;
  // The robot's URDF: the camera 0.3 m ahead of and 1.0 m above base_link, looking
  // forward (optical frame: z forward, x right, y down).
  const Pose base_from_camera{cv::Matx33d(0, 0, 1, -1, 0, 0, 0, -1, 0), {0.3, 0, 1.0}};
  geometry_msgs::TransformStamped mount;
  mount.header.stamp = ros::Time::now();
  mount.header.frame_id = "base_link";
  mount.child_frame_id = "camera_optical";
  mount.transform = toTransformMsg(base_from_camera);
  urdf.sendTransform(mount);
  info.publish(cameraInfo(world.camera, world.camera, "camera_optical"));
  conflict_info.publish(cameraInfo(world.camera, world.camera, "camera_optical"));
  rigid_info.publish(cameraInfo(world.camera, world.camera, "camera_optical"));
  duplicate_info.publish(cameraInfo(world.camera, world.camera, "camera_optical"));
  spinUntil(
      [&] {
        return tracks.getNumSubscribers() > 0 && conflict_tracks.getNumSubscribers() > 0 &&
               rigid_tracks.getNumSubscribers() > 0 && duplicate_tracks.getNumSubscribers() > 0 &&
               planes.sub.getNumPublishers() > 0 && duplicate_planes.sub.getNumPublishers() > 0 &&
               conflict_planes.sub.getNumPublishers() > 0 &&
               rigid_planes.sub.getNumPublishers() > 0;
      },
      30.0);
  ASSERT_GT(tracks.getNumSubscribers(), 0u);
  ASSERT_GT(conflict_tracks.getNumSubscribers(), 0u);
  scaledWait(1.0).sleep();  // the static tree reaches the nodelets' tf listeners

  // Odometry: the truth seen from an odometry origin 1 m aside and turned 0.3 rad about z
  // (odom is z up: REP 105); another localiser's map -> odom is a fixed shift.
  const Pose ros_from_target = rosMapFromTarget();
  const Pose odom_from_rosmap{
      cv::Matx33d(std::cos(0.3), -std::sin(0.3), 0, std::sin(0.3), std::cos(0.3), 0, 0, 0, 1),
      {1, 0.5, 0}};
  const Pose amcl_map_from_odom{cv::Matx33d::eye(), {-2, 3, 0}};
  const ros::Time start = ros::Time::now();
  PlaneArrayConstPtr last;
  Pose truth_map_from_base;
  ros::Time last_stamp;
  bool amcl_on = localiser;  // another localiser's map -> odom sent with the odometry
  // Image k of the path, stamped `later` images on (the path again after a ~reset).
  auto sendFrame = [&](int k, int later = 0) {
    const double t = k / 30.0;
    TrackFrame f = world.frame(t);
    f.stamp = (start + ros::Duration((k + later) / 30.0)).toSec();
    const ros::Time stamp(f.stamp);  // what the tracks carry: the same nanoseconds on tf
    truth_map_from_base =
        ros_from_target * world.truthMapFromCamera(t) * base_from_camera.inverse();
    std::vector<geometry_msgs::TransformStamped> out;
    geometry_msgs::TransformStamped odom;
    odom.header.stamp = stamp;
    odom.header.frame_id = "odom";
    odom.child_frame_id = "base_link";
    odom.transform = toTransformMsg(odom_from_rosmap * truth_map_from_base);
    out.push_back(odom);
    if (amcl_on) {
      geometry_msgs::TransformStamped amcl;
      amcl.header.stamp = stamp;
      amcl.header.frame_id = "map";
      amcl.child_frame_id = "odom";
      amcl.transform = toTransformMsg(amcl_map_from_odom);
      out.push_back(amcl);
    }
    // The robot's odometry lags the camera: tf for this stamp comes after the tracks
    // (the pipeline waits for it, odom_wait_s; it took "visual pose only" before).
    tracks.publish(toTracks(f, "camera_optical"));
    conflict_tracks.publish(toTracks(f, "camera_optical"));
    rigid_tracks.publish(toTracks(f, "camera_optical"));
    duplicate_tracks.publish(toTracks(f, "camera_optical"));
    ros::WallDuration(0.02).sleep();
    broadcaster.sendTransform(out);
    last = planes.wait(stamp);
    ASSERT_TRUE(last) << "image " << k;
    ASSERT_TRUE(conflict_planes.wait(stamp)) << "image " << k;
    ASSERT_TRUE(rigid_planes.wait(stamp)) << "image " << k;
    ASSERT_TRUE(duplicate_planes.wait(stamp)) << "image " << k;
    last_stamp = stamp;
  };
  int with_odometry = 0, without_after_start = 0;  // images once the start placed the map
  for (int k = 0; k < 150; ++k) {
    sendFrame(k);
    if (HasFatalFailure()) return;
    if (last->status.rfind("tracking (odometry)", 0) == 0)  // (a suffix may follow)
      ++with_odometry;
    else if (with_odometry > 0)
      ++without_after_start;
  }
  EXPECT_EQ(last->status.rfind("tracking (odometry)", 0), 0u) << last->status;
  EXPECT_GT(with_odometry, 60);
  EXPECT_LE(without_after_start, 2);     // a loaded machine may miss the wait now and then
  spinUntil([] { return false; }, 1.0);  // the last transforms arrive

  // A tree: every frame has one parent, the robot's frames keep theirs.
  for (const auto& [child, set] : recorder.parents) {
    EXPECT_EQ(set.size(), 1u) << child << " has " << set.size() << " parents";
  }
  EXPECT_EQ(*recorder.parents["camera_optical"].begin(), "base_link");
  EXPECT_EQ(*recorder.parents["base_link"].begin(), "odom");
  for (const auto& [node, edges] : recorder.edges_by_publisher)
    for (const auto& edge : edges) std::printf("tf from %s: %s\n", node.c_str(), edge.c_str());
  // Only the one link from the pipeline's manager; nothing from the refusing one.
  const std::set<std::string> ours = recorder.edges_by_publisher["/camera/plane_detection_manager"];
  ASSERT_EQ(ours.size(), 1u);
  EXPECT_EQ(*ours.begin(), localiser ? "odom -> plane_map" : "plane_map -> odom");
  EXPECT_EQ(recorder.edges_by_publisher.count("/conflict/manager"), 0u);
  EXPECT_EQ(recorder.edges_by_publisher.count("/rigid/manager"), 0u);
  EXPECT_EQ(recorder.edges_by_publisher.count("/duplicate/manager"), 0u);
  {
    // odom_frame:=base_link: no odometry taken from a frame rigid with the camera.
    DiagnosticsProbe rigid(nh, "rigid/plane_detector: planes");
    ASSERT_TRUE(rigid.waitFresh());
    EXPECT_EQ(rigid.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << rigid.message();
    EXPECT_NE(rigid.value("problem: odometry").find("rigidly attached"), std::string::npos)
        << rigid.value("problem: odometry");
    const PlaneArrayConstPtr r = rigid_planes.by_stamp.rbegin()->second;
    EXPECT_NE(r->status.rfind("tracking (odometry)", 0), 0u) << r->status;
  }
  // plane_map -> base_link through tf, against the truth.
  ASSERT_TRUE(buffer.canTransform("plane_map", "base_link", last_stamp, ros::Duration(2.0)));
  const Pose through_tf =
      fromTransformMsg(buffer.lookupTransform("plane_map", "base_link", last_stamp).transform);
  const double error = cv::norm(through_tf.t - truth_map_from_base.t);
  std::printf("plane_map -> base_link via tf: %.3f m from the truth\n", error);
  EXPECT_LT(error, 0.1);
  const cv::Matx33d dR = through_tf.R.t() * truth_map_from_base.R;
  EXPECT_GT((dR.val[0] + dR.val[4] + dR.val[8] - 1) / 2, std::cos(3 * CV_PI / 180));
  if (localiser) {
    std::string parent;
    ASSERT_TRUE(buffer._getParent("odom", ros::Time(0), parent));
    EXPECT_EQ(parent, "map");  // the localiser's link is untouched
  }

  // After another's link to odom: images 150-169 sent, none of our plane_map -> odom
  // stamped after `after` heard, and an ERROR that names the second parent.
  auto expectOurLinkRefused = [&](const ros::Time& after, const std::string& beside) {
    int ours = 0, heard = 0;  // (heard: the subscriber is connected, odometry flows)
    ros::Subscriber tf_sub =
        nh.subscribe<tf2_msgs::TFMessage>("/tf", 100, [&](const tf2_msgs::TFMessageConstPtr& m) {
          for (const auto& t : m->transforms) {
            ++heard;
            ours += t.child_frame_id == "odom" && t.header.frame_id == "plane_map" &&
                    t.header.stamp > after;
          }
        });
    for (int k = 150; k < 170; ++k) {
      sendFrame(k);
      if (HasFatalFailure()) return;
    }
    spinUntil([] { return false; }, 1.0);
    EXPECT_GT(heard, 0) << "no /tf heard: the check below would say nothing";
    EXPECT_EQ(ours, 0) << "plane_map -> odom still published " << beside;
    DiagnosticsProbe camera(nh, "camera/plane_detector: planes");
    ASSERT_TRUE(camera.waitFresh());
    EXPECT_EQ(camera.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << camera.message();
    EXPECT_NE(camera.message().find("second parent"), std::string::npos) << camera.message();
  };
  if (late_localiser) {
    // Another localiser (AMCL) that starts after the pipeline's plane_map -> odom: its
    // dynamic map -> odom gives odom a second parent. The nodelet must stop publishing
    // with an ERROR; after ~reset, tf_mode auto sees the localiser's parent (newer stamps
    // than ours) and attaches odom -> plane_map below it.
    amcl_on = true;
    // (From the localiser's second image: its first may meet our link of the same stamp.)
    expectOurLinkRefused(start + ros::Duration(151 / 30.0), "beside the localiser's map -> odom");
    if (HasFatalFailure()) return;
    DiagnosticsProbe camera(nh, "camera/plane_detector: planes");

    std_srvs::Empty reset;
    ASSERT_TRUE(ros::service::call("/camera/plane_detector/reset", reset));
    int above_after = 0, below_after = 0;
    ros::Subscriber after_sub =
        nh.subscribe<tf2_msgs::TFMessage>("/tf", 100, [&](const tf2_msgs::TFMessageConstPtr& m) {
          for (const auto& t : m->transforms) {
            above_after += t.child_frame_id == "odom" && t.header.frame_id == "plane_map";
            below_after += t.child_frame_id == "plane_map" && t.header.frame_id == "odom";
          }
        });
    for (int k = 0; k < 150; ++k) {  // the path again (the map starts over), stamps on
      sendFrame(k, 170);
      if (HasFatalFailure()) return;
    }
    spinUntil([] { return false; }, 1.0);
    EXPECT_EQ(above_after, 0) << "plane_map -> odom published again after the reset";
    EXPECT_GT(below_after, 60) << "odom -> plane_map not published below the localiser";
    ASSERT_TRUE(camera.waitFresh());
    EXPECT_NE(camera.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << camera.message();
    // The listeners see one tree: the localiser's map above odom, the planes' map below it.
    std::string parent;
    ASSERT_TRUE(buffer._getParent("odom", ros::Time(0), parent));
    EXPECT_EQ(parent, "map");
    ASSERT_TRUE(buffer._getParent("plane_map", ros::Time(0), parent));
    EXPECT_EQ(parent, "odom");
    EXPECT_TRUE(buffer.canTransform("map", "plane_map", ros::Time(0)));
  } else if (!localiser) {
    // A static map -> odom that comes after the pipeline's plane_map -> odom (a
    // static_transform_publisher started later). tf2 hides a late static parent behind
    // the dynamic link to the same frame; odom got two parents, silently (hostile try).
    // The nodelet must stop publishing, with an ERROR that says why.
    geometry_msgs::TransformStamped late;
    // Stamped 0, as a static_transform_publisher started under simulated time before
    // /clock stamps it: tf2 drops it from odom's cache (older than our links), so only
    // /tf_static shows it.
    late.header.stamp = ros::Time(0);
    late.header.frame_id = "map";
    late.child_frame_id = "odom";
    late.transform = toTransformMsg(amcl_map_from_odom);
    urdf.sendTransform(late);  // the broadcaster keeps the URDF's mount as well
    scaledWait(1.0).sleep();
    expectOurLinkRefused(start + ros::Duration(149 / 30.0), "beside the static map -> odom");
    if (HasFatalFailure()) return;
    DiagnosticsProbe camera(nh, "camera/plane_detector: planes");
    int ours_after = 0;

    // ~reset: auto mode now sees the static parent (below_odom), but odom -> plane_map would
    // loop through our earlier plane_map -> odom, which the tf listeners keep (they dropped
    // the late static link): nothing is published, and the ERROR says how to get out
    // (before, the reset chose plane_map -> odom again and hit the same conflict).
    std_srvs::Empty reset;
    ASSERT_TRUE(ros::service::call("/camera/plane_detector/reset", reset));
    int below_after = 0;
    ros::Subscriber below_sub =
        nh.subscribe<tf2_msgs::TFMessage>("/tf", 100, [&](const tf2_msgs::TFMessageConstPtr& m) {
          for (const auto& t : m->transforms) {
            ours_after += t.child_frame_id == "odom" && t.header.frame_id == "plane_map";
            below_after += t.child_frame_id == "plane_map";
          }
        });
    // The path again from its start (the target in view: the map starts over), stamps on.
    for (int k = 0; k < 150; ++k) {
      sendFrame(k, 170);
      if (HasFatalFailure()) return;
    }
    spinUntil([] { return false; }, 1.0);
    EXPECT_EQ(ours_after, 0) << "plane_map -> odom published again after the reset";
    EXPECT_EQ(below_after, 0) << "odom -> plane_map published: a loop for the listeners";
    ASSERT_TRUE(camera.waitFresh());
    EXPECT_EQ(camera.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << camera.message();
    EXPECT_NE(camera.message().find("tf_mode:=below_odom"), std::string::npos) << camera.message();
  }

  // The nodelet told to publish the camera's own frame refused, loudly.
  DiagnosticsProbe conflict(nh, "conflict/plane_detector: planes");
  ASSERT_TRUE(conflict.waitFresh());
  EXPECT_EQ(conflict.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << conflict.message();
  EXPECT_NE(conflict.message().find("second parent"), std::string::npos) << conflict.message();

  // The nodelet told to publish a link the URDF already sends: refused, and said so.
  DiagnosticsProbe duplicate(nh, "duplicate/plane_detector: planes");
  ASSERT_TRUE(duplicate.waitFresh());
  EXPECT_EQ(duplicate.level(), diagnostic_msgs::DiagnosticStatus::ERROR) << duplicate.message();
  EXPECT_NE(duplicate.message().find("'base_link -> camera_optical' is already on tf_static"),
            std::string::npos)
      << duplicate.message();
}

// Two pipelines with one map_frame (tf_shared_map.test): each WARNs, naming the other's link;
// a static frame hung under a map_frame on purpose is no other pipeline.
TEST(SharedMapFrame, TwoPipelinesInOneMapFrameAreTold) {
  ros::NodeHandle nh;
  SyntheticTracks world("wheeled");
  const std::vector<std::string> robots{"robot1", "robot2", "robot3"};
  std::vector<ros::Publisher> tracks, infos;
  std::vector<std::unique_ptr<Answers>> planes;
  for (const std::string& r : robots) {
    tracks.push_back(nh.advertise<Tracks>("/" + r + "/tracks", 20));
    infos.push_back(nh.advertise<sensor_msgs::CameraInfo>("/" + r + "/camera_info", 1, true));
    infos.back().publish(cameraInfo(world.camera, world.camera, r + "/camera_optical"));
    planes.push_back(std::make_unique<Answers>(nh, "/" + r + "/planes"));
  }
  spinUntil(
      [&] {
        for (size_t i = 0; i < robots.size(); ++i)
          if (tracks[i].getNumSubscribers() == 0 || planes[i]->sub.getNumPublishers() == 0)
            return false;
        return true;
      },
      30.0);
  // robot3's ground truth hung under its map, as ground_truth_frame does: static.
  tf2_ros::StaticTransformBroadcaster hanger;
  geometry_msgs::TransformStamped truth;
  truth.header.stamp = ros::Time::now();
  truth.header.frame_id = "robot3/plane_map";
  truth.child_frame_id = "robot3/truth";
  truth.transform.rotation.w = 1.0;
  hanger.sendTransform(truth);
  const ros::Time start = ros::Time::now();
  for (int k = 0; k < 120; ++k) {
    TrackFrame f = world.frame(k / 30.0);
    f.stamp = (start + ros::Duration(k / 30.0)).toSec();
    for (size_t i = 0; i < robots.size(); ++i)
      tracks[i].publish(toTracks(f, robots[i] + "/camera_optical"));
    for (size_t i = 0; i < robots.size(); ++i)
      ASSERT_TRUE(planes[i]->wait(ros::Time(f.stamp))) << robots[i] << " image " << k;
  }
  const PlaneArrayConstPtr last = planes[0]->by_stamp.rbegin()->second;
  ASSERT_EQ(last->status.rfind("tracking", 0), 0u) << last->status;  // a map on tf
  for (const std::string& r : {std::string("robot1"), std::string("robot2")}) {
    const std::string other = r == "robot1" ? "robot2" : "robot1";
    DiagnosticsProbe probe(nh, r + "/plane_detector: planes");
    ASSERT_TRUE(probe.waitFresh());
    EXPECT_EQ(probe.level(), diagnostic_msgs::DiagnosticStatus::WARN) << probe.message();
    const std::string tf = probe.value("problem: tf");
    EXPECT_NE(tf.find("map_frame 'plane_map' also holds plane_map -> " + other +
                      "/camera_optical_estimate"),
              std::string::npos)
        << tf;
    EXPECT_NE(tf.find("give each camera its own map_frame"), std::string::npos) << tf;
  }
  DiagnosticsProbe own(nh, "robot3/plane_detector: planes");
  ASSERT_TRUE(own.waitFresh());
  EXPECT_EQ(own.level(), diagnostic_msgs::DiagnosticStatus::OK) << own.message();
  EXPECT_EQ(own.value("tf"), "robot3/plane_map -> robot3/camera_optical_estimate");
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_ros_interface");
  ros::NodeHandle nh;
  readTimeoutScale();
  return RUN_ALL_TESTS();
}
