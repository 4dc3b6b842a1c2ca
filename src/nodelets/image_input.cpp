#include "image_input.h"

#include <sensor_msgs/image_encodings.h>

#include <sstream>

namespace mono_plane_detection {

GreyImage toGrey(const sensor_msgs::ImageConstPtr& msg) {
  GreyImage out;
  if (msg->width == 0 || msg->height == 0) {
    std::ostringstream why;
    why << "empty image (" << msg->width << "x" << msg->height << ")";
    out.error = why.str();
    return out;
  }
  // A malformed message must not make cv_bridge read past the buffer.
  if (static_cast<uint64_t>(msg->step) * msg->height > msg->data.size() || msg->step < msg->width) {
    std::ostringstream why;
    why << "malformed image: step " << msg->step << " x height " << msg->height
        << " does not fit data of " << msg->data.size() << " bytes";
    out.error = why.str();
    return out;
  }
  try {
    out.image = cv_bridge::toCvShare(msg, sensor_msgs::image_encodings::MONO8);
  } catch (const cv_bridge::Exception& e) {
    out.error = "unsupported encoding '" + msg->encoding + "': " + e.what();
  } catch (const cv::Exception& e) {
    out.error = "cannot convert encoding '" + msg->encoding + "' to mono8: " + e.what();
  }
  return out;
}

}  // namespace mono_plane_detection
