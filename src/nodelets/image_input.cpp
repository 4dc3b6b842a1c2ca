#include "image_input.h"

#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <sstream>

namespace mono_plane_detection {
namespace {

// cv_bridge hands big-endian multi-byte images through without swapping (Debian 12's
// version returned a 16-bit image for a mono8 request): swap them here.
sensor_msgs::ImageConstPtr littleEndian(const sensor_msgs::ImageConstPtr& msg) {
  if (!msg->is_bigendian) return msg;
  int bytes = 1;
  try {
    bytes = sensor_msgs::image_encodings::bitDepth(msg->encoding) / 8;
  } catch (const std::exception&) {
    return msg;  // unknown encoding: cv_bridge will say so
  }
  if (bytes <= 1) return msg;
  sensor_msgs::ImagePtr copy(new sensor_msgs::Image(*msg));
  for (size_t i = 0; i + bytes <= copy->data.size(); i += bytes)
    std::reverse(copy->data.begin() + i, copy->data.begin() + i + bytes);
  copy->is_bigendian = 0;
  return copy;
}

// A known encoding without grey levels (depth, disparity: 16UC1, 32FC1, ...): cv_bridge
// refuses it with "[16UC1] is not a color format. but [mono8] is. The conversion does not
// make sense", which a user at the robot does not read as "wrong topic".
bool isDataEncoding(const std::string& encoding) {
  namespace enc = sensor_msgs::image_encodings;
  if (enc::isColor(encoding) || enc::isMono(encoding) || enc::isBayer(encoding)) return false;
  try {
    return enc::bitDepth(encoding) > 0;  // (throws for unknown ones)
  } catch (const std::exception&) {
    return false;
  }
}

std::string dataEncodingAdvice(const std::string& encoding) {
  return "depth or other single-value images (" + encoding +
         ") are not supported; use the camera's grey or colour image (mono8/mono16 or bgr8), "
         "not its depth";
}

}  // namespace

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
    out.image = cv_bridge::toCvShare(littleEndian(msg), sensor_msgs::image_encodings::MONO8);
  } catch (const cv_bridge::Exception& e) {
    out.error = "unsupported encoding '" + msg->encoding + "': " +
                (isDataEncoding(msg->encoding) ? dataEncodingAdvice(msg->encoding) : e.what());
    return out;
  } catch (const cv::Exception& e) {
    out.error = "cannot convert encoding '" + msg->encoding + "' to mono8: " + e.what();
    return out;
  } catch (const std::exception& e) {
    out.error = "cannot convert encoding '" + msg->encoding + "': " + e.what();
    return out;
  }
  // Never hand the tracker anything but 8-bit grey, whatever cv_bridge returned.
  if (!out.image || out.image->image.empty() || out.image->image.type() != CV_8UC1) {
    out.error = "encoding '" + msg->encoding + "' did not convert to 8-bit grey";
    out.image.reset();
  }
  return out;
}

}  // namespace mono_plane_detection
