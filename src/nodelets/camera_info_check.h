// The one place where a sensor_msgs/CameraInfo is judged before OpenCV sees it: image
// size, finite K and P, the distortion model (image_geometry's names) and the number of
// its coefficients OpenCV takes; and what image_geometry::PinholeCameraModel says the
// pixels of a stream mean: a raw image has K and D, a rectified one (image_proc's
// image_rect) has P and no distortion, both of the images binning and ROI leave (a
// camera_info's width, height, K and P are the sensor's); equidistant (fisheye) pixels
// are moved to the pinhole image of the same K with cv::fisheye before the core sees them.
#pragma once

#include <sensor_msgs/CameraInfo.h>

#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "mono_plane_detection/tracking/track_frame.h"

namespace mono_plane_detection {

// Images or tracks may come this long (wall time, s) before a usable camera_info without a
// WARN: drivers and bags send it with the first images, not always before them.
constexpr double kCameraInfoGraceS = 5.0;

// Empty when usable, else one sentence naming the bad field and value.
std::string cameraInfoError(const sensor_msgs::CameraInfo& info);

// K and D (1 x N, CV_64F; empty D: no distortion) of a usable raw camera_info with
// OpenCV's pinhole model (through image_geometry::PinholeCameraModel: K of the images
// sent, binning and ROI applied), or the reason it is not usable (equidistant included:
// intrinsicsFromCameraInfo handles it).
std::string fromCameraInfo(const sensor_msgs::CameraInfo& info, cv::Matx33d& K, cv::Mat& D);

// The camera as the core sees it.
struct CameraIntrinsics {
  cv::Size size;      // of the images it describes: width x height less binning and ROI
  cv::Matx33d K;      // of the pixels given to the core
  cv::Mat D;          // OpenCV's model (plumb_bob, rational_polynomial); empty: none
  cv::Mat fisheye_D;  // equidistant (1 x 4): tracks go through undistortFisheye first
  bool rectified = false;
  std::string frame_id;  // camera_info's header.frame_id, tf style (no leading '/')
};

// rectified: the stream is rectified (P, no distortion), else raw (K, D). Empty when
// usable, else one sentence naming what is wrong.
std::string intrinsicsFromCameraInfo(const sensor_msgs::CameraInfo& info, bool rectified,
                                     CameraIntrinsics& out);

// Empty when a camera_info describing images of `info_size` (binning and ROI applied:
// CameraIntrinsics::size) is these images' camera, else the ERROR both nodelets give: it
// names both sizes and what to do. Such a camera_info is not used for those images;
// `earlier_kept`: an earlier camera_info of their size still is (CalibrationHolder).
std::string infoSizeMismatch(const cv::Size& info_size, const cv::Size& image_size,
                             bool earlier_kept = false);

// A frame id as tf2 takes it: without a leading '/' (ROS 1 drivers of the tf1 era still
// send one).
std::string tfFrame(const std::string& frame_id);

// Empty when the camera used for images of frame `image_frame_id` names that frame (or
// either names none), else the WARN both nodelets give: drivers give an image and its
// camera_info one frame_id, so another one is most often the other camera's camera_info
// (a remap gone wrong, of the same size). It is used all the same (a driver may name
// them apart).
std::string infoFrameMismatch(const CameraIntrinsics& camera, const std::string& image_frame_id);

// Which calibration describes the images: the last usable camera_info when it is of their
// size, else the last one that was. A stray camera_info of another size (a second driver
// on the topic, a calibration reloaded at another resolution) is then an ERROR in the
// diagnostics but does not take the camera, and with it the map, away from the images.
class CalibrationHolder {
 public:
  void offer(const CameraIntrinsics& camera) { latest_ = camera; }
  // For images of `size`: the calibration to use (null: none, image-space planes), and
  // in `mismatch` the ERROR when the last camera_info is of another size.
  const CameraIntrinsics* forImages(const cv::Size& size, std::string& mismatch);
  // The same without taking the last camera_info (diagnostics); no size (no images
  // yet): the last camera_info.
  const CameraIntrinsics* heldFor(const cv::Size& size) const;
  std::string mismatch(const cv::Size& size) const;
  const std::optional<CameraIntrinsics>& latest() const { return latest_; }

 private:
  std::optional<CameraIntrinsics> latest_;  // the last usable camera_info
  std::optional<CameraIntrinsics> held_;    // the last one of the images' size
};

// The camera model a nodelet uses, for its diagnostics: "none", "not used: camera_info
// for another image size", "rectified (P)", "equidistant (K, D via cv::fisheye)" or "raw (K, D)".
std::string cameraModelName(const CalibrationHolder& calibration, const cv::Size& images);

// A rectified stream by its topic's name: image_proc calls it image_rect (or image_rect_color).
bool isRectifiedTopic(const std::string& resolved_image_topic);
// Why a nodelet takes its images as rectified (P, no distortion), "" when raw (K, D): the
// parameter `rectified`, or the topic's name (isRectifiedTopic). Both nodelets apply it.
std::string rectifiedBy(bool rectified_parameter, const std::string& resolved_image_topic);

// Equidistant cameras: every pixel moved to where the pinhole camera K sees the same ray
// (cv::fisheye::undistortPoints); points that land outside the image are dropped. No-op
// for other models.
void undistortFisheye(TrackFrame& frame, const CameraIntrinsics& camera);

}  // namespace mono_plane_detection
