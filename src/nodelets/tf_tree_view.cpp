#include "tf_tree_view.h"

#include "camera_info_check.h"  // tfFrame

namespace mono_plane_detection {

void TfTreeView::noteStatic(const tf2_msgs::TFMessage& msg) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& t : msg.transforms)
    static_parents_[tfFrame(t.child_frame_id)] = tfFrame(t.header.frame_id);
}

std::optional<std::string> TfTreeView::staticParent(const std::string& frame) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = static_parents_.find(frame);
  if (it == static_parents_.end()) return {};
  return it->second;
}

std::vector<std::string> TfTreeView::ancestors(const std::string& frame) const {
  std::vector<std::string> chain{frame};
  std::string parent;
  while (chain.size() < 64 && buffer_._getParent(chain.back(), ros::Time(0), parent))
    chain.push_back(parent);
  return chain;
}

std::string TfTreeView::staleLinks(const std::string& camera, const std::string& odom_frame,
                                   const ros::Time& stamp) const {
  const std::vector<std::string> chain = ancestors(camera);
  std::string stale;
  for (size_t k = 0; k + 1 < chain.size() && chain[k] != odom_frame; ++k)
    if (!buffer_.canTransform(chain[k + 1], chain[k], stamp))
      stale += (stale.empty() ? "" : ", ") + chain[k + 1] + " -> " + chain[k];
  return stale;
}

std::string TfTreeView::rigidOdomFrame(const std::string& camera,
                                       const std::string& odom_frame) const {
  if (camera == odom_frame)
    return "odom_frame '" + odom_frame + "' is the camera frame itself: it is no odometry; " +
           "set odom_frame to the odometry's fixed frame (e.g. odom)";
  std::string frame = camera;
  for (int depth = 0; depth < 64; ++depth) {
    const std::optional<std::string> parent = staticParent(frame);
    if (!parent) return {};
    frame = *parent;
    if (frame == odom_frame)
      return "odom_frame '" + odom_frame + "' is rigidly attached to the camera frame '" + camera +
             "' (static transforms only, /tf_static): it moves with the camera, so "
             "it is no odometry; set odom_frame to the odometry's fixed frame (e.g. odom)";
  }
  return {};
}

std::string TfTreeView::odometryProblem(const std::string& camera,
                                        const std::string& odom_frame) const {
  const std::string fix =
      ": the images' header.frame_id must be a tf frame of the robot "
      "(its URDF), linked to odom_frame '" +
      odom_frame + "'";
  if (camera.empty()) return "the images have an empty frame_id" + fix;
  if (!buffer_._frameExists(camera))
    return "camera frame '" + camera + "' (the images' header.frame_id) is not in the tf tree" +
           fix;
  if (!buffer_._frameExists(odom_frame)) {
    // Where the camera's tree goes instead: a robot's namespaced odometry (robot1/odom).
    const std::string root = ancestors(camera).back();
    return "odom_frame '" + odom_frame + "' is not on tf: no odometry published (yet)" +
           (root != camera ? "; the camera's tf goes up to '" + root + "'" : std::string());
  }
  if (!buffer_.canTransform(odom_frame, camera, ros::Time(0))) {
    // Where the camera's chain ends: a URDF frame whose joint's publisher has not sent
    // yet (robot_state_publisher at start) is no wrong frame_id.
    return "camera frame '" + camera + "' (the images' header.frame_id) is not connected to " +
           "odom_frame '" + odom_frame + "' on tf (yet): its tf goes up to '" +
           ancestors(camera).back() +
           "' only; the link above that is missing (its publisher not running yet, e.g. "
           "robot_state_publisher, or the odometry's odom -> base_link), or the frame_id is "
           "not a frame of the robot's URDF";
  }
  return {};
}

std::string TfTreeView::conflict(const std::string& parent, const std::string& child,
                                 const std::set<std::string>& published) const {
  // We never publish static links: any static link to our child is another's.
  if (const std::optional<std::string> other = staticParent(child)) {
    if (*other == parent)
      return "'" + parent + " -> " + child +
             "' is already on tf_static from another broadcaster: publishing it too would "
             "give two sources of one link";
    return "frame '" + child + "' has the static parent '" + *other +
           "' on tf_static: publishing " + parent + " -> " + child +
           " would give it a second parent";
  }
  std::string existing;
  if (buffer_._getParent(child, ros::Time(0), existing)) {
    if (existing != parent)
      return "frame '" + child + "' already has the parent '" + existing + "' on tf: publishing " +
             parent + " -> " + child + " would give it a second parent";
    if (!published.count(parent + " -> " + child))
      return "'" + parent + " -> " + child + "' is already on tf from another broadcaster";
  }
  std::string up = parent;  // no loop: the child must not be above the parent
  for (int depth = 0; depth < 64 && buffer_._getParent(up, ros::Time(0), existing); ++depth) {
    if (existing == child) {
      std::string why = "'" + child + "' is above '" + parent + "' on tf: " + parent + " -> " +
                        child + " would make a loop";
      // Our own earlier link, kept by every tf listener that heard it: a static parent of
      // that frame sent after it was dropped by them (tf2's TF_OLD_DATA), so they would
      // keep the loop. Only restarting them clears it.
      const std::string ours = existing + " -> " + up;
      if (published.count(ours))
        why += " through this nodelet's earlier " + ours + ": tf listeners that heard it keep it" +
               staticParentNote(up) +
               ": restart the pipeline and the tf listeners (rviz) with tf_mode:=below_odom, or "
               "start the static publisher first";
      return why;
    }
    up = existing;
  }
  return {};
}

std::vector<std::string> TfTreeView::foreignLinks(const std::string& frame,
                                                  const std::set<std::string>& published) const {
  std::vector<std::string> frames, foreign;
  buffer_._getFrameStrings(frames);
  std::string parent;
  for (const std::string& f : frames) {
    if (!buffer_._getParent(f, ros::Time(0), parent) || (f != frame && parent != frame)) continue;
    const std::string edge = parent + " -> " + f;
    if (!published.count(edge) && staticParent(f) != parent) foreign.push_back(edge);
  }
  return foreign;
}

std::string TfTreeView::staticParentNote(const std::string& frame) const {
  const std::optional<std::string> parent = staticParent(frame);
  return !parent ? std::string()
                 : ", and dropped the static parent '" + *parent + "' of '" + frame +
                       "' sent after it (TF_OLD_DATA)";
}

}  // namespace mono_plane_detection
