// Renders a synthetic sequence into a rosbag (image, camera_info, ground-truth tf) and
// writes its ground truth as YAML next to it. The ROS side of the renderer.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

#include "mono_plane_detection/sim/camera_trajectory.h"
#include "mono_plane_detection/sim/indoor_scene.h"
#include "mono_plane_detection/sim/scene_renderer.h"

namespace mono_plane_detection {

struct SequenceSpec {
  RoomParams room;
  CameraModel camera;
  RenderOptions render;
  TrajectoryParams trajectory;
  int frames = 300;
  double fps = 30;
  std::string encoding = "mono8";           // mono8 | bgr8
  std::string frame_id = "camera_optical";  // of images and camera_info
  std::string image_topic = "/camera/image_raw";
  std::string info_topic = "/camera/camera_info";
  std::string map_frame = "map",
              ground_truth_frame = "camera_gt";  // tf published as map -> camera_gt
  double start_time_s = 1000.0;                  // stamp of the first image
  double exposure_swing = 0.0;                   // exposure varies by +- this share, 4 s period
};

struct SequenceReport {
  int frames = 0;
  double render_ms_mean = 0;  // per image, all sub-frames included
};

// A spec the writer refuses (the caller's input).
struct SequenceSpecError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
// A file that cannot be written.
struct SequenceWriteError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws SequenceSpecError (bad spec) or SequenceWriteError (unwritable file), both
// std::runtime_error. progress(k) after image k.
SequenceReport writeSequence(const SequenceSpec& spec, const std::string& bag_path,
                             const std::string& yaml_path,
                             const std::function<void(int)>& progress = nullptr);

// The camera_gt pose of image k in the map frame.
Pose groundTruthPose(const SequenceSpec& spec, const IndoorScene& scene, int k);

}  // namespace mono_plane_detection
