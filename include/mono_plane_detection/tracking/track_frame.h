// One image's tracked points as the plane stage sees them (the content of a Tracks
// message without ROS), and the check that rejects malformed input. ROS-free.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/tracking/feature_tracker.h"

namespace mono_plane_detection {

struct TrackFrame {
  double stamp = 0;  // s
  cv::Size size;     // source image, pixels
  std::vector<std::uint64_t> ids;
  std::vector<cv::Point2d> pixels;
  std::vector<bool> target_corner;  // corner of the start-up target
  // Got its id back from before it was lost (re-identification): an old id that is no
  // sign of a tracker that started over. Empty: none is.
  std::vector<bool> reidentified;
  // The tracker's run (Tracks.tracker_run): another one is a tracker that started over
  // (reloaded, respawned). 0: not said.
  std::uint32_t tracker_run = 0;
};

// The tracker's points of one image as a frame (what the tracker nodelet's Tracks message
// carries), for programs that run tracker and planes in one process.
TrackFrame trackFrameOf(const std::vector<TrackedPoint>& points, double stamp, cv::Size size);

// Points may lie this far outside the image (sub-pixel refinement at the border).
constexpr double kTrackBorderMarginPx = 2.0;

// Empty when the frame is usable; otherwise why not (array lengths differ, a coordinate
// is not finite or more than kTrackBorderMarginPx outside the image, an id repeats, the
// image size is zero).
std::string validateTrackFrame(const TrackFrame& frame);

// Pixel pairs of the points seen in both frames, matched by track id, with the ids.
struct TrackPairs {
  std::vector<std::uint64_t> ids;
  std::vector<cv::Point2d> first, second;
};
TrackPairs matchById(const TrackFrame& first, const TrackFrame& second);

}  // namespace mono_plane_detection
