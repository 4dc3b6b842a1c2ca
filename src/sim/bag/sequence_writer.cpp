#include "sequence_writer.h"

#include <cv_bridge/cv_bridge.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "mono_plane_detection/eval/map_evaluation.h"
#include "mono_plane_detection/ros/pose_msg.h"

namespace mono_plane_detection {
namespace {

YAML::Node vec(const cv::Vec3d& v) {
  YAML::Node n;
  n.SetStyle(YAML::EmitterStyle::Flow);
  for (int i = 0; i < 3; ++i) n.push_back(v[i]);
  return n;
}

sensor_msgs::CameraInfo cameraInfo(const SequenceSpec& spec, const std_msgs::Header& header) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = spec.camera.size.width;
  info.height = spec.camera.size.height;
  info.distortion_model = "plumb_bob";
  info.D = {spec.camera.k1, spec.camera.k2, 0, 0, 0};
  info.K = {spec.camera.fx, 0, spec.camera.cx, 0, spec.camera.fy, spec.camera.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  info.P = {spec.camera.fx, 0, spec.camera.cx, 0, 0, spec.camera.fy, spec.camera.cy, 0, 0, 0, 1, 0};
  return info;
}

void validate(const SequenceSpec& spec) {
  if (spec.frames < 1) throw SequenceSpecError("frames must be at least 1");
  if (!(spec.fps > 0)) throw SequenceSpecError("fps must be positive");
  // Images 1/fps apart in ros::Time (nanoseconds): at 1e300 fps every stamp was equal.
  if (!(spec.fps <= 1e6)) throw SequenceSpecError("fps must be at most 1e6 (distinct stamps)");
  if (!(spec.exposure_swing >= 0 && spec.exposure_swing < 1))
    throw SequenceSpecError("exposure swing must be in [0, 1)");
  if (spec.encoding != "mono8" && spec.encoding != "bgr8")
    throw SequenceSpecError("encoding must be mono8 or bgr8, not '" + spec.encoding + "'");
  if (spec.camera.size.width < 1 || spec.camera.size.height < 1 || !(spec.camera.fx > 0) ||
      !(spec.camera.fy > 0))
    throw SequenceSpecError("camera size and focal lengths must be positive");
  const std::string& name = spec.trajectory.name;
  if (!knownTrajectory(name))
    throw SequenceSpecError(
        "trajectory must be wheeled, humanoid, rotation, turn_in_place or look_around, not '" +
        name + "'");
}

void writeGroundTruth(const SequenceSpec& spec, const IndoorScene& scene, const std::string& path) {
  const Pose map_from_world = scene.target.world_from_map.inverse();
  YAML::Node root;
  root["trajectory"] = spec.trajectory.name;
  root["frames"] = spec.frames;
  root["fps"] = spec.fps;
  root["start_time_s"] = spec.start_time_s;
  root["image_topic"] = spec.image_topic;
  root["frame_id"] = spec.frame_id;
  YAML::Node camera;
  camera["width"] = spec.camera.size.width;
  camera["height"] = spec.camera.size.height;
  camera["fx"] = spec.camera.fx;
  camera["fy"] = spec.camera.fy;
  camera["cx"] = spec.camera.cx;
  camera["cy"] = spec.camera.cy;
  camera["k1"] = spec.camera.k1;
  camera["k2"] = spec.camera.k2;
  root["camera"] = camera;
  root["map_frame"] =
      "origin at the target centre; x along the target's width, y along its "
      "height, z = x cross y out of the target into the room (metres)";
  YAML::Node target;
  root["layout"] = spec.room.layout;
  target["type"] = scene.target.type;
  if (scene.target.type == "aruco") {
    target["aruco_dictionary"] = scene.target.aruco_dictionary;
    target["aruco_id"] = scene.target.aruco_id;
    target["corner_order"] =
        "corners_map: (-x,-y) (+x,-y) (+x,+y) (-x,+y); the marker's top-left, top-right, "
        "bottom-right, bottom-left are corners 3, 2, 1, 0";
  }
  target["background"] = scene.target.type == "sheet" ? spec.room.target_background : "";
  target["width_m"] = scene.target.width_m;
  target["height_m"] = scene.target.height_m;
  target["plane_id"] = scene.planes[scene.target.plane_index].id;
  for (const auto& c : scene.target.corners)
    target["corners_map"].push_back(vec(map_from_world.apply(c)));
  root["target"] = target;
  // How much of some image each plane covers: the accuracy tests require the planes
  // that cover at least 10 % of an image.
  std::vector<double> max_share(scene.planes.size(), 0.0), range(scene.planes.size(), 0.0);
  for (int k = 0; k < spec.frames; ++k) {
    const Pose world_from_camera = trajectoryPose(spec.trajectory, k / spec.fps);
    const std::vector<double> shares = imageShares(scene, spec.camera, world_from_camera, 16);
    for (size_t i = 0; i < shares.size(); ++i) {
      if (shares[i] <= max_share[i]) continue;
      max_share[i] = shares[i];
      range[i] = scene.planes[i].distanceFrom(world_from_camera.t);
    }
  }
  for (size_t i = 0; i < scene.planes.size(); ++i) {
    const ScenePlane& p = scene.planes[i];
    YAML::Node plane;
    plane["max_image_share"] = max_share[i];
    plane["range_at_max_share_m"] = range[i];
    plane["id"] = p.id;
    plane["name"] = p.name;
    plane["surface"] = p.surface;
    const cv::Vec3d n = map_from_world.R * p.normal();
    plane["normal"] = vec(n);
    plane["distance_m"] = n.dot(map_from_world.apply(p.origin));
    for (const auto& c : p.corners()) plane["polygon_map"].push_back(vec(map_from_world.apply(c)));
    root["planes"].push_back(plane);
  }
  for (int k = 0; k < spec.frames; ++k) {
    const Pose pose = groundTruthPose(spec, scene, k);
    YAML::Node entry;
    entry["stamp"] = spec.start_time_s + k / spec.fps;
    entry["position"] = vec(pose.t);
    const geometry_msgs::Quaternion q = toQuaternionMsg(pose.R);
    entry["orientation_xyzw"].SetStyle(YAML::EmitterStyle::Flow);
    for (double c : {q.x, q.y, q.z, q.w}) entry["orientation_xyzw"].push_back(c);
    root["camera_gt_in_map"].push_back(entry);
  }
  std::ofstream out(path);
  if (!out) throw SequenceWriteError("cannot write " + path);
  out << "# Ground truth of a synthetic sequence (mono_plane_detection make_sequence)\n"
      << root << "\n";
}

}  // namespace

Pose groundTruthPose(const SequenceSpec& spec, const IndoorScene& scene, int k) {
  return scene.target.world_from_map.inverse() * trajectoryPose(spec.trajectory, k / spec.fps);
}

SequenceReport writeSequence(const SequenceSpec& spec, const std::string& bag_path,
                             const std::string& yaml_path,
                             const std::function<void(int)>& progress) {
  validate(spec);
  IndoorScene scene;
  try {
    scene = makeRoom(spec.room);
  } catch (const std::invalid_argument& e) {
    throw SequenceSpecError(e.what());
  }
  const SceneRenderer renderer(scene, spec.camera, spec.render);
  rosbag::Bag bag;
  try {
    bag.open(bag_path, rosbag::bagmode::Write);
  } catch (const rosbag::BagException& e) {
    throw SequenceWriteError("cannot write " + bag_path + ": " + e.what());
  }
  SequenceReport report;
  double render_ms = 0;
  const int subframes = std::max(1, spec.render.blur_subframes);
  for (int k = 0; k < spec.frames; ++k) {
    const double t = k / spec.fps;
    std_msgs::Header header;
    header.stamp = ros::Time(spec.start_time_s + t);
    header.frame_id = spec.frame_id;

    // Motion blur: the poses over half an image period before the stamp.
    std::vector<Pose> poses;
    for (int s = 0; s < subframes; ++s) {
      const double dt =
          subframes > 1 ? -0.5 / spec.fps * (subframes - 1 - s) / (subframes - 1) : 0.0;
      poses.push_back(trajectoryPose(spec.trajectory, std::max(0.0, t + dt)));
    }
    const auto start = std::chrono::steady_clock::now();
    const double gain = 1.0 + spec.exposure_swing * std::sin(2 * CV_PI * t / 4.0);
    cv::Mat image = renderer.renderBlurred(poses, static_cast<unsigned>(k), gain);
    render_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (spec.encoding == "bgr8") cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);

    bag.write(spec.image_topic, header.stamp,
              cv_bridge::CvImage(header, spec.encoding, image).toImageMsg());
    bag.write(spec.info_topic, header.stamp, cameraInfo(spec, header));

    const Pose gt = groundTruthPose(spec, scene, k);
    geometry_msgs::TransformStamped tf;
    tf.header.stamp = header.stamp;
    tf.header.frame_id = spec.map_frame;
    tf.child_frame_id = spec.ground_truth_frame;
    tf.transform = toTransformMsg(gt);
    tf2_msgs::TFMessage tf_msg;
    tf_msg.transforms.push_back(tf);
    bag.write("/tf", header.stamp, tf_msg);
    ++report.frames;
    if (progress) progress(k);
  }
  bag.close();
  writeGroundTruth(spec, scene, yaml_path);
  report.render_ms_mean = render_ms / spec.frames;
  return report;
}

}  // namespace mono_plane_detection
