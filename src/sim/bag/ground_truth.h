// The ground truth YAML written by make_sequence, read back: planes and camera poses in
// the map frame. Plus the conversion of a PlaneArray into map planes, so that a run of
// the nodelets can be judged with map_evaluation.h (demo report, accuracy rostest).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "mono_plane_detection/PlaneArray.h"
#include "mono_plane_detection/eval/map_evaluation.h"
#include "mono_plane_detection/ros/pose_msg.h"

namespace mono_plane_detection {

struct GroundTruth {
  std::string trajectory;
  std::vector<TruthPlane> planes;
  std::vector<double> stamps;             // s, one per image
  std::vector<Pose> poses;                // map_from_camera of each image
  double travelled_m = 0;                 // path length of the camera
  std::vector<cv::Vec3d> target_corners;  // map frame
};

// Throws std::runtime_error when the file cannot be read or lacks a field.
GroundTruth loadGroundTruth(const std::string& yaml_path);

// The pose of the image with this stamp (within 1 ms), if any.
std::optional<Pose> poseAt(const GroundTruth& truth, double stamp);

// The metric planes of a PlaneArray as map planes (id, normal, distance, polygon,
// observations, confidence) in the core's map frame (the target's, where the truth is:
// the message's ROS map frame and d sign undone, ros/map_frame.h); only the confirmed
// ones (PlaneEstimate.confirmed: what a user of the topic is told to trust).
std::vector<MapPlane> mapPlanesOf(const PlaneArray& msg);

}  // namespace mono_plane_detection
