// Metres from the camera's height above the floor (beyond the paper; the monocular
// scale of libviso2): a wheeled robot's camera stays at a known height, so once the
// floor is found between two views the motion is known in floor distances and the known
// height turns it into metres. The motion's direction comes from every track (essential
// matrix, RANSAC at 3 sigma of the tracks' measured noise), the floor is a plane through
// triangulated tracks (RANSAC, then a least-squares fit to its tracks' image motion).
// Which plane is the floor (the assumption): of the planes whose normal lies within
// max_floor_angle_deg of the camera's down direction for a nominal downward pitch
// (roll 0), below the camera and with no tracks clearly beyond it (the floor is the
// lowest surface), the one whose homography carries the most tracks that the rotation
// alone does not. ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

struct FloorParams {
  double camera_height_m = 0;        // optical centre above the floor; 0: unknown
  double pitch_down_deg = 10;        // nominal camera tilt below the horizon
  double max_floor_angle_deg = 25;   // the floor's normal within this of the nominal down
  double min_parallax_deg = 4.0;     // median angle between the floor tracks' two rays
  double min_motion = 0.2;           // camera motion needed, in camera heights
  // Floor tracks needed, of those the rotation alone does not explain (those fit every
  // plane): the rendered room at 1.2 m shows 8-30 floor tracks of the tracker's 150.
  int min_inliers = 8;
  int confirmations = 5;             // images in a row that find the same floor ...
  double max_floor_change_deg = 4;   // ... its down direction changing less than this
  double max_error_px = 3.0;         // RANSAC threshold: 3 sigma of the measured noise, at most this
  // After the start the map is checked and corrected against the floor landmarks it
  // triangulates (fitFloorToLandmarks, floorCorrection) before a pose is given out: once
  // the camera has moved this far (camera heights) and the floor has min_check_points
  // landmarks. A start whose floor disagrees (by max_check_angle_deg, or a scale off by
  // max_check_scale) is undone.
  double check_motion = 1.0;
  int min_check_points = 30;
  double max_check_angle_deg = 6;
  double max_check_scale = 0.25;     // |scale - 1| at most this
  // The camera positions' noise in that fit (camera heights): a wheeled camera stays at
  // one height, so its path shares the floor's normal (fitFloorToLandmarks).
  double check_camera_sigma = 0.01;
};

struct FloorStart {
  bool ok = false;
  std::string reason;            // why not, when !ok
  Pose second_from_first;        // metres
  cv::Vec3d down{0, 1, 0};       // first camera frame: unit normal from the camera to the floor
  std::vector<int> floor_points; // indices of the floor's tracks
  double parallax_deg = 0;       // median over the floor's tracks
  double noise_px = 0;           // the tracks' measured noise (sigma of the epipolar error)
  // Every track triangulated (indices into first/second), first camera frame, metres.
  std::vector<int> point_index;
  std::vector<cv::Vec3d> points;
};

// first/second: undistorted normalised coordinates of the same tracks in two images.
FloorStart floorStart(const std::vector<cv::Point2d>& first,
                      const std::vector<cv::Point2d>& second, double focal_px,
                      const FloorParams& params);

// An up-to-scale start for a camera that sees too little floor in the image (a
// humanoid's head): the motion from every track (as floorStart), every track
// triangulated, `down` the nominal one (pitch_down_deg, roll 0) and the scale a guess
// (the lowest tracks taken to lie camera_height_m down). Its up and scale are for the
// floor landmarks to fix (fitFloorToLandmarks, floorCorrection). Needs min_check_points
// triangulated tracks whose median parallax reaches min_parallax_deg. floor_points empty.
FloorStart unscaledStart(const std::vector<cv::Point2d>& first,
                         const std::vector<cv::Point2d>& second, double focal_px,
                         const FloorParams& params);

// The map frame the floor defines (core convention, y up): origin on the floor below the
// first camera, y up (against `down`), z backwards along the floor (so the ROS map's x
// is the camera's heading at the start). map_from_first camera.
Pose floorMapFromCamera(const cv::Vec3d& down, double camera_height_m);

// The floor {x : up . x = offset} fitted to a map's landmarks (map frame): of the
// planes through three of them whose normal lies within max_angle_deg of `up` (the
// map's up as started) and that lie below every camera, the one with the most landmarks
// within tolerance_m (one gate for all: the landmarks' sigma_m, a pixel over their
// parallax, overstate their noise after the bundle adjustment), then refined by
// weighted total least squares on those (weights 1 / sigma^2) and their inliers again.
// camera_sigma_m > 0: the cameras stay at one height (a wheeled robot), their positions
// (noise camera_sigma_m) share the floor's normal: a floor seen as a strip ahead fixes
// its tilt about the strip poorly, the camera's motion along the floor fixes that.
// relative: tolerance_m and camera_sigma_m are shares of the cameras' median height above
// each plane tried (a map whose scale is not known yet: unscaledStart), and a plane with
// more than a fifth as many landmarks below its gate as within it is not the floor (the
// lowest surface: with an up-to-scale start's wide cone, a plane through the floor and
// the foot of a wall, tilted, otherwise wins where the wall is dense).
struct FloorFit {
  bool ok = false;
  std::string reason;            // why not, when !ok
  cv::Vec3d up{0, 1, 0};         // unit, from the floor towards the cameras
  double offset = 0;             // m: the floor is up . x = offset
  std::vector<int> inliers;      // indices into the points
  double rms_m = 0;              // the inliers' distance from the floor
};
FloorFit fitFloorToLandmarks(const std::vector<cv::Vec3d>& points,
                             const std::vector<double>& sigma_m,
                             const std::vector<cv::Vec3d>& cameras, const cv::Vec3d& up,
                             double max_angle_deg, double tolerance_m, int min_points,
                             double camera_sigma_m = 0, bool relative = false);

// The robust spread (1.4826 x the median absolute deviation) of the cameras' heights
// above a floor, as a share of their median height; infinite without a camera above it.
double relativeHeightSpread(const FloorFit& floor, const std::vector<cv::Vec3d>& cameras);

// x' = scale * R * x + t: a similarity of the map.
struct Similarity {
  double scale = 1;
  cv::Matx33d R = cv::Matx33d::eye();
  cv::Vec3d t{0, 0, 0};
  cv::Vec3d apply(const cv::Vec3d& x) const { return scale * (R * x) + t; }
  // A camera pose (map_from_camera) moved with the map.
  Pose apply(const Pose& map_from_camera) const {
    return {R * map_from_camera.R, apply(map_from_camera.t)};
  }
};

// The similarity that puts a map's floor (its fit) at y = 0 with +y up (the smallest
// rotation of its up), and the cameras (positions, map frame) camera_height_m above it
// (the median of their heights), the origin staying below `origin_camera`.
Similarity floorCorrection(const FloorFit& floor, const std::vector<cv::Vec3d>& cameras,
                           const cv::Vec3d& origin_camera, double camera_height_m);

}  // namespace mono_plane_detection
