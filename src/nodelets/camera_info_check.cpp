#include "camera_info_check.h"

#include <image_geometry/pinhole_camera_model.h>
#include <sensor_msgs/distortion_models.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <sstream>

#include "mono_plane_detection/mapping/plane_pipeline.h"

namespace mono_plane_detection {

namespace {

// What raw and rectified streams both need: an image size and a finite P.
std::string sizeAndProjectionError(const sensor_msgs::CameraInfo& info) {
  std::ostringstream why;
  if (info.width == 0 || info.height == 0) {
    why << "image size " << info.width << "x" << info.height << " is empty";
    return why.str();
  }
  for (int i = 0; i < 12; ++i)
    if (!std::isfinite(info.P[i])) {
      why << "P[" << i << "] = " << info.P[i] << " is not finite";
      return why.str();
    }
  return {};
}

// image_geometry's model of the camera (binning and ROI applied to K and P), or the reason
// it refused the message.
std::string cameraModelOf(const sensor_msgs::CameraInfo& info,
                          image_geometry::PinholeCameraModel& model) {
  try {
    model.fromCameraInfo(info);
  } catch (const std::exception& e) {
    return std::string("image_geometry refused it: ") + e.what();
  }
  const cv::Size size = model.reducedResolution();
  if (size.width <= 0 || size.height <= 0)
    return "binning " + std::to_string(info.binning_x) + "x" + std::to_string(info.binning_y) +
           " and ROI " + std::to_string(info.roi.width) + "x" + std::to_string(info.roi.height) +
           " leave no image";
  return {};
}

}  // namespace

std::string cameraInfoError(const sensor_msgs::CameraInfo& info) {
  if (std::string error = sizeAndProjectionError(info); !error.empty()) return error;
  std::ostringstream why;
  cv::Matx33d K;
  for (int i = 0; i < 9; ++i) K.val[i] = info.K[i];
  // Empty D is "no distortion" (simulators, rectified streams), whatever the model says.
  if (!info.D.empty()) {
    namespace dm = sensor_msgs::distortion_models;
    if (info.distortion_model == dm::EQUIDISTANT) {
      if (info.D.size() != 4) {
        why << "distortion model 'equidistant' takes 4 coefficients (k1..k4), not "
            << info.D.size();
        return why.str();
      }
      for (double d : info.D)
        if (!std::isfinite(d)) return "an equidistant coefficient is not finite";
      const cv::Mat none;
      return cameraIntrinsicsError(K, none);
    }
    if (info.distortion_model != dm::PLUMB_BOB && info.distortion_model != dm::RATIONAL_POLYNOMIAL)
      return "distortion model '" + info.distortion_model +
             "' is not supported (plumb_bob, rational_polynomial, equidistant)";
  }
  // 1 x N without copying; an empty vector would make reshape throw (issue 15, case 2).
  const cv::Mat D = info.D.empty() ? cv::Mat()
                                   : cv::Mat(1, static_cast<int>(info.D.size()), CV_64F,
                                             const_cast<double*>(info.D.data()));
  if (std::string error = cameraIntrinsicsError(K, D); !error.empty())
    return error;
  return {};
}

std::string fromCameraInfo(const sensor_msgs::CameraInfo& info, cv::Matx33d& K, cv::Mat& D) {
  if (std::string error = cameraInfoError(info); !error.empty()) return error;
  if (!info.D.empty() && info.distortion_model == sensor_msgs::distortion_models::EQUIDISTANT)
    return "distortion model 'equidistant' is not OpenCV's pinhole model (see "
           "intrinsicsFromCameraInfo: cv::fisheye)";
  image_geometry::PinholeCameraModel model;
  if (std::string error = cameraModelOf(info, model); !error.empty()) return error;
  K = model.intrinsicMatrix();  // of the images sent: binning and ROI applied
  D = cv::Mat();
  if (!info.D.empty()) {  // (reshape throws on an empty matrix)
    D = model.distortionCoeffs().clone().reshape(1, 1);
    D.convertTo(D, CV_64F);
  }
  return {};
}

std::string intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info, bool rectified,
                                     CameraIntrinsics& out) {
  out = CameraIntrinsics();
  out.rectified = rectified;
  out.frame_id = tfFrame(info.header.frame_id);
  image_geometry::PinholeCameraModel model;
  if (rectified) {
    // image_geometry: rectified pixels are those of P's left 3x3, without distortion
    // (D belongs to the raw image the stream was rectified from).
    if (std::string error = sizeAndProjectionError(info); !error.empty()) return error;
    if (std::string error = cameraModelOf(info, model); !error.empty()) return error;
    const cv::Matx34d& P = model.projectionMatrix();
    out.K = cv::Matx33d(P(0, 0), P(0, 1), P(0, 2), P(1, 0), P(1, 1), P(1, 2), P(2, 0), P(2, 1),
                        P(2, 2));
    if (std::string error = cameraIntrinsicsError(out.K, cv::Mat()); !error.empty())
      return "P (rectified stream): " + error;
    out.size = model.reducedResolution();
    return {};
  }
  if (std::string error = cameraInfoError(info); !error.empty()) return error;
  if (std::string error = cameraModelOf(info, model); !error.empty()) return error;
  out.size = model.reducedResolution();
  if (!info.D.empty() && info.distortion_model == sensor_msgs::distortion_models::EQUIDISTANT) {
    out.K = model.intrinsicMatrix();
    out.fisheye_D = cv::Mat(1, 4, CV_64F);
    for (int i = 0; i < 4; ++i) out.fisheye_D.at<double>(0, i) = info.D[i];
    return {};
  }
  return fromCameraInfo(info, out.K, out.D);
}

