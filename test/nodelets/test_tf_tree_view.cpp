// The plane nodelet's questions to the robot's tf tree (src/nodelets/tf_tree_view.h),
// asked of a tf2 buffer filled by hand: no ROS master. The rostests (tf_tree.test,
// plane_nodelet.test Q2, tf_late_localiser.test) ask them through a running tf.
#include <gtest/gtest.h>

#include "../../src/nodelets/tf_tree_view.h"

using namespace mono_plane_detection;

namespace {

geometry_msgs::TransformStamped link(const std::string& parent, const std::string& child,
                                     double stamp) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.header.stamp = ros::Time(stamp);
  t.child_frame_id = child;
  t.transform.rotation.w = 1.0;
  t.transform.translation.x = 0.1;
  return t;
}

// A robot: odom -> base_link (odometry, dynamic), base_link -> camera (static, the URDF's
// mount), as tf2 holds it and as /tf_static told the view.
struct Robot {
  tf2::BufferCore buffer;
  TfTreeView view{buffer};
  Robot() {
    for (double t : {1.0, 2.0, 3.0}) buffer.setTransform(link("odom", "base_link", t), "odometry");
    addStatic("base_link", "camera");
  }
  void addStatic(const std::string& parent, const std::string& child) {
    buffer.setTransform(link(parent, child, 0.0), "urdf", true);
    tf2_msgs::TFMessage msg;
    msg.transforms.push_back(link("/" + parent, child, 0.0));  // a leading '/' as ROS 1 allowed
    view.noteStatic(msg);
  }
};

}  // namespace

TEST(TfTreeView, AncestorsGoUpToTheRoot) {
  Robot robot;
  EXPECT_EQ(robot.view.ancestors("camera"),
            (std::vector<std::string>{"camera", "base_link", "odom"}));
  EXPECT_EQ(robot.view.ancestors("nowhere"), std::vector<std::string>{"nowhere"});
  EXPECT_EQ(robot.view.staticParent("camera"), std::optional<std::string>("base_link"));
  EXPECT_FALSE(robot.view.staticParent("base_link"));
}

TEST(TfTreeView, OdomFrameRigidWithTheCameraIsNamed) {
  Robot robot;
  EXPECT_EQ(robot.view.rigidOdomFrame("camera", "odom"), "");
  const std::string mount = robot.view.rigidOdomFrame("camera", "base_link");
  EXPECT_NE(mount.find("rigidly attached to the camera frame 'camera'"), std::string::npos)
      << mount;
  EXPECT_NE(robot.view.rigidOdomFrame("camera", "camera").find("the camera frame itself"),
            std::string::npos);
}

TEST(TfTreeView, OdometryProblemsSayWhatIsMissing) {
  Robot robot;
  EXPECT_EQ(robot.view.odometryProblem("camera", "odom"), "");
  EXPECT_NE(robot.view.odometryProblem("", "odom").find("empty frame_id"), std::string::npos);
  EXPECT_NE(robot.view.odometryProblem("camera_optical", "odom").find("is not in the tf tree"),
            std::string::npos);
  const std::string no_odom = robot.view.odometryProblem("camera", "map");
  EXPECT_NE(no_odom.find("'map' is not on tf"), std::string::npos) << no_odom;
  // Where the camera's tf goes instead (a namespaced robot1/odom against odom).
  EXPECT_NE(no_odom.find("the camera's tf goes up to 'odom'"), std::string::npos) << no_odom;
  // A head on joints whose publisher has not sent yet: the chain ends at 'head'.
  robot.addStatic("head", "head_camera");
  robot.buffer.setTransform(link("map", "elsewhere", 1.0), "other");
  const std::string cut = robot.view.odometryProblem("head_camera", "odom");
  EXPECT_NE(cut.find("its tf goes up to 'head' only"), std::string::npos) << cut;
}

TEST(TfTreeView, StaleLinksAreTheOnesWithoutTheStamp) {
  Robot robot;
  // Joint states up to t = 2 only, odometry up to 3.
  for (double t : {1.0, 2.0}) robot.buffer.setTransform(link("base_link", "neck", t), "joints");
  robot.addStatic("neck", "eye");
  EXPECT_EQ(robot.view.staleLinks("eye", "odom", ros::Time(1.5)), "");
  EXPECT_EQ(robot.view.staleLinks("eye", "odom", ros::Time(2.5)), "base_link -> neck");
  EXPECT_EQ(robot.view.staleLinks("eye", "odom", ros::Time(3.5)),
            "base_link -> neck, odom -> base_link");
}

