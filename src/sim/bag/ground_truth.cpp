#include "ground_truth.h"

#include "mono_plane_detection/ros/map_frame.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <stdexcept>

namespace mono_plane_detection {
namespace {

cv::Vec3d vec3(const YAML::Node& n) {
  return {n[0].as<double>(), n[1].as<double>(), n[2].as<double>()};
}

}  // namespace

GroundTruth loadGroundTruth(const std::string& yaml_path) {
  GroundTruth truth;
  try {
    const YAML::Node root = YAML::LoadFile(yaml_path);
    truth.trajectory = root["trajectory"] ? root["trajectory"].as<std::string>() : "";
    for (const auto& p : root["planes"]) {
      TruthPlane t;
      t.id = p["id"].as<int>();
      t.name = p["name"].as<std::string>();
      t.normal = vec3(p["normal"]);
      t.distance = p["distance_m"].as<double>();
      t.max_image_share = p["max_image_share"] ? p["max_image_share"].as<double>() : 1.0;
      t.range_m = p["range_at_max_share_m"] ? p["range_at_max_share_m"].as<double>() : 0.0;
      truth.planes.push_back(t);
    }
    for (const auto& c : root["target"]["corners_map"]) truth.target_corners.push_back(vec3(c));
    for (const auto& e : root["camera_gt_in_map"]) {
      geometry_msgs::Pose pose;
      const cv::Vec3d t = vec3(e["position"]);
      pose.position.x = t[0];
      pose.position.y = t[1];
      pose.position.z = t[2];
      pose.orientation.x = e["orientation_xyzw"][0].as<double>();
      pose.orientation.y = e["orientation_xyzw"][1].as<double>();
      pose.orientation.z = e["orientation_xyzw"][2].as<double>();
      pose.orientation.w = e["orientation_xyzw"][3].as<double>();
      if (!truth.poses.empty()) truth.travelled_m += cv::norm(t - truth.poses.back().t);
      truth.stamps.push_back(e["stamp"].as<double>());
      truth.poses.push_back(fromPoseMsg(pose));
    }
  } catch (const YAML::Exception& e) {
    throw std::runtime_error("cannot read ground truth " + yaml_path + ": " + e.what());
  }
  if (truth.planes.empty() || truth.poses.empty())
    throw std::runtime_error("ground truth " + yaml_path + " has no planes or poses");
  return truth;
}

std::optional<Pose> poseAt(const GroundTruth& truth, double stamp) {
  for (size_t i = 0; i < truth.stamps.size(); ++i)
    if (std::abs(truth.stamps[i] - stamp) < 1e-3) return truth.poses[i];
  return {};
}

std::vector<MapPlane> mapPlanesOf(const PlaneArray& msg) {
  std::vector<MapPlane> out;
  for (const auto& p : msg.planes) {
    if (!p.metric || !p.confirmed) continue;
    // Back from the ROS map (z up, shape_msgs sign) to the target's frame of the truth.
    const cv::Matx33d target_from_ros = rosMapFromTarget().R.t();
    MapPlane m;
    m.id = p.id;
    m.normal = target_from_ros * cv::Vec3d(p.normal.x, p.normal.y, p.normal.z);
    m.distance = -p.d;
    for (const auto& v : p.polygon) m.polygon.push_back(target_from_ros * cv::Vec3d(v.x, v.y, v.z));
    m.observations = static_cast<int>(p.observations);
    m.confidence = p.confidence;
    m.rms_m = p.rms_m;
    out.push_back(m);
  }
  return out;
}

}  // namespace mono_plane_detection
