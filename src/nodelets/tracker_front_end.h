// What the tracker nodelet does with one message, without ROS transport, so that tests
// and the message fuzz target (test/fuzz/fuzz_messages.cpp) call exactly what the
// nodelet calls: every input checked before OpenCV sees it, stamps compared in integer
// nanoseconds (ros::Duration throws beyond 2^31 s), images missing from the stream and
// a stream mixing cameras counted.
#pragma once

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "camera_info_check.h"
#include "image_input.h"
#include "recent_events.h"
#include "stretched_wait.h"
#include "mono_plane_detection/Tracks.h"
#include "mono_plane_detection/params/param_table.h"
#include "mono_plane_detection/tracking/feature_tracker.h"
#include "mono_plane_detection/tracking/stream_gaps.h"
#include "mono_plane_detection/tracking/target_startup.h"

namespace mono_plane_detection {

// Something to log; `kind` keys the throttling, so one kind never hides another.
struct LogEvent {
  std::string kind;
  std::string text;
  // Lines of this kind logged per 5 s of wall time: 1, or a few for rare events each
  // worth its line (a bag loop's reset: every loop of a bag played fast is told).
  size_t burst = 1;
};

struct TrackerOutput {
  TracksPtr tracks;               // null when the image was dropped
  std::string dropped;            // why it was dropped (an ERROR or WARN)
  bool dropped_is_error = false;  // bad input, not a repeat
  std::vector<LogEvent> warnings;
  // The camera_info is for another image size (infoSizeMismatch): not used for this image.
  std::string info_mismatch;
  std::vector<std::string> infos;
  GreyImage grey;  // the image as tracked (for the debug drawing)
};

struct TrackerCounts {
  long dropped = 0;          // images refused (bad, too small, repeated stamp)
  long missing = 0;          // images missing from the stream (stamp gaps)
  long camera_switches = 0;  // frame_id or size changed from one image to the next
  long backwards = 0;        // stamps went back (a bag loop): tracking started over
  long info_size_mismatch = 0;  // images the camera_info was not used for (another size)
  long info_frame_mismatch = 0;  // images whose camera_info names another frame_id
  long lost = 0;             // points lost, total
  long searches = 0;         // corner searches, total
  int tracked_now = 0;
};

class TrackerFrontEnd {
 public:
  explicit TrackerFrontEnd(const TrackerNodeParams& params = TrackerNodeParams());

  TrackerOutput process(const sensor_msgs::ImageConstPtr& msg);
  // Kept for its size (checked against the images); the reason when unusable.
  std::string setCameraInfo(const sensor_msgs::CameraInfo& info);
  void reset();  // nobody listens: forget everything but the counts
  // The tracker's parameters while it runs (dynamic_reconfigure; FeatureTracker::setParams):
  // "" when taken, else why not and nothing changes. Validated by the caller.
  std::string setTrackerParams(const TrackerParams& params);
  // The images are rectified (image_proc's image_rect*): camera_info's P describes them,
  // without distortion (image_geometry); else K and D. Call before setCameraInfo.
  void setRectified(bool rectified) { rectified_ = rectified; }

  const TrackerCounts& counts() const { return counts_; }
  bool hasCameraInfo() const { return calibration_.latest().has_value(); }
  // The camera model the target is searched with (cameraModelName).
  std::string cameraModel() const { return cameraModelName(calibration_, last_size_); }
  // A camera_info of the last image's size is used (the newest or an earlier one).
  bool hasCalibrationForImages() const { return calibration_.heldFor(last_size_) != nullptr; }
  // Now: the usable camera_info is for another size than the last image's ("" when it
  // fits or either is missing); a matching camera_info or image clears it at once.
  std::string infoMismatch() const;
  bool targetFound() const { return target_startup_.found(); }
  const TargetStartup& targetStartup() const { return target_startup_; }
  // What a user has to show the camera, from the target parameters ("a white sheet
  // 0.297 x 0.21 m on a darker surface"): the log names it, not only the parameter.
  std::string targetDescription() const;
  // Why the last image gave no target (empty once found or before any image).
  std::string targetReason() const;
  // The last image's candidates by rejection ("weak edge 12, bright surround 2"): which
  // check fails most tells what to fix (light, background, distance).
  std::string targetRejections() const;
  // Seconds of images without a target (stamps), 0 once found.
  double targetWaitS() const;
  // Past target_timeout_s without a target while images arrive.
  bool targetOverdue() const;
  const TrackerNodeParams& params() const { return params_; }
  // Tracks.tracker_run of every message: random, never 0, another for another front end.
  std::uint32_t run() const { return run_; }

 private:
  TrackerNodeParams params_;
  FeatureTracker tracker_;
  TargetStartup target_startup_;
  std::uint32_t run_;  // Tracks.tracker_run: drawn once per front end, kept over reset()
  // The stream's rhythm: every message heard of it, also one dropped as bad (hear()).
  void hear(uint64_t stamp_ns);
  void startOver(uint64_t stamp_ns, bool new_rhythm);
  void hearDropped(const std_msgs::Header& header);
  uint64_t heard_ns_ = 0;       // newest stamp heard of the tracked stream; 0: none yet
  uint64_t last_stamp_ns_ = 0;  // of the last image tracked; 0: none yet
  cv::Size last_size_;
  std::string last_frame_id_;
  bool rectified_ = false;
  // The usable camera_infos (K and D, or P when rectified): the lens the target is
  // undistorted with, given to the target start-up only for images of its size.
  CalibrationHolder calibration_;
  StretchedWait target_wait_;  // images searched for the target (stamps)
  GapCounter gaps_;
  TrackerCounts counts_;
};

}  // namespace mono_plane_detection
