// Thin ROS glue around TrackerFrontEnd (FeatureTracker + checks): image in, Tracks and
// a debug image out. Every callback runs inside guard_ (callback_guard.h).
#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <std_srvs/Empty.h>

#include <iomanip>
#include <map>
#include <memory>
#include <mutex>
#include <pluginlib/class_list_macros.hpp>
#include <sstream>

#include "callback_guard.h"
#include "camera_info_check.h"
#include "mono_plane_detection/TrackerConfig.h"
#include "mono_plane_detection/viz/draw_tracks.h"
#include "nodelet_diagnostics.h"
#include "recent_events.h"
#include "reconfigure_bridge.h"
#include "ros_params.h"
#include "tracker_front_end.h"

namespace mono_plane_detection {

class TrackerNodelet : public nodelet::Nodelet {
 public:
  ~TrackerNodelet() override {
    std::lock_guard<std::mutex> lock(connect_mutex_);
    image_sub_.shutdown();
  }

 private:
  void onInit() override {
    initOrAbandon(
        getName(), [this] { init(); }, [this] { abandonInit(); });
  }

  void abandonInit() {
    std::lock_guard<std::mutex> lock(connect_mutex_);
    diagnostics_.stop();
    image_sub_.shutdown();
    info_sub_.shutdown();
    tracks_pub_.shutdown();
    debug_pub_.shutdown();
    reset_srv_.shutdown();
    reconfigure_.stop();
    it_.reset();
  }

  void init() {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    guard_.setLogger(getName());
    TrackerNodeParams params;
    config_errors_ = readParams(pnh, trackerNodeParamTable(), params, getName());
    front_ = TrackerFrontEnd(params);
    // Rectified images (said so, or image_proc's image_rect*): P without distortion, as
    // the plane nodelet reads them; else the raw image's K and D (the target is searched
    // undistorted).
    image_topic_ = nh.resolveName("image");
    const std::string rectified_by = rectifiedBy(params.rectified, image_topic_);
    front_.setRectified(!rectified_by.empty());
    if (!rectified_by.empty())
      NODELET_INFO("rectified images (%s): camera_info's P is used, without distortion",
                   rectified_by.c_str());

    diagnostics_.start(nh, pnh, getName(), "tracking", this, &TrackerNodelet::diagnose, guard_,
                       params.expected_min_rate_hz, params.expected_max_rate_hz);
    // The corner search, its triggers, LK's stopping rules and checks, re-identification
    // (cfg/Tracker.cfg): taken between images, without losing the tracks.
    reconfigure_.start(pnh, trackerNodeParamTable(), trackerRuntimeParamNames(), front_.params(),
                       [this](TrackerConfig& config, bool first) {
                         guard_.run("reconfigure", [&] { onReconfigure(config, first); });
                       });

    it_ = std::make_unique<image_transport::ImageTransport>(nh);
    std::lock_guard<std::mutex> lock(connect_mutex_);
    auto connect = guard_.wrap("connect", [this](const auto&) { updateSubscription(); });
    tracks_pub_ = nh.advertise<Tracks>("tracks", 10, connect, connect);
    debug_pub_ = it_->advertise("debug_image", 1, connect, connect);
    if (!front_.params().lazy) subscribe();
    diagnostics_.setIdle(front_.params().lazy);  // until a listener comes
    reset_srv_ = pnh.advertiseService("reset", &TrackerNodelet::onReset, this);
  }

  void onReconfigure(TrackerConfig& config, bool first) {
    std::lock_guard<std::mutex> lock(state_mutex_);
    TrackerNodeParams node;
    std::vector<std::string> errors = reconfigure_.take(config, front_.params(), node);
    // (Only the tracker's runtime parameters are in the .cfg: FeatureTracker takes them.)
    if (const std::string refused = front_.setTrackerParams(node.tracker); !refused.empty()) {
      errors.push_back(refused);
      reconfigure_.writeBack(front_.params(), config);
    }
    for (const std::string& error : errors) NODELET_ERROR("reconfigure: %s", error.c_str());
    reconfigure_errors_ = errors;
    if (!first) ++reconfigures_;
  }

  // ~reset: every track and the start-up target start over (ids keep increasing, so no
  // listener mistakes a new point for an old one); the counts stay.
  bool onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&) {
    bool done = false;
    guard_.run("reset", [&] {
      std::lock_guard<std::mutex> lock(state_mutex_);
      front_.reset();
      ++resets_;
      NODELET_INFO("reset: tracks and the start-up target start over");
      done = true;
    });
    return done;
  }