TEST(TfTreeView, ConflictsThatWouldBreakTheTree) {
  Robot robot;
  const std::set<std::string> none;
  // Above the odometry: fine; below it, a frame of nobody's: fine.
  EXPECT_EQ(robot.view.conflict("plane_map", "odom", none), "");
  EXPECT_EQ(robot.view.conflict("odom", "plane_map", none), "");
  // A second parent, dynamic or static, and a link someone else already publishes.
  EXPECT_NE(robot.view.conflict("plane_map", "base_link", none)
                .find("already has the parent 'odom' on tf"),
            std::string::npos);
  EXPECT_NE(robot.view.conflict("plane_map", "camera", none).find("has the static parent"),
            std::string::npos);
  EXPECT_NE(robot.view.conflict("base_link", "camera", none).find("two sources of one link"),
            std::string::npos);
  EXPECT_NE(robot.view.conflict("odom", "base_link", none).find("from another broadcaster"),
            std::string::npos);
  EXPECT_EQ(robot.view.conflict("odom", "base_link", {"odom -> base_link"}), "");  // our own
  // A loop: the child is above the parent.
  EXPECT_NE(robot.view.conflict("base_link", "odom", none).find("would make a loop"),
            std::string::npos);
}

TEST(TfTreeView, ALoopThroughOurOwnEarlierLinkSaysHowToClearIt) {
  tf2::BufferCore buffer;
  TfTreeView view(buffer);
  // Ours: plane_map -> odom; then a localiser's static map -> odom came after it and tf2
  // dropped it; now below_odom would publish odom -> plane_map.
  buffer.setTransform(link("plane_map", "odom", 1.0), "us");
  tf2_msgs::TFMessage late;
  late.transforms.push_back(link("map", "odom", 0.0));
  view.noteStatic(late);
  const std::string why = view.conflict("odom", "plane_map", {"plane_map -> odom"});
  EXPECT_NE(why.find("would make a loop"), std::string::npos) << why;
  EXPECT_NE(why.find("dropped the static parent 'map' of 'odom' sent after it"), std::string::npos)
      << why;
  // Without the static one: the loop through our earlier link, and what to do.
  tf2::BufferCore buffer2;
  TfTreeView view2(buffer2);
  buffer2.setTransform(link("plane_map", "odom", 1.0), "us");
  const std::string loop = view2.conflict("odom", "plane_map", {"plane_map -> odom"});
  EXPECT_NE(loop.find("through this nodelet's earlier plane_map -> odom"), std::string::npos)
      << loop;
  EXPECT_NE(loop.find("restart the pipeline"), std::string::npos) << loop;
  EXPECT_EQ(loop.find("dropped the static parent"), std::string::npos) << loop;
}

TEST(TfTreeView, ForeignLinksOfAMapFrameAreOthersDynamicOnes) {
  Robot robot;
  // Ours: plane_map -> odom. Another pipeline's: plane_map -> robot2/odom (dynamic). A
  // frame hung under plane_map on purpose: plane_map -> truth (static).
  robot.buffer.setTransform(link("plane_map", "odom", 2.0), "us");
  EXPECT_TRUE(robot.view.foreignLinks("plane_map", {"plane_map -> odom"}).empty());
  robot.addStatic("plane_map", "truth");
  EXPECT_TRUE(robot.view.foreignLinks("plane_map", {"plane_map -> odom"}).empty());
  robot.buffer.setTransform(link("plane_map", "robot2/odom", 2.0), "other");
  EXPECT_EQ(robot.view.foreignLinks("plane_map", {"plane_map -> odom"}),
            std::vector<std::string>{"plane_map -> robot2/odom"});
  // Another's parent of the map frame counts too.
  tf2::BufferCore buffer;
  TfTreeView view(buffer);
  buffer.setTransform(link("plane_map", "camera_estimate", 1.0), "us");
  buffer.setTransform(link("robot2/odom", "plane_map", 1.0), "other");
  EXPECT_EQ(view.foreignLinks("plane_map", {"plane_map -> camera_estimate"}),
            std::vector<std::string>{"robot2/odom -> plane_map"});
}
