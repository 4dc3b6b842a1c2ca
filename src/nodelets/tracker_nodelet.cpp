// Thin ROS glue around FeatureTracker: image in, Tracks and a debug image out.
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>

#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <pluginlib/class_list_macros.hpp>

#include "image_input.h"
#include "mono_plane_detection/Tracks.h"
#include "mono_plane_detection/viz/draw_tracks.h"
#include "mono_plane_detection/tracking/feature_tracker.h"
#include "mono_plane_detection/tracking/target_startup.h"
#include "nodelet_diagnostics.h"
#include "param_check.h"

namespace mono_plane_detection {
namespace {

TrackerParams readParams(const ros::NodeHandle& pnh) {
  TrackerParams p;
  pnh.param("max_features", p.max_features, p.max_features);
  pnh.param("min_distance_px", p.min_distance_px, p.min_distance_px);
  pnh.param("quality_level", p.quality_level, p.quality_level);
  pnh.param("block_size", p.block_size, p.block_size);
  pnh.param("pyramid_levels", p.pyramid_levels, p.pyramid_levels);
  pnh.param("window_size_px", p.window_size_px, p.window_size_px);
  pnh.param("max_iterations", p.max_iterations, p.max_iterations);
  pnh.param("epsilon_px", p.epsilon_px, p.epsilon_px);
  pnh.param("min_eigen_threshold", p.min_eigen_threshold, p.min_eigen_threshold);
  pnh.param("redetect_lost_fraction", p.redetect_lost_fraction, p.redetect_lost_fraction);
  pnh.param("redetect_every", p.redetect_every, p.redetect_every);
  pnh.param("match_radius_px", p.match_radius_px, p.match_radius_px);
  pnh.param("forward_backward_check", p.forward_backward_check, p.forward_backward_check);
  pnh.param("forward_backward_max_px", p.forward_backward_max_px, p.forward_backward_max_px);
  pnh.param("reanchor_on_search", p.reanchor_on_search, p.reanchor_on_search);
  pnh.param("reanchor_window_px", p.reanchor_window_px, p.reanchor_window_px);
  pnh.param("reanchor_max_shift_px", p.reanchor_max_shift_px, p.reanchor_max_shift_px);
  pnh.param("mask_existing", p.mask_existing, p.mask_existing);
  pnh.param("reidentify", p.reidentify, p.reidentify);
  pnh.param("reid_memory_frames", p.reid_memory_frames, p.reid_memory_frames);
  pnh.param("reid_max_hamming", p.reid_max_hamming, p.reid_max_hamming);
  pnh.param("reid_ratio", p.reid_ratio, p.reid_ratio);
  pnh.param("reid_max_radius_px", p.reid_max_radius_px, p.reid_max_radius_px);
  return p;
}

// Values that would make OpenCV assert are replaced by the defaults, loudly.
TrackerParams sanitized(TrackerParams p, const std::string& name) {
  const TrackerParams d;
  const ParamCheck fix(name);
  fix(p.max_features < 1, "max_features", p.max_features, d.max_features);
  fix(p.quality_level <= 0 || p.quality_level >= 1, "quality_level", p.quality_level,
      d.quality_level);
  fix(p.block_size < 1, "block_size", p.block_size, d.block_size);
  fix(p.pyramid_levels < 1, "pyramid_levels", p.pyramid_levels, d.pyramid_levels);
  fix(p.window_size_px < 3, "window_size_px", p.window_size_px, d.window_size_px);
  fix(p.reanchor_window_px < 1, "reanchor_window_px", p.reanchor_window_px, d.reanchor_window_px);
  fix(p.max_iterations < 1, "max_iterations", p.max_iterations, d.max_iterations);
  return p;
}

TracksPtr toMessage(const std_msgs::Header& header, const cv::Size& size,
                    const std::vector<TrackedPoint>& points, bool searched) {
  TracksPtr msg(new Tracks);
  msg->header = header;
  msg->width = size.width;
  msg->height = size.height;
  msg->searched = searched;
  const size_t n = points.size();
  msg->id.reserve(n);
  msg->u.reserve(n);
  msg->v.reserve(n);
  msg->prev_index.reserve(n);
  msg->flags.reserve(n);
  msg->age.reserve(n);
  for (const auto& p : points) {
    msg->id.push_back(p.id);
    msg->u.push_back(p.uv.x);
    msg->v.push_back(p.uv.y);
    msg->prev_index.push_back(p.prev_index);
    msg->flags.push_back((p.is_new ? Tracks::FLAG_NEW : 0) |
                         (p.is_tracked ? Tracks::FLAG_TRACKED : 0) |
                         (p.is_reidentified ? Tracks::FLAG_REIDENTIFIED : 0) |
                         (p.is_target_corner ? Tracks::FLAG_TARGET_CORNER : 0));
    msg->age.push_back(p.age);
  }
  return msg;
}

}  // namespace

class TrackerNodelet : public nodelet::Nodelet {
 public:
  ~TrackerNodelet() override {
    std::lock_guard<std::mutex> lock(connect_mutex_);
    image_sub_.shutdown();
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    tracker_ = FeatureTracker(sanitized(readParams(pnh), getName()));
    pnh.param("lazy", lazy_, true);
    pnh.param("detect_target", detect_target_, true);
    pnh.param("max_gap_s", max_gap_s_, 1.0);
    pnh.param("target_width_m", target_params_.width_m, target_params_.width_m);
    pnh.param("target_height_m", target_params_.height_m, target_params_.height_m);
    target_startup_ = TargetStartup(target_params_);
    pnh.param<std::string>("image_transport", transport_, "raw");

    diagnostics_.start(nh, pnh, getName(), "tracking", this, &TrackerNodelet::diagnose);

    it_ = std::make_unique<image_transport::ImageTransport>(nh);
    std::lock_guard<std::mutex> lock(connect_mutex_);
    auto connect = [this](const auto&) { updateSubscription(); };
    tracks_pub_ = nh.advertise<Tracks>("tracks", 10, connect, connect);
    debug_pub_ = it_->advertise("debug_image", 1, connect, connect);
    if (!lazy_) subscribe();
  }

