// Paper II-A on the image side: until the start-up target has been confirmed, each image
// is searched for it (the sheet or the ArUco marker, params.target_type); its four corners
// then join the tracker as points flagged as target corners (in TargetDetection's order),
// so the plane stage can place the camera. One detection is not enough: a target fixes
// the map frame only after params.confirm_frames consecutive images in which it is found
// where Lucas-Kanade moved its corners from the image before (a chance quadrilateral in
// texture does not stay put under the camera's motion). After that, while its four
// corners are tracked (params.redetect_tracked), the target is found again in each image
// in a small region around them, and the tracks are moved onto the detected sub-pixel
// corners (ids kept) when all four agree: the corners the start averages are then
// independent measurements, not Lucas-Kanade's drift. ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <cstdint>
#include <optional>
#include <vector>

#include "mono_plane_detection/tracking/feature_tracker.h"
#include "mono_plane_detection/tracking/target_detector.h"

namespace mono_plane_detection {

class TargetStartup {
 public:
  explicit TargetStartup(const TargetParams& params = TargetParams());

  // Call after tracker.process(gray), on every image. Returns the detection on the image
  // where the target is confirmed (once); nothing before and after (after, the tracked
  // corners are re-anchored to the re-detected target). focal_px: 0 when unknown;
  // principal_px: negative for the image centre.
  std::optional<TargetDetection> process(const cv::Mat& gray, FeatureTracker& tracker,
                                         double focal_px = 0,
                                         cv::Point2d principal_px = {-1, -1});

  // The raw image's lens (camera_info K and D): with distortion the target is searched
  // in the image undistorted to K, where the sheet's sides are straight lines, and its
  // corners are given back in raw pixels. D: OpenCV's model (plumb_bob,
  // rational_polynomial), or with fisheye the equidistant model (1 x 4); empty: none.
  // K then also gives process() its focal length and principal point.
  void setLens(const cv::Matx33d& K, const cv::Mat& D, bool fisheye = false);

  bool found() const { return found_; }
  void reset();  // search again (the tracker was reset)
  const TargetParams& params() const { return params_; }
  // The last image's detection (found or why not), for diagnostics.
  const TargetDetection& lastDetection() const { return last_; }
  int consecutive() const { return consecutive_; }  // images the candidate has been confirmed in
  // After confirmation: whether the last image's target tracks were moved onto a
  // re-detection, in how many images they were (of how many with all four tracked), and
  // their largest move there (px).
  bool reanchored() const { return reanchored_; }
  int reanchoredImages() const { return reanchored_images_; }
  int followedImages() const { return followed_images_; }
  double lastReanchorShiftPx() const { return last_shift_px_; }

 private:
  TargetParams params_;
  TargetParams follow_params_;  // params_ without the aspect check (followTarget's crops)
  bool found_ = false;
  int consecutive_ = 0;
  cv::Mat previous_;  // the image of the last detection, for Lucas-Kanade
  TargetDetection last_;
  std::vector<std::uint64_t> corner_ids_;  // the tracker's ids of the corners, in order
  bool reanchored_ = false;
  int reanchored_images_ = 0;
  int followed_images_ = 0;
  double last_shift_px_ = 0;
  cv::Mat crop_;  // the region searched after confirmation (undistorted when a lens is set)
  void followTarget(const cv::Mat& gray, FeatureTracker& tracker);
  void ensureMaps(const cv::Size& size);
  // The lens (setLens) and the undistortion maps for the last image size.
  cv::Matx33d K_ = cv::Matx33d::eye();
  cv::Mat D_;
  bool fisheye_ = false;
  cv::Size map_size_;
  cv::Mat map1_, map2_, undistorted_;
};

}  // namespace mono_plane_detection
