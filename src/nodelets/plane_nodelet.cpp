// Thin ROS glue around PlanePipeline: tracks (+ camera_info, optional odometry tf) in;
// map planes, image planes, the camera pose, rviz markers, the map's points, tf and a
// debug image out. Frames, tf modes and services: docs/ros_interface.md.
#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <pluginlib/class_list_macros.hpp>

#include "callback_guard.h"
#include "camera_info_check.h"
#include "map_file.h"
#include "mono_plane_detection/PlanesConfig.h"
#include "mono_plane_detection/SaveMap.h"
#include "mono_plane_detection/mapping/plane_pipeline.h"
#include "mono_plane_detection/ros/map_frame.h"
#include "mono_plane_detection/ros/pose_msg.h"
#include "mono_plane_detection/viz/draw_planes.h"
#include "nodelet_diagnostics.h"
#include "plane_messages.h"
#include "plane_status.h"
#include "recent_events.h"
#include "reconfigure_bridge.h"
#include "ros_params.h"
#include "stretched_wait.h"
#include "tf_tree_view.h"

namespace mono_plane_detection {
namespace {

geometry_msgs::TransformStamped toTransform(const Pose& parent_from_child, const ros::Time& stamp,
                                            const std::string& parent, const std::string& child) {
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = stamp;
  tf.header.frame_id = parent;
  tf.child_frame_id = child;
  tf.transform = toTransformMsg(parent_from_child);
  return tf;
}

std::string sizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

}  // namespace

class PlaneNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    initOrAbandon(
        getName(), [this] { init(); }, [this] { abandonInit(); });
  }

  void abandonInit() {
    std::lock_guard<std::mutex> lock(connect_mutex_);
    diagnostics_.stop();
    tracks_sub_.shutdown();
    retry_timer_.stop();
    info_sub_.shutdown();
    image_sub_.shutdown();
    static_sub_.shutdown();
    debug_pub_.shutdown();
    for (ros::Publisher* p :
         {&planes_pub_, &image_planes_pub_, &pose_pub_, &markers_pub_, &cloud_pub_})
      p->shutdown();
    reset_srv_.shutdown();
    save_srv_.shutdown();
    reconfigure_.stop();
    tf_listener_.reset();
    tf_view_.reset();
    tf_buffer_.reset();
    broadcaster_.reset();
    image_transport_.reset();
  }

  void init() {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    guard_.setLogger(getName());
    PlaneNodeParams node;
    start_errors_ = readParams(pnh, planeNodeParamTable(), node, getName());
    params_ = node.pipeline;
    pipeline_ = std::make_unique<PlanePipeline>(params_);
    map_frame_ = node.map_frame;
    odom_frame_ = node.odom_frame;
    camera_frame_ = node.camera_frame;
    publish_tf_ = node.publish_tf;
    transport_ = node.image_transport;
    max_odom_jump_m_ = node.max_odom_jump_m;
    odom_wait_s_ = node.odom_wait_s;  // (not a live parameter)
    target_timeout_s_ = node.target_timeout_s;
    tf_mode_ = node.tf_mode;
    if (tf_mode_ != "auto" && tf_mode_ != "above_odom" && tf_mode_ != "below_odom") {
      NODELET_ERROR("parameter tf_mode = '%s' is not auto, above_odom or below_odom; using auto",
                    tf_mode_.c_str());
      tf_mode_ = "auto";
    }
    // image_proc's rectified stream, or said so: P without distortion (image_geometry).
    const std::string rectified_by = rectifiedBy(node.rectified, nh.resolveName("image"));
    rectified_ = !rectified_by.empty();
    if (rectified_)
      NODELET_INFO("rectified images (%s): camera_info's P is used, without distortion",
                   rectified_by.c_str());

    // Tracks held by an odometry wait are processed in one burst when it ends (one
    // callback of this nodelet's single-threaded queue) while new ones queue in the
    // subscription: deep enough for a wait's worth of images at 30 Hz and two more, no
    // deeper (on a machine too slow for the image rate every answer is a queue length
    // old). The burst's answers are published at once, faster than roscpp's writer thread
    // may send them to another process: the per-image answers queue as deep.
    const uint32_t burst = odom_frame_.empty()
                               ? 5
                               : static_cast<uint32_t>(std::clamp<double>(
                                     std::ceil(odom_wait_s_ * 30) + 2, 5, kMaxPending));
    planes_pub_ = nh.advertise<PlaneArray>("planes", burst);
    image_planes_pub_ = nh.advertise<PlaneArray>("image_planes", burst);
    pose_pub_ = nh.advertise<geometry_msgs::PoseStamped>("camera_pose", burst);
    markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>("plane_markers", 5);
    cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("map_points", 2);
    image_transport_ = std::make_unique<image_transport::ImageTransport>(nh);
    // The image is only needed to draw on: subscribe while someone watches the drawing.
    auto connect = guard_.wrap(
        "connect", [this](const image_transport::SingleSubscriberPublisher&) { this->connect(); });
    debug_pub_ = image_transport_->advertise("debug_image", 1, connect, connect);
    if (publish_tf_) broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
    // Also without odometry: what is already on tf is checked before publishing to it.
    if (publish_tf_ || !odom_frame_.empty()) {
      tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
      tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_);
      tf_view_ = std::make_unique<TfTreeView>(*tf_buffer_);
    }
    // tf2 keeps one cache per frame: a static parent that comes after our own dynamic
    // link to the same child hides behind it there. Static links are latched, one
    // message per publisher on connecting (tf2_ros's own queue: 100): their parents are
    // kept (tf_view_) for the tf check and for odom_frame's (rigidOdomFrame).
    if (publish_tf_ || !odom_frame_.empty())
      static_sub_ = nh.subscribe<tf2_msgs::TFMessage>(
          "/tf_static", 100, guard_.message("tf_static", this, &PlaneNodelet::onTfStatic));
    node_ = node;
    startReconfigure(pnh);
    reset_srv_ = pnh.advertiseService("reset", &PlaneNodelet::onReset, this);
    save_srv_ = pnh.advertiseService("save_map", &PlaneNodelet::onSaveMap, this);

    diagnostics_.start(nh, pnh, getName(), "planes", this, &PlaneNodelet::diagnose, guard_,
                       node.expected_min_rate_hz, node.expected_max_rate_hz);

    retry_timer_ = nh.createSteadyTimer(
        ros::WallDuration(kRetryS), guard_.wrap("odometry wait", [this](const auto&) { drain(); }),
        true /* oneshot */, false /* autostart */);
    // The map must follow every image, so tracks are always subscribed (the tracker
    // itself runs lazily: only while this nodelet listens); queued as deep as a burst.
    tracks_sub_ = nh.subscribe<Tracks>("tracks", burst,
                                       guard_.message("tracks", this, &PlaneNodelet::onTracks));
    info_sub_ = nh.subscribe<sensor_msgs::CameraInfo>(
        "camera_info", 2, guard_.message("camera_info", this, &PlaneNodelet::onCameraInfo));
  }

  // dynamic_reconfigure for the parameters read on every image (cfg/Planes.cfg).
  void startReconfigure(ros::NodeHandle& pnh) {
    reconfigure_.start(pnh, planeNodeParamTable(), planeRuntimeParamNames(), node_,
                       [this](PlanesConfig& config, bool first) {
                         guard_.run("reconfigure", [&] { onReconfigure(config, first); });
                       });
  }

  void onReconfigure(PlanesConfig& config, bool first) {
    std::lock_guard<std::mutex> lock(mutex_);
    PlaneNodeParams node;
    const std::vector<std::string> errors = reconfigure_.take(config, node_, node);
    for (const std::string& error : errors) NODELET_ERROR("reconfigure: %s", error.c_str());
    reconfigure_errors_ = errors;
    node_ = node;
    params_ = node.pipeline;
    pipeline_->setPerImageParams(params_.planes, params_.frame_gap, params_.max_gap_s);
    if (!first) ++run_.reconfigures;
  }

  void connect() {
    std::lock_guard<std::mutex> lock(connect_mutex_);
    if (debug_pub_.getNumSubscribers() > 0 && !image_sub_) {
      image_sub_ = image_transport_->subscribe(
          "image", 2, guard_.message("image", this, &PlaneNodelet::onImage), ros::VoidPtr(),
          image_transport::TransportHints(transport_));
    } else if (debug_pub_.getNumSubscribers() == 0 && image_sub_) {
      image_sub_.shutdown();
      std::lock_guard<std::mutex> state(mutex_);
      images_.clear();
    }
  }

  void onImage(const sensor_msgs::ImageConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    images_.push_back(msg);
    while (images_.size() > 10) images_.pop_front();
  }

  // Kept, and given to the pipeline with the next tracks of its image size (process()):
  // a camera_info for another size is not used for those tracks.
  void onCameraInfo(const sensor_msgs::CameraInfoConstPtr& msg) {
    CameraIntrinsics camera;
    std::string error = intrinsicsFromCameraInfo(*msg, rectified_, camera);
    if (error.empty()) error = cameraIntrinsicsError(camera.K, camera.D);
    std::lock_guard<std::mutex> lock(mutex_);
    if (!error.empty()) {
      ++run_.dropped_info;
      // One throttle per reason: an unknown distortion model after a zero K is named too.
      if (problems_.note("camera_info " + reasonKind(error), "camera_info rejected: " + error,
                         10.0))
        NODELET_WARN(
            "camera_info rejected: %s; %s", error.c_str(),
            calibration_.latest() ? "the last usable one stays in use" : "image-space planes only");
      return;
    }
    calibration_.offer(camera);  // (its size with binning and ROI applied)
  }

  bool onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    bool done = false;
    guard_.run("reset", [&] {
      {
        std::lock_guard<std::mutex> order(drain_mutex_);  // (drain_mutex_ before mutex_)
        odometry_live_ = true;                            // the odometry is waited for again
      }
      std::lock_guard<std::mutex> lock(mutex_);
      pipeline_->reset();
      mapStartedOver();
      last_odom_.reset();
      last_planes_.reset();
      run_.tf_conflict.clear();
      resolved_tf_mode_.clear();  // our earlier links stay ours (published_edges_)
      // Until the next tracks say otherwise (a paused robot's diagnostics kept the old map's).
      run_.status = "reset: the map starts over with the next tracks";
      run_.start_wait_s = run_.start_target_unseen_s = 0;
      run_.metric_source.clear();
      run_.tf_edge.clear();
      run_.map_frame_shared.clear();
      ++run_.resets;
      NODELET_INFO("reset: the map and the camera pose start over");
      done = true;
    });
    return done;
  }

  // What the map's output keeps beyond the pipeline, started over with it (mutex_ held).
  // The wait for the target goes on over a bag loop (the tracker's does too); a ~reset or
  // another camera starts it again.
  void mapStartedOver(bool keep_target_wait = false) {
    markers_shown_.clear();
    // rviz drops the old map's planes now, not when a new map first has markers (hostile
    // try: after ~reset they stayed 33 s and more).
    std_msgs::Header header;
    header.frame_id = map_frame_;
    header.stamp = ros::Time::now();
    visualization_msgs::MarkerArrayPtr clear(new visualization_msgs::MarkerArray);
    clear->markers.push_back(deleteAllMarker(header));
    markers_pub_.publish(clear);
    if (!keep_target_wait) target_wait_.reset();
  }

  // A log line at most once per period_s of wall time per kind: ROS's _THROTTLE macros
  // count in ros::Time, which a looping bag sets back, silencing them for a whole loop.
  bool logNow(const std::string& kind, double period_s) { return logged_.note(kind, "", period_s); }

  // The odometry moves the camera otherwise than its images show (odometry_check.h), and
  // what to look at: the two configuration errors that do it (hostile try: odom_frame
  // base_link on a humanoid left the map empty with every status OK).
  std::string odometryMismatchText() const {
    return "the odometry (tf " + odom_frame_ +
           " -> camera) does not move the camera as its "
           "images show: " +
           pipeline_->odometryMonitor().summary() +
           "; is odom_frame the odometry's fixed frame (odom, not base_link or another frame "
           "on the robot), and the images' frame_id the camera's optical frame (z forward, x "
           "right, y down)?";
  }

  // Tracks for kCameraInfoGraceS of wall time without a usable camera_info: the first
  // tracks of a bag or a driver often come before it (a WARN at every start before).
  bool cameraInfoOverdue() const {
    return !first_tracks_.isZero() &&
           (ros::WallTime::now() - first_tracks_).toSec() > kCameraInfoGraceS;
  }

  bool onSaveMap(SaveMap::Request& req, SaveMap::Response& res) {
    guard_.run("save_map", [&] {
      PlaneArrayConstPtr planes;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        planes = last_planes_;
      }
      const MapFileResult written = writeMapFile(planes.get(), req.path);
      res.success = written.success;
      res.planes = written.planes;
      res.message = written.message;
      if (res.success)
        NODELET_INFO("save_map: %s", res.message.c_str());
      else
        NODELET_ERROR("save_map: %s", res.message.c_str());
    });
    return true;  // the reason is in the response
  }

  // tf_problem: why tf links no odometry to these tracks' camera at all ("" when it does,
  // or when only this stamp is missing: the odometry stopped or is late).
  // rigid: tf_problem is odom_frame rigid with the camera (a configuration error).
  // stale_link: when only this stamp is missing, the link between them that lacks it.
  std::optional<Pose> odometry(const std_msgs::Header& header, std::string& tf_problem, bool& rigid,
                               std::string& stale_link) {
    tf_problem.clear();
    stale_link.clear();
    rigid = false;
    if (odom_frame_.empty()) return {};
    tf_problem = tf_view_->rigidOdomFrame(tfFrame(header.frame_id), odom_frame_);
    rigid = !tf_problem.empty();
    if (rigid) {
      if (logNow("odometry rigid", 10.0)) NODELET_ERROR("%s: visual pose only", tf_problem.c_str());
      return {};
    }
    try {
      // Never wait in a callback: drain() waited (odom_wait_s) without blocking; now
      // take what tf has for this stamp or go visual.
      const auto tf =
          tf_buffer_->lookupTransform(odom_frame_, tfFrame(header.frame_id), header.stamp);
      const Pose odom = fromTransformMsg(tf.transform);
      // tf2 rejects NaN but not infinity; a driver glitch can also jump far in one step.
      std::lock_guard<std::mutex> lock(mutex_);
      // Time went backwards (a bag loop): the map starts over, and so does the jump check
      // (against the pose from before the loop it refused the first odometry after it).
      if (!last_odom_stamp_.isZero() && header.stamp < last_odom_stamp_) last_odom_.reset();
      last_odom_stamp_ = header.stamp;
      const std::string error = odometryError(odom, last_odom_, max_odom_jump_m_);
      last_odom_ = odom;
      if (!error.empty()) {
        ++run_.refused_odom;
        problems_.note("odometry refused", "odometry refused: " + error);
        if (logNow("odometry refused", 5.0))
          NODELET_WARN("odometry %s -> %s at %.3f refused (%s): visual pose used",
                       odom_frame_.c_str(), header.frame_id.c_str(), header.stamp.toSec(),
                       error.c_str());
        return {};
      }
      return odom;
    } catch (const tf2::TransformException& e) {
      tf_problem = tf_view_->odometryProblem(tfFrame(header.frame_id), odom_frame_);
      if (tf_problem.empty())
        stale_link = tf_view_->staleLinks(tfFrame(header.frame_id), odom_frame_, header.stamp);
      if (!tf_problem.empty() ? logNow("odometry tf " + tf_problem, 10.0)
                              : logNow("odometry lookup", 10.0))
        NODELET_WARN("no %s -> %s transform at %.3f (%s): visual pose only%s%s",
                     odom_frame_.c_str(), header.frame_id.c_str(), header.stamp.toSec(), e.what(),
                     tf_problem.empty() ? "" : "; ", tf_problem.c_str());
      return {};
    }
  }

  // Static links' parents, for the tf checks (tf_tree_view.h).
  void onTfStatic(const tf2_msgs::TFMessageConstPtr& msg) { tf_view_->noteStatic(*msg); }

  // The one transform this nodelet publishes for this image, if any (mutex_ held).
  std::optional<geometry_msgs::TransformStamped> transformFor(const Pose& ros_map_from_camera,
                                                              const std::optional<Pose>& odom,
                                                              const std_msgs::Header& header) {
    if (!publish_tf_ || !run_.tf_conflict.empty()) return {};
    std::string parent, child;
    Pose parent_from_child;
    if (!odom_frame_.empty()) {
      // Only the map <-> odom link: the robot's own tree (odom -> base_link -> camera)
      // is never touched. No odometry for this image: nothing new to say.
      if (!odom) return {};
      if (resolved_tf_mode_.empty()) {
        // A static parent first: tf2 drops one sent after a dynamic link to the same frame
        // (ours, before a ~reset), so only /tf_static shows it (as to TfTreeView::conflict).
        std::string odom_parent = tf_view_->staticParent(odom_frame_).value_or("");
        const bool has_parent =
            !odom_parent.empty() || tf_buffer_->_getParent(odom_frame_, ros::Time(0), odom_parent);
        resolved_tf_mode_ = tf_mode_ != "auto"                        ? tf_mode_
                            : has_parent && odom_parent != map_frame_ ? "below_odom"
                                                                      : "above_odom";
        if (tf_mode_ == "auto") {
          const std::string why = resolved_tf_mode_ == "below_odom"
                                      ? "'" + odom_frame_ + "' already has the parent '" +
                                            odom_parent + "': publishing " + odom_frame_ + " -> " +
                                            map_frame_
                                      : "publishing " + map_frame_ + " -> " + odom_frame_;
          NODELET_INFO("tf_mode auto: %s", why.c_str());
        }
      }
      const Pose map_from_odom = ros_map_from_camera * odom->inverse();
      if (resolved_tf_mode_ == "above_odom") {
        parent = map_frame_;
        child = odom_frame_;
        parent_from_child = map_from_odom;
      } else {
        parent = odom_frame_;
        child = map_frame_;
        parent_from_child = map_from_odom.inverse();
      }
    } else {
      if (header.frame_id.empty()) {
        if (logNow("empty frame_id", 10.0))
          NODELET_WARN("tracks have an empty frame_id: no camera estimate on tf");
        return {};
      }
      // Never the camera's own frame: the robot's URDF is its parent already.
      parent = map_frame_;
      child = camera_frame_.empty() ? tfFrame(header.frame_id) + "_estimate" : camera_frame_;
      parent_from_child = ros_map_from_camera;
    }
    run_.tf_conflict = tf_view_->conflict(parent, child, published_edges_);
    if (!run_.tf_conflict.empty() && child == map_frame_)
      run_.tf_conflict +=
          " (a second pipeline with the same map_frame? give each camera its own, "
          "e.g. map_frame:=robot1/plane_map)";
    if (!run_.tf_conflict.empty()) {
      NODELET_ERROR("tf refused, nothing more is published on tf (until ~reset): %s",
                    run_.tf_conflict.c_str());
      return {};
    }
    run_.tf_edge = parent + " -> " + child;
    published_edges_.insert(run_.tf_edge);
    return toTransform(parent_from_child, header.stamp, parent, child);
  }

  // Another pipeline publishing into this map_frame (mutex_ held; once a second): two
  // robots or cameras launched with the default map_frame put two maps with unrelated
  // origins into one frame, and every status was OK (hostile try).
  void checkMapFrameShared() {
    if (!tf_view_ || !publish_tf_ || run_.tf_edge.empty()) return;
    const ros::WallTime now = ros::WallTime::now();
    if (now - shared_checked_ < ros::WallDuration(1.0)) return;
    shared_checked_ = now;
    std::string foreign;
    for (const std::string& edge : tf_view_->foreignLinks(map_frame_, published_edges_))
      foreign += (foreign.empty() ? "" : ", ") + edge;
    if (!foreign.empty() && foreign != run_.map_frame_shared)
      NODELET_WARN("%s", mapFrameSharedText(map_frame_, foreign).c_str());
    run_.map_frame_shared = foreign;
  }

  // Tracks wait (in order, without blocking a callback) until tf has the odometry at
  // their stamp: a robot's odometry often reaches tf a period after the image. tf2_ros's
  // MessageFilter waits too, but without a time bound: an image waits until its queue
  // overflows, so with odometry stopped every image is answered a queue length late and
  // the last one before a pause never. Waits are measured on the steady clock (a clock
  // step of the system time must not stretch or cut them short). This needs the
  // nodelet's single-threaded queue (getNodeHandle), tracks and retry timer alike: on a
  // multi-threaded one a callback would block on drain_mutex_ while another processes.
  // Malformed tracks are dropped on arrival: they never wait, nor hold back those behind.
  void onTracks(const TracksConstPtr& msg) {
    diagnostics_.tick();
    std::string error;
    TrackFrame frame = toTrackFrame(*msg, error);
    if (!error.empty()) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++run_.dropped;
      if (problems_.note("tracks " + reasonKind(error), "tracks dropped: " + error))
        NODELET_ERROR("tracks dropped: %s", error.c_str());
      return;
    }
    {
      std::lock_guard<std::mutex> lock(pending_mutex_);
      pending_.push_back({msg, std::move(frame), ros::SteadyTime::now()});
    }
    drain();
  }

  void drain() {
    bool look_again = false;
    {
      std::lock_guard<std::mutex> order(drain_mutex_);  // one image at a time, oldest first
      look_again = drainLocked();
    }
    if (look_again) {  // (re-armed outside the lock) tf has no event per stamp
      retry_timer_.stop();
      retry_timer_.setPeriod(ros::WallDuration(kRetryS));
      retry_timer_.start();
    }
  }

  // Processes the waiting tracks in order; true when the oldest still waits.
  bool drainLocked() {
    for (;;) {
      TracksConstPtr msg;
      ros::SteadyTime arrived;
      size_t waiting = 0;
      {
        std::lock_guard<std::mutex> lock(pending_mutex_);
        if (pending_.empty()) return false;
        msg = pending_.front().msg;
        arrived = pending_.front().arrived;
        waiting = pending_.size();
      }
      if (mustWait(*msg, waiting)) {
        if ((ros::SteadyTime::now() - arrived).toSec() < odom_wait_s_) return true;
        ++odom_waits_in_vain_;
        odometry_live_ = false;             // waited in vain: the next tracks do not wait...
        missed_stamp_ = msg->header.stamp;  // ...until tf's odometry comes within reach
      }
      TrackFrame frame;
      {
        std::lock_guard<std::mutex> lock(pending_mutex_);
        frame = std::move(pending_.front().frame);
        pending_.pop_front();
      }
      // One bad message never stalls the rest.
      guard_.run("tracks", [&] { process(*msg, std::move(frame)); });
    }
  }

  // Whether these tracks wait for their odometry: an odometry frame is set, fewer than
  // kMaxPending wait, tf lacks the odometry at their stamp (the usual case, odometry in
  // time, costs this one lookup), tf links the odometry to their camera at all (another
  // camera's tracks, or none yet, do not wait), and the odometry is live.
  bool mustWait(const Tracks& msg, size_t waiting) {
    const std::string frame = tfFrame(msg.header.frame_id);
    if (odom_frame_.empty() || odom_wait_s_ <= 0 || frame.empty() || waiting >= kMaxPending ||
        tf_buffer_->canTransform(odom_frame_, frame, msg.header.stamp))
      return false;
    ros::Time newest;
    try {
      newest = tf_buffer_->lookupTransform(odom_frame_, frame, ros::Time(0)).header.stamp;
    } catch (const tf2::TransformException&) {
      return false;
    }
    // Wait again once the odometry is within reach: tf's newest is past the stamp that
    // waited in vain and no further behind this image than odom_wait_s (odometry that
    // always lags more is not waited for at every image), or time went backwards.
    if (!odometry_live_)
      odometry_live_ =
          msg.header.stamp < missed_stamp_ ||
          (newest > missed_stamp_ && newest + ros::Duration(odom_wait_s_) >= msg.header.stamp);
    return odometry_live_;
  }

  // Whether tracks come from before a jump back of ros::Time (a bag loop): tf2_ros's
  // listener cleared its buffer at the jump, and a transform stamped at the previous
  // loop's end filled it with times the new loop's first 10 s are too old for (tf2's
  // cache: ~60 TF_OLD_DATA warnings per loop). Such tracks have stamps nearer the clock
  // before the jump than the clock now; the first that does not ends the jump.
  bool fromBeforeClockJump(const ros::Time& stamp) {
    const ros::Time now = ros::Time::now();
    std::lock_guard<std::mutex> lock(mutex_);
    if (now < clock_seen_) jumped_from_ = clock_seen_;
    clock_seen_ = now;
    if (jumped_from_.isZero()) return false;
    if (stamp.toSec() > 0.5 * (now.toSec() + jumped_from_.toSec())) return true;
    jumped_from_ = ros::Time();
    return false;
  }

  // frame: msg's tracks, checked on arrival (toTrackFrame).
  void process(const Tracks& msg, TrackFrame frame) {
    const ros::WallTime started = ros::WallTime::now();
    const bool before_jump = fromBeforeClockJump(msg.header.stamp);
    std::string odom_tf_problem, odom_stale_link;
    bool odom_rigid = false;
    const std::optional<Pose> odom =
        before_jump ? std::nullopt
                    : odometry(msg.header, odom_tf_problem, odom_rigid, odom_stale_link);
    PlaneArrayPtr planes, image_planes;
    geometry_msgs::PoseStampedPtr pose;
    visualization_msgs::MarkerArrayPtr markers;
    sensor_msgs::PointCloud2Ptr cloud;
    cv::Mat drawing;
    std::optional<geometry_msgs::TransformStamped> tf;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // An empty frame_id names no camera: only a named change or a size change counts.
      const bool other_frame = !msg.header.frame_id.empty() && !last_frame_id_.empty() &&
                               msg.header.frame_id != last_frame_id_;
      if (!last_tracks_size_.empty() && (other_frame || frame.size != last_tracks_size_)) {
        ++run_.camera_switches;
        // A recent problem, not a state: the diagnostics are OK again a while after the
        // last switch (the total stays).
        const std::string why = "tracks changed camera ('" + last_frame_id_ + "' " +
                                sizeText(last_tracks_size_) + " -> '" + msg.header.frame_id + "' " +
                                sizeText(frame.size) + ")";
        if (problems_.note(kCameraSwitch, "tracks mix cameras: " + why))
          NODELET_WARN("%s: one camera per tracks topic, or the planes of neither are found",
                       why.c_str());
      }
      if (!msg.header.frame_id.empty()) last_frame_id_ = msg.header.frame_id;
      last_tracks_size_ = frame.size;
      if (first_tracks_.isZero()) first_tracks_ = ros::WallTime::now();
      // Corners of a target of another size than ours would fix a wrong scale (two
      // nodelets configured apart): refused, loudly, until they agree. Every message says
      // the tracker's target, so a tracker relaunched with the right one clears it at once.
      run_.target_mismatch = targetMismatch(msg, node_.pipeline.target);
      if (!run_.target_mismatch.empty()) {
        if (logNow("target mismatch", 10.0)) NODELET_ERROR("%s", run_.target_mismatch.c_str());
        frame.target_corner.assign(frame.target_corner.size(), false);
      }
      // A camera_info describes tracks of its image size only (binning and ROI applied):
      // the last one of their size is used; with none the pipeline has no camera
      // (image-space planes, no target pose from it) until one comes.
      std::string info_mismatch;
      const CameraIntrinsics* camera = calibration_.forImages(frame.size, info_mismatch);
      if (!info_mismatch.empty()) {
        ++run_.info_size_mismatch;
        if (logNow("info size", 10.0)) NODELET_ERROR("%s", info_mismatch.c_str());
      }
      // Another camera's camera_info? Used all the same, said (throttled) and counted.
      if (camera) {
        if (std::string other = infoFrameMismatch(*camera, msg.header.frame_id); !other.empty()) {
          ++run_.info_frame_mismatch;
          if (logNow("info frame", 10.0))
            NODELET_WARN("%s (%s)", other.c_str(), info_sub_.getTopic().c_str());
        }
      }
      // The tracker's start-up target seen while the map could not use it (no camera):
      // the tracker joins it once, so once its corners are gone the map waits for ever.
      const bool target_in_tracks =
          std::find(frame.target_corner.begin(), frame.target_corner.end(), true) !=
          frame.target_corner.end();
      if (target_in_tracks) run_.target_missed = !camera;
      if (camera) {
        pipeline_->setCamera(camera->K, camera->D);  // (checked on arrival; same: no change)
        undistortFisheye(frame, *camera);            // equidistant: pinhole pixels of the same K
      } else if (pipeline_->hasCamera()) {           // (the map of that camera does not apply)
        pipeline_ = std::make_unique<PlanePipeline>(params_);
        mapStartedOver();
      } else if (!calibration_.latest() && cameraInfoOverdue() && logNow("no camera_info", 10.0)) {
        NODELET_WARN("tracks arrive but no usable camera_info on %s: image-space planes only",
                     info_sub_.getTopic().c_str());
      }
      // The core's axes (y up) for the odometry: with metric_source odometry the ROS map
      // is then the odometry frame itself (docs/ros_interface.md).
      const PipelineResult result = pipeline_->process(
          frame, odom ? std::optional<Pose>(targetFromRosMap(*odom)) : std::nullopt);
      const PoseEstimator* estimator = pipeline_->poseEstimator();
      run_.metric_source = estimator ? toString(estimator->metricSource()) : "";
      // The tf of the odometry source stopped: vision carries the pose (landmarks in the
      // odometry's frame, so no jump), said in diagnostics.
      // Any source: without odometry no map <-> odom tf is published for the image.
      // (Tracks of before a jump back of the clock say nothing of the odometry now.)
      if (!before_jump) {
        run_.odom_tf_problem = odom_tf_problem;
        run_.odom_rigid = odom_rigid;
        run_.odometry_stopped = !odom && !odom_frame_.empty() && odom_tf_problem.empty();
        run_.odom_stale_link = odom_stale_link;
      }
      if (result.was_reset) {
        // Rare (a bag loop): every time while loops come at most once a second, on the
        // wall clock (a throttle on ros::Time was silenced by the loop itself); a flood
        // of stamps going back and forth is limited as the tracker limits it.
        if (result.tracker_restarted) {
          // A reloaded or respawned tracker: its new tracks are no points of this map.
          NODELET_WARN(
              "the tracker started over (another tracker_run in its tracks, or its track ids "
              "began again with none of the last image's left: a reloaded or respawned "
              "tracker nodelet?): the map starts over%s",
              node_.pipeline.pose.metric_source == "target"
                  ? "; show the start-up target to the camera again"
                  : "");
          mapStartedOver();
          ++run_.resets;
          ++run_.tracker_restarts;
        } else {
          if (logged_.note("backwards", "", 5.0, kRareEventBurst))
            NODELET_WARN(
                "tracks stamp %.3f is before the previous one: time went backwards (bag "
                "loop?), the map starts over",
                frame.stamp);
          mapStartedOver(true);
          ++run_.resets;
          ++run_.backwards_resets;
          stream_health_.wentBackwards();
        }
        // Under simulated time the listener cleared its buffer when it saw the clock go
        // back, then took in what was queued before the jump: our own transform of the
        // previous loop's last images among it (measured: 59 TF_OLD_DATA in a loop of the
        // room bag with the stale tracks above kept off tf). Without it (a bag looped on
        // the wall clock) nothing cleared it, and every transform of the new loop, ours and
        // the bag's, came again at a stamp it held: tf2 printed TF_REPEATED_DATA for each,
        // about 570 per 10 s loop. Cleared now that the tracks agree, either way (tf2_ros's
        // own remedy; the static links stay): the new loop's transforms refill it.
        if (tf_buffer_) tf_buffer_->clear();
      }
      if (pipeline_->odometryMonitor().disagrees() && logNow("odometry mismatch", 10.0))
        NODELET_ERROR("%s", odometryMismatchText().c_str());
      if (result.tracking_loss && logNow("tracking loss", 5.0))
        NODELET_WARN(
            "%.3f s without tracks: tracking lost, waiting for %s to place the camera "
            "again",
            result.pause_s,
            !odom_frame_.empty()                                   ? "the odometry"
            : node_.pipeline.pose.metric_source == "camera_height" ? "the map"
                                                                   : "the map or the target");
      // One line per change of the status (the pose's source too: "tracking (target)" ->
      // "(odometry)" went unsaid), not of its "; too little parallax (...)" remark.
      // A status that flips image by image is said once per 10 s each way.
      const std::string status_key = result.status.substr(0, result.status.find(';'));
      if (result.state != last_state_ || status_key != last_status_key_) {
        if (logNow("status " + status_key, 10.0)) NODELET_INFO("%s", result.status.c_str());
        last_state_ = result.state;
        last_status_key_ = status_key;
      }
      // Waited in tracks stamps over the stretches of the stream (a pause or a jump of the
      // stamps is a tracking loss, time going back a reset: each closes one), since the
      // target was last seen, as the tracker counts it.
      if (result.state == PipelineState::kWaitingForTarget) {
        if (result.tracking_loss || result.was_reset) target_wait_.closeStretch();
        target_wait_.seen(frame.stamp);
      } else {
        target_wait_.reset();
      }
      ++run_.frames;
      // Tracks missing by their stamps, as the pipeline's rhythm counts them: the tracker's
      // images it never got and tracks this nodelet's queue dropped (roscpp says neither).
      run_.missing_tracks += result.missing_images;
      stream_health_.received(result.missing_images);
      run_.status = result.status;
      run_.state = result.state;
      run_.start_wait_s = result.start_wait_s;
      run_.start_target_unseen_s = result.start_target_unseen_s;
      run_.observed = result.planes.size();
      std_msgs::Header map_header = msg.header;
      map_header.frame_id = map_frame_;
      image_planes = toImagePlanes(msg.header, result);
      planes = toMapPlanes(map_header, result, pipeline_->map());
      planes->metric_source = image_planes->metric_source = run_.metric_source;
      if (planes->metric) {
        const Pose ros_map_from_camera = rosMapFromTarget() * result.pose->map_from_camera;
        pose.reset(new geometry_msgs::PoseStamped);
        pose->header = map_header;
        pose->pose = planes->camera_pose;
        if (markers_pub_.getNumSubscribers() > 0 || reset_markers_) {
          markers = toMarkers(map_header, pipeline_->map(), markers_shown_);
          if (reset_markers_) {
            markers->markers.insert(markers->markers.begin(), deleteAllMarker(map_header));
            reset_markers_ = false;
          }
        }
        if (cloud_pub_.getNumSubscribers() > 0 && pipeline_->poseEstimator())
          cloud = toCloud(map_header, *pipeline_->poseEstimator(), pipeline_->map());
        if (!before_jump) tf = transformFor(ros_map_from_camera, odom, msg.header);
        checkMapFrameShared();
      }
      last_planes_ = planes;
      if (debug_pub_.getNumSubscribers() > 0) {
        for (const auto& image : images_)
          if (image->header.stamp == msg.header.stamp) {
            try {
              drawing = drawPlanes(cv_bridge::toCvShare(image, "mono8")->image, result);
            } catch (const cv_bridge::Exception& e) {
              if (logNow("draw", 10.0)) NODELET_WARN("cannot draw on the image: %s", e.what());
            }
          }
      }
    }
    const float ms = static_cast<float>((ros::WallTime::now() - started).toSec() * 1e3);
    planes->processing_ms = image_planes->processing_ms = ms;
    planes_pub_.publish(planes);  // shared pointers: no copy inside one manager
    image_planes_pub_.publish(image_planes);
    if (pose) pose_pub_.publish(pose);
    if (markers) markers_pub_.publish(markers);
    if (cloud) cloud_pub_.publish(cloud);
    if (tf) broadcaster_->sendTransform(*tf);
    if (!drawing.empty())
      debug_pub_.publish(cv_bridge::CvImage(msg.header, "bgr8", drawing).toImageMsg());
  }

  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
    std::lock_guard<std::mutex> lock(mutex_);
    PlaneStatusView view;
    view.map_frame = map_frame_;
    view.odom_frame = odom_frame_;
    view.metric_source_param = node_.pipeline.pose.metric_source;
    view.config_blocked = metricSourceProblem(node_);
    view.refused_params = refusedParams(start_errors_, reconfigure_errors_);
    view.odom_wait_s = odom_wait_s_;
    view.target_timeout_s = target_timeout_s_;
    view.publish_tf = publish_tf_;
    view.info_mismatch = calibration_.mismatch(last_tracks_size_);
    view.camera_info_overdue = run_.frames > 0 && !calibration_.latest() && cameraInfoOverdue();
    view.camera_model = cameraModelName(calibration_, last_tracks_size_);
    if (pipeline_->odometryMonitor().disagrees()) view.odometry_mismatch = odometryMismatchText();
    view.target_waited_s = target_wait_.seconds();  // (0 unless waiting for the start)
    view.exceptions = guard_.count();
    if (view.exceptions > 0) view.last_exception = guard_.lastReason();
    view.odom_waits_in_vain = odom_waits_in_vain_.load();
    view.map_up = mapUpText(*pipeline_, run_.metric_source);
    view.map_planes = pipeline_->map().planes().size();
    if (pipeline_->poseEstimator()) view.landmarks = pipeline_->poseEstimator()->landmarks().size();
    view.stream_problems = stream_health_.problems(
        "tracks",
        "images the tracker never got, or this nodelet's queue overflowed: the map is "
        "slower than the stream, e.g. under CPU load",
        "the map starting over", "tracks");
    view.recent_problems = problems_.recent(kRecentS);
    reportPlaneStatus(run_, view, status);
  }

  CallbackGuard guard_;                          // first member: the last destroyed
  PlaneNodeParams node_;                         // as read, then as reconfigured
  std::vector<std::string> start_errors_;        // parameters refused at start
  std::vector<std::string> reconfigure_errors_;  // refused by the last reconfigure
  PipelineParams params_;
  std::unique_ptr<PlanePipeline> pipeline_;
  std::string map_frame_, odom_frame_, camera_frame_, transport_, tf_mode_;
  bool publish_tf_ = true, rectified_ = false;
  double target_timeout_s_ = 30;

  ros::Publisher planes_pub_, image_planes_pub_, pose_pub_, markers_pub_, cloud_pub_;
  ros::Subscriber tracks_sub_, info_sub_, static_sub_;
  ros::SteadyTimer retry_timer_;  // drain() again while tracks wait for odometry
  std::mutex pending_mutex_, drain_mutex_;
  struct PendingTracks {
    TracksConstPtr msg;
    TrackFrame frame;         // msg's tracks, checked
    ros::SteadyTime arrived;  // (steady clock)
  };
  std::deque<PendingTracks> pending_;
  bool odometry_live_ = true;  // (drain_mutex_) false after a wait in vain...
  ros::Time missed_stamp_;     // ...for the odometry of the image of this stamp
  static constexpr double kRetryS = 0.005;
  static constexpr size_t kMaxPending = 30;  // more waiting: the oldest goes without
  ros::ServiceServer reset_srv_, save_srv_;
  std::unique_ptr<image_transport::ImageTransport> image_transport_;
  image_transport::Publisher debug_pub_;
  image_transport::Subscriber image_sub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> broadcaster_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::unique_ptr<TfTreeView> tf_view_;     // on tf_buffer_ (declared after it: goes first)
  RecentEvents problems_;                   // refused tracks, camera_info, odometry
  static constexpr double kRecentS = 10.0;  // a WARN in diagnostics lasts this long
  static constexpr const char* kCameraSwitch = "tracks camera switch";  // (problems_ kind)
  NodeletDiagnostics diagnostics_;

  std::mutex mutex_, connect_mutex_;  // mutex_ guards everything below and the pipeline
  std::deque<sensor_msgs::ImageConstPtr> images_;
  CalibrationHolder calibration_;       // the usable camera_infos
  ros::Time clock_seen_, jumped_from_;  // fromBeforeClockJump()
  RecentEvents logged_;                 // log throttles on wall time (logNow)
  std::set<int> markers_shown_;
  // The first markers of this nodelet begin with DELETEALL: a reloaded or respawned one
  // clears the old one's planes from rviz (hostile try: they stayed beside the new; a
  // DELETEALL at load would reach no rviz not yet connected). Start-overs publish their own.
  bool reset_markers_ = true;
  PipelineState last_state_ = PipelineState::kNoCamera;
  PlaneRunState run_;            // the last tracks' state and the totals, for diagnose()
  std::string last_status_key_;  // the status last logged, without its "; ..." remark
  StreamHealth stream_health_;   // tracks missing, time going back (last 10 s)
  ros::WallTime first_tracks_;   // wall time of the first tracks (camera_info's grace)
  double max_odom_jump_m_ = 1.0;
  double odom_wait_s_ = 0.25;
  std::atomic<long> odom_waits_in_vain_{0};  // tracks that waited odom_wait_s for nothing
  StretchedWait target_wait_;                // for the metric start, in tracks stamps
  std::optional<Pose> last_odom_;
  ros::Time last_odom_stamp_;
  std::string last_frame_id_;
  cv::Size last_tracks_size_;
  PlaneArrayConstPtr last_planes_;
  std::string resolved_tf_mode_;           // above_odom | below_odom once decided
  ros::WallTime shared_checked_;           // (checkMapFrameShared)
  std::set<std::string> published_edges_;  // links this nodelet has put on tf
  // Last: destroyed first, so no reconfigure callback outlives what it locks and changes.
  ReconfigureBridge<PlanesConfig, PlaneNodeParams> reconfigure_;
};

}  // namespace mono_plane_detection

PLUGINLIB_EXPORT_CLASS(mono_plane_detection::PlaneNodelet, nodelet::Nodelet)