std::string tfFrame(const std::string& frame_id) {
  return frame_id.rfind('/', 0) == 0 ? frame_id.substr(1) : frame_id;
}

std::string infoFrameMismatch(const CameraIntrinsics& camera, const std::string& image_frame_id) {
  const std::string image = tfFrame(image_frame_id);
  if (camera.frame_id.empty() || image.empty() || camera.frame_id == image) return {};
  return "camera_info is of frame '" + camera.frame_id + "', the images of '" + image +
         "': another camera's? Used all the same; remap camera_info to this camera's";
}

std::string infoSizeMismatch(const cv::Size& info_size, const cv::Size& image_size,
                             bool earlier_kept) {
  if (info_size == image_size) return {};
  std::ostringstream why;
  why << "camera_info is for " << info_size.width << "x" << info_size.height
      << " images but the images are " << image_size.width << "x" << image_size.height
      << ": not used for them ("
      << (earlier_kept ? "the last camera_info of their size still is"
                       : "planes stay in image space")
      << "); publish the camera's binning_x/y or ROI in camera_info, or a calibration made at "
      << image_size.width << "x" << image_size.height;
  // image_proc/resize (resize_scale) rounds the image's size but truncates camera_info's:
  // one pixel short in a side is that, from a size the scale does not divide.
  const int dw = image_size.width - info_size.width, dh = image_size.height - info_size.height;
  if (dw >= 0 && dh >= 0 && dw <= 1 && dh <= 1)
    why << " (one pixel short: image_proc/resize, as resize_scale uses it, on a size that "
           "1/resize_scale does not divide: 0.5 needs even sides, 0.25 sides divisible by 4; "
           "else no resize_scale)";
  return why.str();
}

const CameraIntrinsics* CalibrationHolder::heldFor(const cv::Size& size) const {
  if (latest_ && (latest_->size == size || size.empty())) return &*latest_;
  return held_ && held_->size == size ? &*held_ : nullptr;
}

std::string CalibrationHolder::mismatch(const cv::Size& size) const {
  if (!latest_ || size.empty()) return {};
  return infoSizeMismatch(latest_->size, size, held_ && held_->size == size);
}

const CameraIntrinsics* CalibrationHolder::forImages(const cv::Size& size,
                                                     std::string& mismatch_text) {
  if (latest_ && latest_->size == size) held_ = latest_;
  mismatch_text = mismatch(size);
  return heldFor(size);
}

std::string cameraModelName(const CalibrationHolder& calibration, const cv::Size& images) {
  const CameraIntrinsics* held = calibration.heldFor(images);
  return !calibration.latest()     ? "none"
         : !held                   ? "not used: camera_info for another image size"
         : held->rectified         ? "rectified (P)"
         : !held->fisheye_D.empty() ? "equidistant (K, D via cv::fisheye)"
                                   : "raw (K, D)";
}

std::string rectifiedBy(bool rectified_parameter, const std::string& topic) {
  if (rectified_parameter) return "parameter rectified";
  return isRectifiedTopic(topic) ? topic : std::string();
}

bool isRectifiedTopic(const std::string& topic) {
  const std::string base = topic.substr(topic.find_last_of('/') + 1);
  return base.rfind("image_rect", 0) == 0;
}

void undistortFisheye(TrackFrame& frame, const CameraIntrinsics& camera) {
  if (camera.fisheye_D.empty() || frame.pixels.empty()) return;
  std::vector<cv::Point2d> pinhole;
  cv::fisheye::undistortPoints(frame.pixels, pinhole, camera.K, camera.fisheye_D, cv::noArray(),
                               camera.K);
  TrackFrame kept = frame;
  kept.ids.clear();
  kept.pixels.clear();
  kept.target_corner.clear();
  kept.reidentified.clear();
  for (size_t i = 0; i < pinhole.size(); ++i) {
    const cv::Point2d& p = pinhole[i];
    if (!(p.x >= 0 && p.y >= 0 && p.x <= frame.size.width - 1 && p.y <= frame.size.height - 1))
      continue;  // beyond the pinhole image (or not finite): no longer a pixel
    kept.ids.push_back(frame.ids[i]);
    kept.pixels.push_back(p);
    kept.target_corner.push_back(frame.target_corner[i]);
    if (!frame.reidentified.empty()) kept.reidentified.push_back(frame.reidentified[i]);
  }
  frame = std::move(kept);
}

}  // namespace mono_plane_detection