  void subscribe() {
    image_sub_ = it_->subscribe("image", 5, &TrackerNodelet::imageCallback, this,
                                image_transport::TransportHints(transport_));
    info_sub_ = getNodeHandle().subscribe("camera_info", 1, &TrackerNodelet::infoCallback, this);
  }

  // Optional: tracking works in pixels without it. Kept for its size, checked so that
  // a broken camera driver is reported here, where the images arrive.
  void infoCallback(const sensor_msgs::CameraInfoConstPtr& info) {
    const bool usable = info->K[0] > 0 && info->K[4] > 0 && std::isfinite(info->K[0]) &&
                        std::isfinite(info->K[4]) && std::isfinite(info->K[2]) &&
                        std::isfinite(info->K[5]) && info->width > 0 && info->height > 0;
    if (!usable) {
      NODELET_WARN_THROTTLE(10.0,
                            "camera_info has unusable intrinsics (fx=%g fy=%g, %ux%u): "
                            "ignored, tracking goes on in pixels",
                            info->K[0], info->K[4], info->width, info->height);
    }
    std::lock_guard<std::mutex> lock(state_mutex_);
    info_size_ = usable ? cv::Size(info->width, info->height) : cv::Size();
  }

  // Lazy subscription: nobody listens, nothing is tracked. Tracking restarts fresh
  // when a listener comes back, as image_proc's nodelets do.
  void updateSubscription() {
    std::lock_guard<std::mutex> lock(connect_mutex_);
    if (!lazy_) return;
    const bool wanted = tracks_pub_.getNumSubscribers() > 0 || debug_pub_.getNumSubscribers() > 0;
    if (wanted && !image_sub_) {
      subscribe();
    } else if (!wanted && image_sub_) {
      image_sub_.shutdown();
      info_sub_.shutdown();
      std::lock_guard<std::mutex> state_lock(state_mutex_);
      tracker_.reset();
      target_startup_.reset();
      last_stamp_ = ros::Time();
    }
  }

