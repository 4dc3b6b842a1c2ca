// Judging a plane map and a camera path against ground truth (synthetic sequences):
// which true plane each mapped plane is, its normal and distance errors, planes missed
// or split in two. Used by the accuracy tests, the demo and the offline runner. ROS-free.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/sim/camera_trajectory.h"
#include "mono_plane_detection/sim/indoor_scene.h"
#include "mono_plane_detection/mapping/plane_map.h"

namespace mono_plane_detection {

struct TruthPlane {
  int id = 0;
  std::string name;
  cv::Vec3d normal;            // unit, map frame, into the room
  double distance = 0;         // m: {x : normal . x = distance}
  double max_image_share = 0;  // largest share of an image it covered (0..1)
  // The camera's distance from it in that image, m (0: unknown): the reference of a
  // relative distance error (a plane is judged against how far it was seen from).
  double range_m = 0;
};

// The scene's planes in the map (target) frame; max_image_share left 0.
std::vector<TruthPlane> truthPlanes(const IndoorScene& scene);

// Share of the image each scene plane covers (index = scene plane), sampling every
// `step` pixels; distortion ignored (a coverage figure, not geometry).
std::vector<double> imageShares(const IndoorScene& scene, const CameraModel& camera,
                                const Pose& world_from_camera, int step = 8);

struct PlaneMatch {
  int map_id = 0;
  int truth_id = -1;  // -1: matches no true plane (a false plane)
  std::string truth_name;
  double normal_error_deg = 0;
  double distance_error_m = 0;  // |distance - true distance|
};

struct MapEvaluation {
  std::vector<PlaneMatch> matches;  // one per mapped plane evaluated
  std::vector<int> missed;          // true planes (id) that were required and not found
  std::vector<int> split;           // true planes (id) matched by more than one mapped plane
  double worst_normal_error_deg = 0, worst_distance_error_m = 0;
};

// Matches each mapped plane to the true plane within the gates with the least
// angle / max_angle_deg + offset / max_offset_m. Required: true planes with max_image_share >= min_share.
MapEvaluation evaluateMap(const std::vector<MapPlane>& planes, const std::vector<TruthPlane>& truth,
                          double min_share = 0.10, double max_angle_deg = 20.0,
                          double max_offset_m = 0.3);

// The rigid motion (no scale) taking the points `from` onto `to` in least squares
// (Kabsch): compares a map with its own origin and heading (odometry, camera_height)
// with the truth. Same sizes, at least 3 points not on a line.
Pose rigidAlign(const std::vector<cv::Vec3d>& from, const std::vector<cv::Vec3d>& to);

}  // namespace mono_plane_detection