  void subscribe() {
    image_sub_ = it_->subscribe(
        "image", 5, guard_.message("image", this, &TrackerNodelet::imageCallback), ros::VoidPtr(),
        image_transport::TransportHints(front_.params().image_transport));
    info_sub_ = getNodeHandle().subscribe<sensor_msgs::CameraInfo>(
        "camera_info", 1, guard_.message("camera_info", this, &TrackerNodelet::infoCallback));
    std::lock_guard<std::mutex> state_lock(state_mutex_);
    subscribed_at_ = ros::WallTime::now();
  }

  // Optional: tracking works in pixels without it. Kept for its size, checked so that
  // a broken camera driver is reported here, where the images arrive.
  void infoCallback(const sensor_msgs::CameraInfoConstPtr& info) {
    std::lock_guard<std::mutex> lock(state_mutex_);
    const std::string error = front_.setCameraInfo(*info);
    if (!error.empty() &&
        problems_.note("camera_info " + reasonKind(error), "camera_info unusable: " + error, 10.0))
      NODELET_WARN("camera_info unusable (%s): ignored, %s", error.c_str(),
                   front_.hasCameraInfo() ? "the last usable one stays in use"
                                          : "tracking goes on in pixels");
  }

  // Lazy subscription: nobody listens, nothing is tracked. Tracking restarts fresh
  // when a listener comes back, as image_proc's nodelets do.
  void updateSubscription() {
    std::lock_guard<std::mutex> lock(connect_mutex_);
    if (!front_.params().lazy) return;
    const bool wanted = tracks_pub_.getNumSubscribers() > 0 || debug_pub_.getNumSubscribers() > 0;
    diagnostics_.setIdle(!wanted);
    if (wanted && !image_sub_) {
      // A transport that is not installed (image_transport: compressed on Debian 12)
      // throws here, when the first listener comes: said once per listener as what it
      // is, and kept in diagnostics (ERROR) until a subscription works.
      std::string error;
      try {
        subscribe();
      } catch (const std::exception& e) {
        // pluginlib's text spans lines and lists every plugin: its first line says it.
        std::string why = e.what();
        why = why.substr(0, why.find('\n'));
        error = std::string("cannot subscribe to ") + getNodeHandle().resolveName("image") +
                " with image_transport '" + front_.params().image_transport + "' (" + why +
                "): no tracks; install that transport or set image_transport: raw";
        // (each listener retries; throttled on wall time, as every log line here)
        if (logged_.note("subscribe", error, 10.0)) NODELET_ERROR("%s", error.c_str());
      }
      std::lock_guard<std::mutex> state_lock(state_mutex_);
      subscribe_error_ = error;
    } else if (!wanted && image_sub_) {
      image_sub_.shutdown();
      info_sub_.shutdown();
      std::lock_guard<std::mutex> state_lock(state_mutex_);
      front_.reset();
      subscribed_at_ = ros::WallTime();
      stream_health_.forget();  // (its WARN stayed 5 s while idle: hostile try)
    }
  }

  // One throttle per kind of event, so that one kind never hides another.
  void warn(const LogEvent& event) {
    // A camera switch is also a problem of the stream for diagnostics (while recent).
    if (event.kind == "camera switch")
      problems_.note("camera switch", "image stream mixes cameras");
    if (event.kind == "backwards") stream_health_.wentBackwards();
    if (logged_.note(event.kind, event.text, 5.0, event.burst))
      NODELET_WARN("%s", event.text.c_str());
  }

