// Thin ROS glue around PlanePipeline: tracks (+ camera_info, optional odometry tf) in;
// planes, rviz markers, the map's points, map -> camera tf and a debug image out.
#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/TransformStamped.h>
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <deque>
#include <memory>
#include <mutex>
#include <pluginlib/class_list_macros.hpp>

#include "callback_guard.h"
#include "camera_info_check.h"
#include "mono_plane_detection/viz/draw_planes.h"
#include "mono_plane_detection/ros/pose_msg.h"
#include "nodelet_diagnostics.h"
#include "plane_messages.h"
#include "ros_params.h"

namespace mono_plane_detection {
namespace {

geometry_msgs::TransformStamped toTransform(const Pose& parent_from_child,
                                            const std_msgs::Header& header,
                                            const std::string& parent, const std::string& child) {
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = header.stamp;
  tf.header.frame_id = parent;
  tf.child_frame_id = child;
  tf.transform = toTransformMsg(parent_from_child);
  return tf;
}

}  // namespace

class PlaneNodelet : public nodelet::Nodelet {
 public:
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    guard_.setLogger(getName());
    PlaneNodeParams node;
    readParams(pnh, planeNodeParamTable(), node, getName());
    params_ = node.pipeline;
    pipeline_ = std::make_unique<PlanePipeline>(params_);
    map_frame_ = node.map_frame;
    odom_frame_ = node.odom_frame;
    publish_tf_ = node.publish_tf;
    transport_ = node.image_transport;
    max_odom_jump_m_ = node.max_odom_jump_m;

    planes_pub_ = nh.advertise<PlaneArray>("planes", 5);
    markers_pub_ = nh.advertise<visualization_msgs::MarkerArray>("plane_markers", 5);
    cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("map_points", 2);
    image_transport_ = std::make_unique<image_transport::ImageTransport>(nh);
    // The image is only needed to draw on: subscribe while someone watches the drawing.
    auto connect = guard_.wrap(
        "connect", [this](const image_transport::SingleSubscriberPublisher&) { this->connect(); });
    debug_pub_ = image_transport_->advertise("debug_image", 1, connect, connect);
    if (publish_tf_) broadcaster_ = std::make_unique<tf2_ros::TransformBroadcaster>();
    if (!odom_frame_.empty()) {
      tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
      tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_);
    }

    diagnostics_.start(nh, pnh, getName(), "planes", this, &PlaneNodelet::diagnose, guard_,
                       node.expected_min_rate_hz, node.expected_max_rate_hz);

    // The map must follow every image, so tracks are always subscribed (the tracker
    // itself runs lazily: only while this nodelet listens).
    tracks_sub_ =
        nh.subscribe<Tracks>("tracks", 5, guard_.message("tracks", this, &PlaneNodelet::onTracks));
    info_sub_ = nh.subscribe<sensor_msgs::CameraInfo>(
        "camera_info", 2, guard_.message("camera_info", this, &PlaneNodelet::onCameraInfo));
    no_info_timer_ = nh.createTimer(ros::Duration(5.0),
                                    guard_.wrap("camera_info timer",
                                                [this](const ros::TimerEvent&) {
                                                  std::lock_guard<std::mutex> lock(mutex_);
                                                  if (!pipeline_->hasCamera() && frames_ > 0)
                                                    NODELET_WARN(
                                                        "no usable camera_info after 5 s: "
                                                        "image-space planes only");
                                                }),
                                    true);
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

  void onCameraInfo(const sensor_msgs::CameraInfoConstPtr& msg) {
    cv::Matx33d K;
    cv::Mat D;
    std::string error = fromCameraInfo(*msg, K, D);
    std::lock_guard<std::mutex> lock(mutex_);
    if (error.empty()) error = pipeline_->setCamera(K, D);
    if (!error.empty()) {
      ++dropped_info_;
      NODELET_WARN_THROTTLE(10.0, "camera_info rejected: %s; image-space planes only",
                            error.c_str());
      return;
    }
    info_size_ = cv::Size(static_cast<int>(msg->width), static_cast<int>(msg->height));
  }

