// The paper's figures 2-3: tracked points in red, new points in blue, ids beside them.
#pragma once

#include <opencv2/core.hpp>
#include <vector>

#include "mono_plane_detection/tracking/feature_tracker.h"

namespace mono_plane_detection {

const cv::Scalar kTrackedColour(0, 0, 255);       // BGR red
const cv::Scalar kNewColour(255, 0, 0);           // BGR blue
const cv::Scalar kReidentifiedColour(0, 200, 0);  // BGR green: lost point come back

// A BGR copy of `image` (mono8 or bgr8) with every point drawn and labelled.
cv::Mat drawTracks(const cv::Mat& image, const std::vector<TrackedPoint>& points);

}  // namespace mono_plane_detection
