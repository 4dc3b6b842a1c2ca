// The other start-up target: an ArUco fiducial marker of known dictionary, id and size
// (OpenCV's contrib aruco module). Its corners come in the same map-frame order as the
// sheet's, so the rest of the pipeline does not know which target it saw
// (docs/start_up.md). ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <string>

#include "mono_plane_detection/tracking/target_detector.h"

namespace mono_plane_detection {

// The marker params.marker_id of params.dictionary in an 8-bit grey image. Corners in the
// map frame's order: the marker's own bottom-left, bottom-right, top-right, top-left (as
// printed, upright), whatever the camera's roll: the marker fixes its orientation.
TargetDetection detectMarkerTarget(const cv::Mat& gray, const TargetParams& params);

// Empty when the dictionary name is one of OpenCV's predefined ones, else the reason.
std::string markerParamsError(const TargetParams& params);

// The marker as printed (black border included), side_px square, white quiet zone of
// margin_px around it: for tests, and for users to print (detect_target --print-marker).
cv::Mat drawMarkerImage(const TargetParams& params, int side_px, int margin_px = 0);

}  // namespace mono_plane_detection