  void imageCallback(const sensor_msgs::ImageConstPtr& msg) {
    diagnostics_.tick();
    const ros::WallTime started = ros::WallTime::now();
    TrackerOutput out;
    {
      std::lock_guard<std::mutex> lock(state_mutex_);
      if (first_image_.isZero()) first_image_ = started;
      last_image_ = started;
      const long missing_before = front_.counts().missing;
      out = front_.process(msg);
      stream_health_.received(front_.counts().missing - missing_before);
      for (const LogEvent& event : out.warnings) warn(event);
      // Not this image's camera (the front end does not use it): an ERROR, on wall time.
      if (!out.info_mismatch.empty() && logged_.note("info size", out.info_mismatch, 10.0))
        NODELET_ERROR("%s", out.info_mismatch.c_str());
      // Before target_timeout_s: why the target is not seen yet, now and then (after it, a
      // WARN says so every 5 s). On wall time: ROS time stands still under use_sim_time
      // without /clock, and goes back in a bag loop (it was never said then; hostile try).
      if (out.tracks && front_.params().detect_target && !front_.targetFound() &&
          !front_.targetOverdue() && logged_.note("target wait", "", 10.0))
        NODELET_INFO("waiting for the start-up target (%s): %s", front_.targetDescription().c_str(),
                     front_.targetReason().c_str());
      if (!out.tracks) {
        // One throttle per reason: each kind of bad image is named at least once.
        if (problems_.note(reasonKind(out.dropped), "image dropped: " + out.dropped)) {
          if (out.dropped_is_error)
            NODELET_ERROR("dropping image: %s", out.dropped.c_str());
          else
            NODELET_WARN("dropping image: %s", out.dropped.c_str());
        }
        return;
      }
    }
    for (const std::string& info : out.infos) NODELET_INFO("%s", info.c_str());
    out.tracks->processing_ms = static_cast<float>((ros::WallTime::now() - started).toSec() * 1e3);
    tracks_pub_.publish(out.tracks);  // shared pointer: no copy inside one manager

    if (debug_pub_.getNumSubscribers() > 0) {
      std::vector<TrackedPoint> points;  // drawn from the message: the tracker moved on
      for (size_t i = 0; i < out.tracks->id.size(); ++i) {
        TrackedPoint p;
        p.id = out.tracks->id[i];
        p.uv = cv::Point2f(out.tracks->u[i], out.tracks->v[i]);
        p.is_new = out.tracks->flags[i] & Tracks::FLAG_NEW;
        p.is_tracked = out.tracks->flags[i] & Tracks::FLAG_TRACKED;
        p.is_reidentified = out.tracks->flags[i] & Tracks::FLAG_REIDENTIFIED;
        p.is_target_corner = out.tracks->flags[i] & Tracks::FLAG_TARGET_CORNER;
        p.prev_index = out.tracks->prev_index[i];
        p.age = out.tracks->age[i];
        points.push_back(p);
      }
      cv_bridge::CvImage debug(msg->header, "bgr8", drawTracks(out.grey.image->image, points));
      debug_pub_.publish(debug.toImageMsg());
    }
  }

  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
    using diagnostic_msgs::DiagnosticStatus;
    std::lock_guard<std::mutex> lock(state_mutex_);
    const TrackerCounts& c = front_.counts();
    const long exceptions = guard_.count();
    const bool no_target = front_.targetOverdue();
    const ros::WallTime now = ros::WallTime::now();
    // Images for a while and no usable camera_info: tracking goes on in pixels, but the
    // plane nodelet needs it for metres and the target check for the sheet's aspect.
    const bool no_info = !front_.hasCameraInfo() && !first_image_.isZero() &&
                         (now - first_image_).toSec() > kCameraInfoGraceS;
    // The present state first, then what happened lately (drops and camera switches count
    // for the level while recent: the totals stay below).
    StatusProblems problems;
    if (!subscribe_error_.empty())
      problems.add(DiagnosticStatus::ERROR, "subscription", subscribe_error_);
    const std::string info_mismatch = front_.infoMismatch();
    if (!info_mismatch.empty()) problems.add(DiagnosticStatus::ERROR, "camera_info", info_mismatch);
    // Lazy and nobody listens: nothing is subscribed, nothing tracked (it said "tracking").
    std::string ok_text = subscribed_at_.isZero() && front_.params().lazy
                              ? "idle: nobody listens, nothing tracked (lazy)"
                              : "tracking";
    if (!subscribed_at_.isZero()) {
      // Subscribed (not idle) and no image for a while, yet or lately: nothing is tracked.
      // (Not at once: a driver takes a moment to send its first image after a subscription.)
      const ros::WallTime since = std::max(subscribed_at_, last_image_);
      const double silent_s = (now - since).toSec();
      const bool none_yet = last_image_ < subscribed_at_;
      if (none_yet) ok_text = "waiting for the first image on " + image_topic_;
      if (silent_s > kNoImagesS) {
        std::ostringstream why;
        why << std::fixed << std::setprecision(0) << "no images on " << image_topic_
            << (none_yet ? " yet (subscribed " : " for ") << silent_s
            << (none_yet ? " s ago)" : " s");
        problems.add(DiagnosticStatus::WARN, "images", why.str());
      }
    }
    if (exceptions > 0) problems.add(DiagnosticStatus::WARN, "exceptions", "exceptions caught");
    if (no_info)
      problems.add(DiagnosticStatus::WARN, "camera_info", "images but no usable camera_info");
    if (no_target)
      problems.add(DiagnosticStatus::WARN, "start-up target",
                   "no start-up target: " + front_.targetReason());
    problems.addWarnings(stream_health_.problems(
        "images",
        "the subscriber queue overflowed: tracking is slower than the stream, e.g. under "
        "CPU load; or the driver or the network dropped them",
        "tracking starting over", "image"));
    // (replaced by the defaults: after the present problems)
    if (const auto refused = refusedParams(config_errors_, reconfigure_errors_); !refused.empty())
      problems.add(DiagnosticStatus::WARN, "configuration", refusedParamsText(refused));
    problems.addWarnings(problems_.recent(kRecentS), "last 10 s, ");
    problems.report(status, ok_text);
    status.add("points tracked", c.tracked_now);
    status.add("points lost (total)", c.lost);
    status.add("searches (total)", c.searches);
    status.add("images dropped (total)", c.dropped);
    status.add("images missing from the stream (total)", c.missing);
    status.add("camera switches (total)", c.camera_switches);
    status.add("exceptions caught (total)", exceptions);
    if (exceptions > 0) status.add("last exception", guard_.lastReason());
    status.add("camera_info", !front_.hasCameraInfo() ? "none or unusable"
                              : info_mismatch.empty() ? "ok"
                              : front_.hasCalibrationForImages()
                                  ? "the last of the images' size "
                                    "(the newest is for another size)"
                                  : "for another image size: not used");
    status.add("camera model", front_.cameraModel());
    status.add("images with camera_info of another size (total)", c.info_size_mismatch);
    status.add("images with camera_info of another frame_id (total)", c.info_frame_mismatch);
    // Every start over of the tracks: ~reset calls and stamps going back (a bag loop).
    status.add("resets (total)", resets_ + c.backwards);
    status.add("resets: time went backwards (total)", c.backwards);
    status.add("reconfigurations (total)", reconfigures_);
    status.add("start-up target", !front_.params().detect_target ? "not searched"
                                  : front_.targetFound()         ? "found"
                                                                 : "waiting");
    if (front_.targetFound() && front_.params().target.redetect_tracked) {
      // Never moved while the sheet is tracked: its re-detection fails (e.g. the region
      // too small or its surround changed); the start then uses the tracks as they drift.
      const TargetStartup& t = front_.targetStartup();
      std::ostringstream moved;
      moved << t.reanchoredImages() << " of " << t.followedImages()
            << " images with its four corners tracked (last move " << std::fixed
            << std::setprecision(2) << t.lastReanchorShiftPx() << " px)";
      status.add("target: corners re-detected", moved.str());
    }
    if (front_.params().detect_target && !front_.targetFound()) {
      // What to fix at the robot: light, background, distance (docs/start_up.md).
      status.add("target type", front_.params().target.target_type);
      status.add("target: last rejection", front_.targetReason());
      status.add("target: candidates rejected (last image)", front_.targetRejections());
      status.add("target: waiting (s)", front_.targetWaitS());
      status.add("target: overdue", no_target);  // past target_timeout_s
    }
  }

  CallbackGuard guard_;  // first member: the last destroyed
  TrackerFrontEnd front_;
  std::unique_ptr<image_transport::ImageTransport> it_;
  image_transport::Subscriber image_sub_;
  ros::Subscriber info_sub_;
  ros::Publisher tracks_pub_;
  image_transport::Publisher debug_pub_;
  ros::ServiceServer reset_srv_;
  ros::WallTime first_image_;  // wall: diagnostics must hold under sim time
  ros::WallTime last_image_;
  ros::WallTime subscribed_at_;              // zero while not subscribed (lazy, nobody listens)
  std::string image_topic_;                  // resolved
  static constexpr double kNoImagesS = 5.0;  // the input rate's window: a stream stopped
                                             // or none since the subscription
  std::vector<std::string> config_errors_;   // parameters refused at start (set in init)
  std::vector<std::string> reconfigure_errors_;  // refused by the last reconfigure
  long reconfigures_ = 0;
  StreamHealth stream_health_;               // images missing, time going back (last 10 s)
  std::string subscribe_error_;  // why the lazy image subscription failed, "" when it did not
  long resets_ = 0;

  std::mutex connect_mutex_;  // subscription changes
  std::mutex state_mutex_;    // front_ and the log throttles

  RecentEvents problems_;                   // dropped images, unusable camera_info
  static constexpr double kRecentS = 10.0;  // a WARN in diagnostics lasts this long
  RecentEvents logged_;                     // the front end's warnings: one throttle per kind

  NodeletDiagnostics diagnostics_;
  // Last: destroyed first, so no reconfigure callback outlives what it locks and changes.
  ReconfigureBridge<TrackerConfig, TrackerNodeParams> reconfigure_;
};

}  // namespace mono_plane_detection

PLUGINLIB_EXPORT_CLASS(mono_plane_detection::TrackerNodelet, nodelet::Nodelet)
