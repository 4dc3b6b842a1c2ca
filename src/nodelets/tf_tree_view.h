// What the plane nodelet asks of the robot's tf tree before it reads odometry from it or
// adds a link to it (REP 105: one parent per frame, no loops): tf2's buffer, plus the
// static parents heard on /tf_static. tf2 keeps one cache per frame, so a static parent
// sent after a dynamic link to the same child (ours, before a ~reset) hides behind it
// there; only /tf_static shows it. No ROS master needed (tested on a tf2::BufferCore).
#pragma once

#include <tf2/buffer_core.h>
#include <tf2_msgs/TFMessage.h>

#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace mono_plane_detection {

class TfTreeView {
 public:
  explicit TfTreeView(const tf2::BufferCore& buffer) : buffer_(buffer) {}

  // A /tf_static message: its links' parents are kept (latched, one message per publisher).
  void noteStatic(const tf2_msgs::TFMessage& msg);
  // frame's parent on /tf_static, as heard (tf2 may have dropped it: see above).
  std::optional<std::string> staticParent(const std::string& frame) const;

  // frame, its parent on tf (latest), that one's, ... up to the root (at most 64).
  std::vector<std::string> ancestors(const std::string& frame) const;
  // The links on tf from the camera up to odom_frame that have no transform at stamp
  // ("parent -> child, ..."), "" when none is found: with a head on joints, joint states
  // that stopped hold the images back as odometry that stopped would.
  std::string staleLinks(const std::string& camera, const std::string& odom_frame,
                         const ros::Time& stamp) const;
  // odom_frame reached from the camera by static links only (/tf_static: a URDF's mount,
  // e.g. odom_frame:=base_link), or the camera frame itself: it moves with the camera, so
  // its "odometry" would say the camera never moves, and plane_map -> base_link would give
  // the robot's frame a second parent. Why, or "" when odom_frame is not such a frame.
  std::string rigidOdomFrame(const std::string& camera, const std::string& odom_frame) const;
  // Why tf cannot link odom_frame to the camera at any time, "" when it can (then only an
  // image's stamp is missing: odometry stopped or late). A camera frame that is not a
  // frame of the robot's tf (a driver's frame_id against another URDF name) is not the
  // odometry's fault.
  std::string odometryProblem(const std::string& camera, const std::string& odom_frame) const;
  // Why publishing parent -> child would break the tree, "" when it would not. tf2 keeps
  // the latest parent of each frame: another broadcaster of `child` shows as another
  // parent, or, before our first transform, as the same edge already there.
  // published: the links this nodelet has put on tf ("parent -> child").
  std::string conflict(const std::string& parent, const std::string& child,
                       const std::set<std::string>& published) const;
  // The links on /tf (dynamic: a static one, e.g. ground_truth_frame's or a user's marker
  // frame, is hung there on purpose) into or out of `frame` that this nodelet did not
  // publish ("parent -> child"): another pipeline publishing into the same map_frame puts
  // a map with an unrelated origin there (hostile try: two robots, both plane_map).
  std::vector<std::string> foreignLinks(const std::string& frame,
                                        const std::set<std::string>& published) const;

 private:
  // ", and dropped the static parent 'p' of 'frame' sent after it" when /tf_static has one.
  std::string staticParentNote(const std::string& frame) const;

  const tf2::BufferCore& buffer_;
  mutable std::mutex mutex_;                           // static_parents_ (tf_static callback)
  std::map<std::string, std::string> static_parents_;  // child -> parent on /tf_static
};

}  // namespace mono_plane_detection
