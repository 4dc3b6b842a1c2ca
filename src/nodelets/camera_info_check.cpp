#include "camera_info_check.h"

#include <image_geometry/pinhole_camera_model.h>
#include <sensor_msgs/distortion_models.h>

#include <cmath>
#include <sstream>

#include "mono_plane_detection/mapping/plane_pipeline.h"

namespace mono_plane_detection {

std::string cameraInfoError(const sensor_msgs::CameraInfo& info) {
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
  cv::Matx33d K;
  for (int i = 0; i < 9; ++i) K.val[i] = info.K[i];
  // Empty D is "no distortion" (simulators, rectified streams), whatever the model says.
  if (!info.D.empty()) {
    namespace dm = sensor_msgs::distortion_models;
    if (info.distortion_model == dm::EQUIDISTANT)
      return "distortion model 'equidistant' (fisheye) is not supported yet";
    if (info.distortion_model != dm::PLUMB_BOB && info.distortion_model != dm::RATIONAL_POLYNOMIAL)
      return "distortion model '" + info.distortion_model +
             "' is not supported (plumb_bob, rational_polynomial)";
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
  if (info.D.empty()) {
    for (int i = 0; i < 9; ++i) K.val[i] = info.K[i];
    D = cv::Mat();
    return {};
  }
  try {
    image_geometry::PinholeCameraModel model;
    model.fromCameraInfo(info);
    K = model.intrinsicMatrix();
    D = model.distortionCoeffs().clone();
    D = D.reshape(1, 1);
    D.convertTo(D, CV_64F);
  } catch (const std::exception& e) {
    return std::string("image_geometry refused it: ") + e.what();
  }
  return {};
}

}  // namespace mono_plane_detection