  void imageCallback(const sensor_msgs::ImageConstPtr& msg) {
    diagnostics_.tick();
    const ros::WallTime started = ros::WallTime::now();
    const GreyImage grey = toGrey(msg);
    if (!grey.image) {
      ++dropped_;
      NODELET_ERROR_THROTTLE(5.0, "dropping image: %s", grey.error.c_str());
      return;
    }
    TracksPtr tracks;
    std::vector<TrackedPoint> points;
    {
      std::lock_guard<std::mutex> lock(state_mutex_);
      if (!last_stamp_.isZero() && msg->header.stamp == last_stamp_) {
        ++dropped_;  // the same image twice (a republisher, a bag with duplicates)
        NODELET_WARN_THROTTLE(5.0, "dropping image: its stamp %.3f repeats the previous one",
                              msg->header.stamp.toSec());
        return;
      }
      if (!last_stamp_.isZero() && msg->header.stamp < last_stamp_) {
        NODELET_WARN(
            "image stamp %.3f is before the previous one (%.3f): time went "
            "backwards (bag loop?), tracking starts over",
            msg->header.stamp.toSec(), last_stamp_.toSec());
        tracker_.reset();
        target_startup_.reset();
      } else if (!last_stamp_.isZero() && (msg->header.stamp - last_stamp_).toSec() > max_gap_s_) {
        // After a pause the scene may have moved anywhere: Lucas-Kanade would follow
        // the old points into the wrong places.
        NODELET_WARN_THROTTLE(5.0, "%.1f s without images: tracking lost, starting over",
                              (msg->header.stamp - last_stamp_).toSec());
        tracker_.reset();
        target_startup_.reset();
      }
      if (msg->header.frame_id.empty())
        NODELET_WARN_THROTTLE(10.0,
                              "images have an empty frame_id: tf from the plane "
                              "nodelet will not name the camera");
      if (grey.image->image.size() != last_size_)
        target_startup_.reset();  // the tracker resets too
      last_size_ = grey.image->image.size();
      last_stamp_ = msg->header.stamp;
      if (!info_size_.empty() && info_size_ != grey.image->image.size()) {
        NODELET_WARN_THROTTLE(10.0, "camera_info is for %dx%d images but the image is %dx%d",
                              info_size_.width, info_size_.height, grey.image->image.cols,
                              grey.image->image.rows);
      }
      tracker_.process(grey.image->image);
      // Paper II-A: until the start-up target is seen, look for it; its corners become
      // tracked points flagged as target corners.
      if (detect_target_) {
        if (const auto target = target_startup_.process(grey.image->image, tracker_))
          NODELET_INFO("start-up target found (%.0f grey levels of contrast)", target->contrast);
      }
      points = tracker_.current();
      const TrackerFrameStats& stats = tracker_.lastStats();
      searches_ += stats.searched ? 1 : 0;
      lost_ += stats.lost;
      tracked_now_ = static_cast<int>(points.size());
      tracks = toMessage(msg->header, grey.image->image.size(), points, stats.searched);
      tracks->processing_ms = static_cast<float>((ros::WallTime::now() - started).toSec() * 1e3);
    }
    tracks_pub_.publish(tracks);  // shared pointer: no copy inside one manager

    if (debug_pub_.getNumSubscribers() > 0) {
      cv_bridge::CvImage debug(msg->header, "bgr8", drawTracks(grey.image->image, points));
      debug_pub_.publish(debug.toImageMsg());
    }
  }

  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
    std::lock_guard<std::mutex> lock(state_mutex_);
    status.summary(dropped_ > 0 ? diagnostic_msgs::DiagnosticStatus::WARN
                                : diagnostic_msgs::DiagnosticStatus::OK,
                   dropped_ > 0 ? "images dropped" : "tracking");
    status.add("points tracked", tracked_now_);
    status.add("points lost (total)", lost_);
    status.add("searches (total)", searches_);
    status.add("images dropped (total)", static_cast<long>(dropped_));
    status.add("camera_info", info_size_.empty() ? "none or unusable" : "ok");
    status.add("start-up target", !detect_target_           ? "not searched"
                                  : target_startup_.found() ? "found"
                                                            : "waiting");
  }

  FeatureTracker tracker_;
  bool lazy_ = true;
  std::string transport_;
  std::unique_ptr<image_transport::ImageTransport> it_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber info_sub_;
  ros::Publisher tracks_pub_;
  image_transport::Publisher debug_pub_;

  std::mutex connect_mutex_;  // subscription changes
  std::mutex state_mutex_;    // tracker and counters
  ros::Time last_stamp_;
  double max_gap_s_ = 1.0;  // a longer pause between images is a tracking loss
  std::atomic<long> dropped_{0};
  long lost_ = 0;
  long searches_ = 0;
  int tracked_now_ = 0;
  cv::Size info_size_;  // size of the last usable camera_info, empty when none
  bool detect_target_ = true;
  TargetParams target_params_;
  TargetStartup target_startup_;
  cv::Size last_size_;

  NodeletDiagnostics diagnostics_;
};

}  // namespace mono_plane_detection

PLUGINLIB_EXPORT_CLASS(mono_plane_detection::TrackerNodelet, nodelet::Nodelet)
