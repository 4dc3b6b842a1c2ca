// The paper's figures 7-8 for a running system: the accepted five-point groups, every
// plane's points in the plane's colour, the dominant plane's voters ringed, and the
// pipeline's status. ROS-free.
#pragma once

#include <opencv2/core.hpp>

#include "mono_plane_detection/mapping/plane_pipeline.h"

namespace mono_plane_detection {

// A distinct BGR colour per plane id (also used for the rviz markers).
cv::Scalar planeColour(int id);

// A BGR copy of `image` (mono8 or bgr8) with the result drawn; at most max_groups groups.
cv::Mat drawPlanes(const cv::Mat& image, const PipelineResult& result, int max_groups = 30);

}  // namespace mono_plane_detection
