// The one place where a sensor_msgs/CameraInfo is judged before OpenCV sees it: image
// size, finite K and P, the distortion model (image_geometry's names) and the number of
// its coefficients OpenCV takes. A later issue extends it to the rectified-P semantics of
// image_geometry::PinholeCameraModel.
#pragma once

#include <sensor_msgs/CameraInfo.h>

#include <opencv2/core.hpp>
#include <string>

namespace mono_plane_detection {

// Empty when usable, else one sentence naming the bad field and value.
std::string cameraInfoError(const sensor_msgs::CameraInfo& info);

// K and D (1 x N, CV_64F; empty D: no distortion) of a usable camera_info (through
// image_geometry::PinholeCameraModel), or the reason it is not usable.
std::string fromCameraInfo(const sensor_msgs::CameraInfo& info, cv::Matx33d& K, cv::Mat& D);

}  // namespace mono_plane_detection