  std::optional<Pose> odometry(const std_msgs::Header& header) {
    if (odom_frame_.empty()) return {};
    try {
      // Never wait in a callback: take what tf has for this stamp or go visual.
      const auto tf = tf_buffer_->lookupTransform(odom_frame_, header.frame_id, header.stamp);
      const Pose odom = fromTransformMsg(tf.transform);
      // tf2 rejects NaN but not infinity; a driver glitch can also jump far in one step.
      std::lock_guard<std::mutex> lock(mutex_);
      const std::string error = odometryError(odom, last_odom_, max_odom_jump_m_);
      last_odom_ = odom;
      if (!error.empty()) {
        ++refused_odom_;
        NODELET_WARN_THROTTLE(5.0, "odometry %s -> %s at %.3f refused (%s): visual pose used",
                              odom_frame_.c_str(), header.frame_id.c_str(), header.stamp.toSec(),
                              error.c_str());
        return {};
      }
      return odom;
    } catch (const tf2::TransformException& e) {
      NODELET_WARN_THROTTLE(10.0, "no %s -> %s transform at %.3f (%s): visual pose only",
                            odom_frame_.c_str(), header.frame_id.c_str(), header.stamp.toSec(),
                            e.what());
      return {};
    }
  }

  void onTracks(const TracksConstPtr& msg) {
    const ros::WallTime started = ros::WallTime::now();
    std::string error;
    const TrackFrame frame = toTrackFrame(*msg, error);
    if (!error.empty()) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++dropped_;
      NODELET_ERROR_THROTTLE(5.0, "tracks dropped: %s", error.c_str());
      return;
    }
    const std::optional<Pose> odom = odometry(msg->header);
    PlaneArrayPtr planes;
    visualization_msgs::MarkerArrayPtr markers;
    sensor_msgs::PointCloud2Ptr cloud;
    cv::Mat drawing;
    std::optional<geometry_msgs::TransformStamped> tf;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // An empty frame_id names no camera: only a named change or a size change counts.
      const bool other_frame = !msg->header.frame_id.empty() && !last_frame_id_.empty() &&
                               msg->header.frame_id != last_frame_id_;
      if (!last_tracks_size_.empty() && (other_frame || frame.size != last_tracks_size_)) {
        ++camera_switches_;
        NODELET_WARN_THROTTLE(5.0,
                              "tracks changed camera ('%s' %dx%d -> '%s' %dx%d): one camera "
                              "per tracks topic, or the planes of neither are found",
                              last_frame_id_.c_str(), last_tracks_size_.width,
                              last_tracks_size_.height, msg->header.frame_id.c_str(),
                              frame.size.width, frame.size.height);
      }
      if (!msg->header.frame_id.empty()) last_frame_id_ = msg->header.frame_id;
      last_tracks_size_ = frame.size;
      if (!info_size_.empty() && info_size_ != frame.size)
        NODELET_WARN_THROTTLE(10.0, "camera_info is for %dx%d images but tracks are of %dx%d",
                              info_size_.width, info_size_.height, frame.size.width,
                              frame.size.height);
      const PipelineResult result = pipeline_->process(frame, odom);
      if (result.was_reset) {
        NODELET_WARN(
            "tracks stamp %.3f is before the previous one: time went backwards (bag "
            "loop?), the map starts over",
            frame.stamp);
        markers_shown_.clear();
        reset_markers_ = true;
      }
      if (result.tracking_loss)
        NODELET_WARN_THROTTLE(5.0,
                              "%.1f s without tracks: tracking lost, waiting for the map "
                              "or the target to place the camera again",
                              params_.max_gap_s);
      if (result.state != last_state_) {
        NODELET_INFO("%s", result.status.c_str());
        last_state_ = result.state;
      }
      ++frames_;
      status_ = result.status;
      observed_ = result.planes.size();
      planes = toPlaneArray(msg->header, map_frame_, result, pipeline_->map());
      if (planes->metric) planes->camera_pose = toPoseMsg(result.pose->map_from_camera);
      if (planes->metric) {
        std_msgs::Header map_header = msg->header;
        map_header.frame_id = map_frame_;
        if (markers_pub_.getNumSubscribers() > 0 || reset_markers_) {
          markers = toMarkers(map_header, pipeline_->map(), markers_shown_);
          if (reset_markers_) {
            visualization_msgs::Marker clear;
            clear.action = visualization_msgs::Marker::DELETEALL;
            markers->markers.insert(markers->markers.begin(), clear);
            reset_markers_ = false;
          }
        }
        if (cloud_pub_.getNumSubscribers() > 0 && pipeline_->poseEstimator())
          cloud = toCloud(map_header, *pipeline_->poseEstimator(), pipeline_->map());
        if (publish_tf_ && odom)  // map -> odom, so that the robot's tf tree stays a tree
          tf = toTransform(result.pose->map_from_camera * odom->inverse(), msg->header, map_frame_,
                           odom_frame_);
        else if (publish_tf_ && !msg->header.frame_id.empty())
          tf = toTransform(result.pose->map_from_camera, msg->header, map_frame_,
                           msg->header.frame_id);
        else if (publish_tf_)
          NODELET_WARN_THROTTLE(10.0, "tracks have an empty frame_id: no map -> camera tf");
      }
      if (debug_pub_.getNumSubscribers() > 0) {
        for (const auto& image : images_)
          if (image->header.stamp == msg->header.stamp) {
            try {
              drawing = drawPlanes(cv_bridge::toCvShare(image, "mono8")->image, result);
            } catch (const cv_bridge::Exception& e) {
              NODELET_WARN_THROTTLE(10.0, "cannot draw on the image: %s", e.what());
            }
          }
      }
    }
    diagnostics_.tick();
    planes->processing_ms = static_cast<float>((ros::WallTime::now() - started).toSec() * 1e3);
    planes_pub_.publish(planes);  // shared pointers: no copy inside one manager
    if (markers) markers_pub_.publish(markers);
    if (cloud) cloud_pub_.publish(cloud);
    if (tf) broadcaster_->sendTransform(*tf);
    if (!drawing.empty())
      debug_pub_.publish(cv_bridge::CvImage(msg->header, "bgr8", drawing).toImageMsg());
  }

  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
    std::lock_guard<std::mutex> lock(mutex_);
    const long exceptions = guard_.count();
    const bool warn = dropped_ > 0 || dropped_info_ > 0 || refused_odom_ > 0 ||
                      camera_switches_ > 0 || exceptions > 0;
    status.summary(
        warn ? diagnostic_msgs::DiagnosticStatus::WARN : diagnostic_msgs::DiagnosticStatus::OK,
        exceptions > 0          ? "exceptions caught"
        : camera_switches_ > 0 ? "tracks mix cameras"
        : status_.empty()      ? "no tracks yet"
                               : status_);
    status.add("exceptions caught (total)", exceptions);
    if (exceptions > 0) status.add("last exception", guard_.lastReason());
    status.add("camera switches (total)", camera_switches_);
    status.add("odometry refused (total)", refused_odom_);
    status.add("images processed", frames_);
    status.add("tracks messages dropped", dropped_);
    status.add("camera_info messages rejected", dropped_info_);
    status.add("planes in this image", observed_);
    status.add("planes in the map", pipeline_->map().planes().size());
    if (pipeline_->poseEstimator())
      status.add("landmarks", pipeline_->poseEstimator()->landmarks().size());
  }

  CallbackGuard guard_;  // first member: the last destroyed
  PipelineParams params_;
  std::unique_ptr<PlanePipeline> pipeline_;
  std::string map_frame_, odom_frame_, transport_;
  bool publish_tf_ = true;

  ros::Publisher planes_pub_, markers_pub_, cloud_pub_;
  ros::Subscriber tracks_sub_, info_sub_;
  std::unique_ptr<image_transport::ImageTransport> image_transport_;
  image_transport::Publisher debug_pub_;
  image_transport::Subscriber image_sub_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> broadcaster_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::Timer no_info_timer_;
  NodeletDiagnostics diagnostics_;

  std::mutex mutex_, connect_mutex_;  // mutex_ guards everything below and the pipeline
  std::deque<sensor_msgs::ImageConstPtr> images_;
  cv::Size info_size_;
  std::set<int> markers_shown_;
  bool reset_markers_ = false;
  PipelineState last_state_ = PipelineState::kNoCamera;
  std::string status_;
  long frames_ = 0, dropped_ = 0, dropped_info_ = 0, refused_odom_ = 0, camera_switches_ = 0;
  double max_odom_jump_m_ = 1.0;
  std::optional<Pose> last_odom_;
  std::string last_frame_id_;
  cv::Size last_tracks_size_;
  size_t observed_ = 0;
};

}  // namespace mono_plane_detection

PLUGINLIB_EXPORT_CLASS(mono_plane_detection::PlaneNodelet, nodelet::Nodelet)
