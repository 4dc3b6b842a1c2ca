// Turns an incoming sensor_msgs/Image into an 8-bit grey cv::Mat, or says why not.
#pragma once

#include <cv_bridge/cv_bridge.h>
#include <sensor_msgs/Image.h>

#include <string>

namespace mono_plane_detection {

struct GreyImage {
  cv_bridge::CvImageConstPtr image;  // mono8; null when the message was rejected
  std::string error;                 // why it was rejected, naming the bad value
};

// Accepts every encoding cv_bridge can turn into mono8 (mono8, mono16, bgr8, rgb8,
// bgra8, rgba8, bayer_*, ...). Rejects empty images, inconsistent sizes and other
// encodings. Shares the message's buffer when it is already mono8.
GreyImage toGrey(const sensor_msgs::ImageConstPtr& msg);

}  // namespace mono_plane_detection
