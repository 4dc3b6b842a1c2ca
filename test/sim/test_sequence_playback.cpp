// A bag from writeSequence played by `rosbag play`: every image, camera_info and tf
// arrives, in order, with its stamp.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <cstdlib>
#include <thread>

#include "../../src/sim/bag/sequence_writer.h"
#include "mono_plane_detection/ros/map_frame.h"
#include "mono_plane_detection/ros/pose_msg.h"
#include "support/test_timeouts.h"
#include "support/temp_path.h"

using namespace mono_plane_detection;

TEST(SequencePlayback, RosbagPlayDeliversEverything) {
  SequenceSpec spec;
  spec.frames = 30;
  spec.camera.size = {320, 240};
  spec.camera.fx = spec.camera.fy = 262.5;
  spec.camera.cx = 159.5;
  spec.camera.cy = 119.5;
  const std::string bag = tempPath("playback.bag");
  writeSequence(spec, bag, tempPath("playback.yaml"));

  ros::NodeHandle nh;
  std::vector<double> image_stamps;
  int infos = 0, tfs = 0;
  auto on_image = [&](const sensor_msgs::ImageConstPtr& m) {
    image_stamps.push_back(m->header.stamp.toSec());
  };
  ros::Subscriber images = nh.subscribe<sensor_msgs::Image>("/camera/image_raw", 100, on_image);
  ros::Subscriber info = nh.subscribe<sensor_msgs::CameraInfo>(
      "/camera/camera_info", 100, [&](const sensor_msgs::CameraInfoConstPtr&) { ++infos; });
  ros::Subscriber tf = nh.subscribe<tf2_msgs::TFMessage>(
      "/tf", 100, [&](const tf2_msgs::TFMessageConstPtr&) { ++tfs; });
  tf2_ros::Buffer buffer(ros::Duration(100));
  tf2_ros::TransformListener listener(buffer);

  // -d 2: rosbag play waits after advertising so that the subscribers connect.
  std::thread player([&] { EXPECT_EQ(std::system(("rosbag play -q -d 2 " + bag).c_str()), 0); });
  spinUntil([&] { return image_stamps.size() >= 30; }, 30.0);
  player.join();
  ros::spinOnce();
  ASSERT_EQ(image_stamps.size(), 30u);
  for (size_t k = 0; k < image_stamps.size(); ++k)
    EXPECT_NEAR(image_stamps[k], 1000.0 + k / 30.0, 1e-6);
  EXPECT_EQ(infos, 30);
  EXPECT_EQ(tfs, 30);
  // ground_truth_frame (sequence_playback.test) joins the bag's tree to plane_map: the
  // last true camera, seen from plane_map, is the ground truth turned into z up.
  const IndoorScene scene = makeRoom(spec.room);
  const Pose expected = rosMapFromTarget() * groundTruthPose(spec, scene, 29);
  geometry_msgs::TransformStamped seen;
  ASSERT_NO_THROW(seen = buffer.lookupTransform("plane_map", "camera_gt",
                                                ros::Time(1000.0 + 29 / 30.0), ros::Duration(5)));
  const Pose got = fromTransformMsg(seen.transform);
  EXPECT_LT(cv::norm(got.t - expected.t), 1e-6);
  EXPECT_LT(cv::norm(cv::Mat(got.R - expected.R)), 1e-6);
  EXPECT_LT(got.t[0], -1.0) << "in front of the target's wall: plane_map's x points into it";
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_sequence_playback");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
