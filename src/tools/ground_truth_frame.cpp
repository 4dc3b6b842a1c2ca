// Hangs make_sequence's ground truth under the pipeline's map frame, so that rviz shows the
// true camera beside the estimate and has no frame it cannot place: the bags' /tf holds
// `map -> camera_gt` with `map` the start-up target's frame (y up, the core's frame), one
// tree of its own. This node publishes the static turn between the two (rosMapFromTarget,
// ros/map_frame.h: the one the nodelets turn their outputs by). (Debian's tf2_ros ships no
// static_transform_publisher; Noetic's would need the quaternion written out again.)
//   rosrun mono_plane_detection ground_truth_frame --parent plane_map
#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <string>

#include "cli_args.h"
#include "mono_plane_detection/ros/map_frame.h"
#include "mono_plane_detection/ros/pose_msg.h"

using namespace mono_plane_detection;

int main(int argc, char** argv) {
  ros::init(argc, argv, "ground_truth_frame");
  std::string parent = "plane_map", child = "map";
  cli::Parser cli(
      "ground_truth_frame", "[options]",
      "  Publishes the static transform from the pipeline's map frame (z up, REP 103) to\n"
      "  make_sequence's ground-truth frame (the start-up target's frame, y up), so that a\n"
      "  generated bag's true camera (tf map -> camera_gt) joins the pipeline's tree. For a\n"
      "  target start (a camera_height map has its own origin and heading). Runs until\n"
      "  shut down.",
      "exit codes: 0 shut down, 2 bad usage\n");
  cli.text("parent", &parent, "the pipeline's map frame (replay.launch's map_frame)", "FRAME")
      .text("child", &child, "the ground truth's frame in the bag", "FRAME");
  if (const auto code = cli.parse(argc, argv)) return *code;
  if (parent.empty() || child.empty() || parent == child)
    return cli.fail("--parent and --child must be two frame names");
  ros::NodeHandle nh;
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time::now();
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform = toTransformMsg(rosMapFromTarget());
  tf2_ros::StaticTransformBroadcaster broadcaster;
  broadcaster.sendTransform(t);
  ros::spin();
  return 0;
}
