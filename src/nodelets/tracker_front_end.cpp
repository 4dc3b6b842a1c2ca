#include "tracker_front_end.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "camera_info_check.h"

namespace mono_plane_detection {
namespace {

TracksPtr toMessage(const std_msgs::Header& header, const cv::Size& size,
                    const std::vector<TrackedPoint>& points, bool searched,
                    const TargetParams& target, std::uint32_t run) {
  TracksPtr msg(new Tracks);
  msg->header = header;
  msg->tracker_run = run;
  msg->width = size.width;
  msg->height = size.height;
  msg->searched = searched;
  msg->target_type = target.target_type;
  const auto corners = targetCornersInMap(target);  // centred: corner 2 is (w/2, h/2)
  msg->target_width_m = static_cast<float>(2 * corners[2].x);
  msg->target_height_m = static_cast<float>(2 * corners[2].y);
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

std::string seconds(uint64_t ns) {
  std::ostringstream out;
  out.precision(3);
  out << std::fixed << static_cast<double>(ns) * 1e-9;
  return out.str();
}

// A run number for this tracker's Tracks (Tracks.tracker_run): random, never 0.
std::uint32_t drawRun() {
  std::random_device device;
  std::uint32_t run = 0;
  while (run == 0) run = device();
  return run;
}

}  // namespace

TrackerFrontEnd::TrackerFrontEnd(const TrackerNodeParams& params)
    : params_(params), tracker_(params.tracker), target_startup_(params.target), run_(drawRun()) {
  validate(params_);  // callers have reported the errors; never run on bad values
  tracker_ = FeatureTracker(params_.tracker);
  target_startup_ = TargetStartup(params_.target);
}

std::string TrackerFrontEnd::setTrackerParams(const TrackerParams& params) {
  const std::string error = tracker_.setParams(params);
  if (error.empty()) params_.tracker = params;
  return error;
}

std::string TrackerFrontEnd::setCameraInfo(const sensor_msgs::CameraInfo& info) {
  std::string error = cameraInfoError(info);
  // A raw image's K and D, a rectified one's P (image_geometry's camera model).
  CameraIntrinsics lens;
  if (error.empty()) error = intrinsicsFromCameraInfo(info, rectified_, lens);
  if (error.empty()) calibration_.offer(lens);  // (binning and ROI applied)
  return error;
}

std::string TrackerFrontEnd::infoMismatch() const {
  return calibration_.mismatch(last_size_);
}

std::string TrackerFrontEnd::targetReason() const {
  if (target_startup_.found()) return {};
  return target_startup_.lastDetection().reason;
}

std::string TrackerFrontEnd::targetDescription() const {
  const TargetParams& t = params_.target;
  std::ostringstream what;
  what.precision(3);
  if (t.target_type == "aruco")
    what << "ArUco marker " << t.dictionary << " id " << t.marker_id << ", " << t.marker_size_m
         << " m";
  else
    what << "a white sheet " << t.width_m << " x " << t.height_m << " m on a darker surface";
  return what.str();
}

std::string TrackerFrontEnd::targetRejections() const {
  if (target_startup_.found()) return {};
  std::ostringstream out;
  const auto& counts = target_startup_.lastDetection().rejected;
  for (int r = 0; r < static_cast<int>(counts.size()); ++r) {
    if (counts[r] == 0) continue;
    out << (out.tellp() > 0 ? ", " : "") << toString(static_cast<TargetRejection>(r)) << " "
        << counts[r];
  }
  return out.str();
}

double TrackerFrontEnd::targetWaitS() const {
  return target_startup_.found() ? 0.0 : target_wait_.seconds();
}

bool TrackerFrontEnd::targetOverdue() const {
  return params_.detect_target && !target_startup_.found() &&
         targetWaitS() > params_.target_timeout_s;
}

void TrackerFrontEnd::reset() {
  tracker_.reset();
  target_startup_.reset();
  target_wait_.reset();
  heard_ns_ = 0;
  last_stamp_ns_ = 0;
  last_size_ = cv::Size();
  last_frame_id_.clear();
  gaps_.reset();
}

// Tracking and the target search start over at this image; `new_rhythm` (a camera
// switch, time going back): the stream's rhythm too (a pause keeps it).
void TrackerFrontEnd::startOver(uint64_t stamp_ns, bool new_rhythm) {
  tracker_.reset();
  target_startup_.reset();
  target_wait_.closeStretch();
  if (!new_rhythm) return;
  gaps_.reset();
  heard_ns_ = stamp_ns;
}

// Images missing from the stream are counted between the messages heard of the tracked
// stream, the ones dropped here as bad (an encoding, a size) included: such an image
// arrived and is counted as dropped; its stamp closes the interval, so it is not counted
// as missing too (between tracked images only, a stream's bad phases counted each bad
// image twice). A bad message of another camera, or stamped before the last one heard,
// changes nothing here: the tracked images decide switches and time going back.
void TrackerFrontEnd::hear(uint64_t stamp_ns) {
  if (heard_ns_ != 0 && stamp_ns > heard_ns_) {
    const auto interval = static_cast<int64_t>(stamp_ns - heard_ns_);
    if (gaps_.isPause(interval, params_.max_gap_s))
      gaps_.addPause(interval);
    else
      counts_.missing += gaps_.add(interval);
  }
  heard_ns_ = std::max(heard_ns_, stamp_ns);
}

// (A stamp a pause away from the stream's is not heard either: a bad message with a
// broken clock would leave the rhythm waiting for its future stamp.)
void TrackerFrontEnd::hearDropped(const std_msgs::Header& header) {
  const bool same_camera = header.frame_id.empty() || last_frame_id_.empty() ||
                           header.frame_id == last_frame_id_;
  const uint64_t stamp_ns = header.stamp.toNSec();
  if (last_stamp_ns_ == 0 || !same_camera || stamp_ns <= heard_ns_) return;
  if (gaps_.isPause(static_cast<int64_t>(stamp_ns - heard_ns_), params_.max_gap_s)) return;
  hear(stamp_ns);
}

TrackerOutput TrackerFrontEnd::process(const sensor_msgs::ImageConstPtr& msg) {
  TrackerOutput out;
  out.grey = toGrey(msg);
  if (!out.grey.image) {
    hearDropped(msg->header);
    ++counts_.dropped;
    out.dropped = out.grey.error;
    out.dropped_is_error = true;
    return out;
  }
  const cv::Mat& image = out.grey.image->image;
  if (std::string error = imageSizeError(image.size(), params_.tracker); !error.empty()) {
    hearDropped(msg->header);
    ++counts_.dropped;
    out.dropped = error;
    out.dropped_is_error = true;
    return out;
  }
  // Integer nanoseconds: (a - b) as a ros::Duration throws beyond 2^31 s (a driver with
  // an uninitialised clock sends secs = 4000000000 after 1.7e9).
  const uint64_t stamp_ns = msg->header.stamp.toNSec();
  if (last_stamp_ns_ != 0 && stamp_ns == last_stamp_ns_) {
    ++counts_.dropped;  // the same image twice (a republisher, a bag with duplicates)
    out.dropped = "its stamp " + seconds(stamp_ns) + " repeats the previous one";
    return out;
  }
  // An empty frame_id names no camera (a driver that leaves it out): not a switch.
  const bool other_frame = !msg->header.frame_id.empty() && !last_frame_id_.empty() &&
                           msg->header.frame_id != last_frame_id_;
  const bool switched = last_stamp_ns_ != 0 && (other_frame || image.size() != last_size_);
  if (switched) {
    ++counts_.camera_switches;
    std::ostringstream why;
    why << "the image stream changed camera (frame_id '" << last_frame_id_ << "' " << last_size_.width
        << "x" << last_size_.height << " -> '" << msg->header.frame_id << "' " << image.cols << "x"
        << image.rows << "): tracking starts over; one camera per image topic";
    out.warnings.push_back({"camera switch", why.str()});
    startOver(stamp_ns, true);
  } else if (last_stamp_ns_ != 0 && stamp_ns < last_stamp_ns_) {
    out.warnings.push_back({"backwards", "image stamp " + seconds(stamp_ns) +
                                             " is before the previous one (" +
                                             seconds(last_stamp_ns_) +
                                             "): time went backwards (bag loop?), tracking "
                                             "starts over",
                            kRareEventBurst});
    ++counts_.backwards;
    startOver(stamp_ns, true);
  } else if (last_stamp_ns_ != 0) {
    const uint64_t gap_ns = stamp_ns - last_stamp_ns_;
    // Judged before this interval joins the rhythm (a 1 Hz stream's first pauses).
    const bool pause = gaps_.isPause(static_cast<int64_t>(gap_ns), params_.max_gap_s);
    hear(stamp_ns);
    if (pause) {
      // After a pause the scene may have moved anywhere: Lucas-Kanade would follow the
      // old points into the wrong places. The stream's rhythm stays (a low-rate camera
      // learns its period through its first pauses).
      out.warnings.push_back({"gap", seconds(gap_ns) + " s without images: tracking lost, "
                                                       "starting over"});
      startOver(stamp_ns, false);
    }
  }
  if (msg->header.frame_id.empty())
    out.warnings.push_back({"frame_id", "images have an empty frame_id: tf from the plane "
                                        "nodelet will not name the camera"});
  last_size_ = image.size();
  last_stamp_ns_ = stamp_ns;
  heard_ns_ = std::max(heard_ns_, stamp_ns);
  if (!msg->header.frame_id.empty()) last_frame_id_ = msg->header.frame_id;
  // A camera_info for another image size is not this image's camera: its lens would bend
  // the sheet's sides and its focal length misjudge its shape (searched as a photo instead).
  // The last one of this size is used, else none.
  const CameraIntrinsics* lens = calibration_.forImages(image.size(), out.info_mismatch);
  if (!out.info_mismatch.empty()) ++counts_.info_size_mismatch;
  if (lens) {
    if (std::string other = infoFrameMismatch(*lens, msg->header.frame_id); !other.empty()) {
      ++counts_.info_frame_mismatch;
      out.warnings.push_back({"camera_info frame", other});
    }
  }
  tracker_.process(image);
  // The target is searched with the lens undone (straight sides) and its aspect judged
  // with the focal length of the pixels it is searched in.
  const double focal_px = lens ? lens->K(0, 0) : 0;
  const cv::Point2d principal_px = lens ? cv::Point2d(lens->K(0, 2), lens->K(1, 2))
                                        : cv::Point2d(-1, -1);
  if (params_.detect_target) {
    const bool fisheye = lens && !lens->fisheye_D.empty();
    target_startup_.setLens(lens ? lens->K : cv::Matx33d::eye(),
                            lens ? (fisheye ? lens->fisheye_D : lens->D) : cv::Mat(), fisheye);
  }
  // Paper II-A: until the start-up target is seen, look for it; its corners become
  // tracked points flagged as target corners.
  if (params_.detect_target && !target_startup_.found()) {
    // The wait counts in image stamps over the stretches searched since the last reset()
    // (a jump or pause of the stamps closes one: startOver()).
    target_wait_.seen(static_cast<double>(stamp_ns) * 1e-9);
    if (const auto target =
            target_startup_.process(image, tracker_, focal_px, principal_px)) {
      std::ostringstream what;
      what << "start-up target (" << params_.target.target_type << ") confirmed in "
           << params_.target.confirm_frames << " consecutive images";
      if (params_.target.target_type == "sheet")
        what << " (" << std::lround(target->contrast) << " grey levels of contrast)";
      out.infos.push_back(what.str());
      // Found: the wait ends. After a bag loop (or a loss) the search starts over and
      // its wait counts from there, as the plane nodelet's does.
      target_wait_.reset();
    } else if (targetOverdue()) {
      std::ostringstream why;
      why.precision(1);
      why << std::fixed << "no start-up target (" << targetDescription() << ") for "
          << targetWaitS() << " s: " << targetReason()
          << "; planes stay in image space until one is seen (or start the metres without "
             "it: metric_source odometry or camera_height)";
      out.warnings.push_back({"target timeout", why.str()});
    }
  } else if (params_.detect_target) {
    // Confirmed: found again around its tracked corners, which then do not drift.
    target_startup_.process(image, tracker_, focal_px, principal_px);
  }
  const TrackerFrameStats& stats = tracker_.lastStats();
  counts_.searches += stats.searched ? 1 : 0;
  counts_.lost += stats.lost;
  counts_.tracked_now = static_cast<int>(tracker_.current().size());
  out.tracks = toMessage(msg->header, image.size(), tracker_.current(), stats.searched,
                         params_.target, run_);
  return out;
}

}  // namespace mono_plane_detection
