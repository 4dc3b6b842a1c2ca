#include "plane_messages.h"

#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>
#include <sstream>
#include <unordered_map>

#include "mono_plane_detection/ros/map_frame.h"
#include "mono_plane_detection/ros/pose_msg.h"
#include "mono_plane_detection/viz/draw_planes.h"

namespace mono_plane_detection {

TrackFrame toTrackFrame(const Tracks& msg, std::string& error) {
  TrackFrame frame;
  const size_t n = msg.id.size();
  if (msg.u.size() != n || msg.v.size() != n || msg.flags.size() != n ||
      msg.prev_index.size() != n || msg.age.size() != n) {
    std::ostringstream why;
    why << "array lengths differ: id " << n << ", u " << msg.u.size() << ", v " << msg.v.size()
        << ", flags " << msg.flags.size() << ", prev_index " << msg.prev_index.size() << ", age "
        << msg.age.size();
    error = why.str();
    return frame;
  }
  frame.stamp = msg.header.stamp.toSec();
  frame.tracker_run = msg.tracker_run;
  frame.size = cv::Size(static_cast<int>(msg.width), static_cast<int>(msg.height));
  frame.ids.assign(msg.id.begin(), msg.id.end());
  frame.pixels.reserve(n);
  frame.target_corner.reserve(n);
  frame.reidentified.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    frame.pixels.emplace_back(msg.u[i], msg.v[i]);
    frame.target_corner.push_back((msg.flags[i] & Tracks::FLAG_TARGET_CORNER) != 0);
    frame.reidentified.push_back((msg.flags[i] & Tracks::FLAG_REIDENTIFIED) != 0);
  }
  error = validateTrackFrame(frame);
  return frame;
}

std::string targetMismatch(const Tracks& msg, const TargetParams& own) {
  if (msg.target_type.empty()) return {};
  const auto corners = targetCornersInMap(own);
  const double width = 2 * corners[2].x, height = 2 * corners[2].y;
  const auto differs = [](double a, double b) { return std::abs(a - b) > 1e-4 * std::abs(b); };
  if (msg.target_type == own.target_type && !differs(msg.target_width_m, width) &&
      !differs(msg.target_height_m, height))
    return {};
  std::ostringstream why;
  why << "the tracker's start-up target (" << msg.target_type << ", " << msg.target_width_m << " x "
      << msg.target_height_m << " m) is not this nodelet's (" << own.target_type << ", " << width
      << " x " << height
      << " m): its corners are not used; set target/* once for both nodelets "
         "(config/target.yaml, launch arg target_config)";
  return why.str();
}

std::string odometryError(const Pose& odom, const std::optional<Pose>& previous,
                          double max_jump_m) {
  for (int i = 0; i < 9; ++i)
    if (!std::isfinite(odom.R.val[i])) return "its rotation is not finite";
  for (int i = 0; i < 3; ++i)
    if (!std::isfinite(odom.t[i])) {
      std::ostringstream why;
      why << "its translation (" << odom.t[0] << ", " << odom.t[1] << ", " << odom.t[2]
          << ") is not finite";
      return why.str();
    }
  if (previous) {
    const double jump = cv::norm(odom.t - previous->t);
    if (!(jump <= max_jump_m)) {
      std::ostringstream why;
      why << "it moved " << jump
          << " m since the previous tracks, more than max_odom_jump_m = " << max_jump_m;
      return why.str();
    }
  }
  return {};
}

namespace {

geometry_msgs::Point point(const cv::Vec3d& v) {
  geometry_msgs::Point p;
  p.x = v[0];
  p.y = v[1];
  p.z = v[2];
  return p;
}

void fill(PlaneEstimate& out, const ImagePlane& plane) {
  out.observed = true;
  for (int i = 0; i < 9; ++i) out.homography[i] = plane.H.val[i];
  out.inlier_ids.assign(plane.inlier_ids.begin(), plane.inlier_ids.end());
  out.rms_error_px = static_cast<float>(plane.rms_error_px);
}

std_msgs::ColorRGBA colourOf(int id, double alpha) {
  const cv::Scalar bgr = planeColour(id);
  std_msgs::ColorRGBA c;
  c.r = static_cast<float>(bgr[2] / 255.0);
  c.g = static_cast<float>(bgr[1] / 255.0);
  c.b = static_cast<float>(bgr[0] / 255.0);
  c.a = static_cast<float>(alpha);
  return c;
}

}  // namespace

PlaneEstimate toPlaneEstimate(const MapPlane& plane) {
  PlaneEstimate out;
  const Pose& ros_from_target = rosMapFromTarget();
  const RosPlane ros = toRosPlane(plane.normal, plane.distance);
  out.id = plane.id;
  out.metric = true;
  out.normal.x = ros.normal[0];
  out.normal.y = ros.normal[1];
  out.normal.z = ros.normal[2];
  out.d = ros.d;
  out.label = static_cast<uint8_t>(planeKind(ros.normal));
  for (const auto& v : plane.polygon) out.polygon.push_back(point(ros_from_target.apply(v)));
  out.observations = static_cast<uint32_t>(plane.observations);
  out.confidence = static_cast<float>(plane.confidence);
  out.rms_m = static_cast<float>(plane.rms_m);
  return out;
}

PlaneArrayPtr toMapPlanes(const std_msgs::Header& map_header, const PipelineResult& result,
                          const PlaneMap& map) {
  PlaneArrayPtr msg(new PlaneArray);
  msg->header = map_header;
  msg->status = result.status;
  msg->metric = result.pose.has_value() && result.state == PipelineState::kTracking;
  msg->reference_stamp = result.reference_stamp > 0 ? result.reference_stamp : 0.0;
  if (msg->metric) msg->camera_pose = toPoseMsg(rosMapFromTarget() * result.pose->map_from_camera);
  std::unordered_map<int, const ImagePlane*> seen;
  if (msg->metric)
    for (const ImagePlane& p : result.planes)
      if (p.map_id >= 0) seen.emplace(p.map_id, &p);
  for (int pass = 0; pass < 2; ++pass)  // observed planes first
    for (const MapPlane& plane : map.planes()) {
      const auto it = seen.find(plane.id);
      if ((it != seen.end()) != (pass == 0)) continue;
      PlaneEstimate out = toPlaneEstimate(plane);
      out.confirmed = plane.confirmed(map.params());
      if (it != seen.end()) {
        fill(out, *it->second);
        // Under rotation every plane moves with one homography; report the tracks whose
        // 3D points the map put on this plane.
        std::vector<std::uint64_t> on_plane;
        for (auto id : out.inlier_ids)
          if (plane.points.count(id)) on_plane.push_back(id);
        out.inlier_ids.assign(on_plane.begin(), on_plane.end());
      }
      msg->planes.push_back(out);
    }
  return msg;
}

PlaneArrayPtr toImagePlanes(const std_msgs::Header& image_header, const PipelineResult& result) {
  PlaneArrayPtr msg(new PlaneArray);
  msg->header = image_header;
  msg->status = result.status;
  msg->metric = false;  // image space: no pose in this message's frame
  msg->reference_stamp = result.reference_stamp > 0 ? result.reference_stamp : 0.0;
  msg->camera_pose.orientation.w = 1;
  for (const ImagePlane& p : result.planes) {
    PlaneEstimate out;
    out.id = p.id;
    fill(out, p);
    out.observations = 1;
    msg->planes.push_back(out);
  }
  return msg;
}

std::string planesYaml(const PlaneArray& planes) {
  std::ostringstream out;
  out.precision(6);
  out << "# mono_plane_detection map: plane {x : normal . x + d = 0} (shape_msgs/Plane sign), m\n"
      << "frame_id: " << planes.header.frame_id << "\n"
      << "stamp: " << std::fixed << planes.header.stamp.toSec() << "\n"
      << "planes:\n";
  out.unsetf(std::ios::fixed);
  static const char* names[] = {"other", "floor", "wall", "ceiling"};
  for (const PlaneEstimate& p : planes.planes) {
    if (!p.metric) continue;
    out << "  - id: " << p.id << "\n"
        << "    label: " << names[p.label < 4 ? p.label : 0] << "\n"
        << "    normal: [" << p.normal.x << ", " << p.normal.y << ", " << p.normal.z << "]\n"
        << "    d: " << p.d << "\n"
        << "    observations: " << p.observations << "\n"
        << "    confirmed: " << (p.confirmed ? "true" : "false") << "\n"
        << "    confidence: " << p.confidence << "\n"
        << "    polygon:\n";
    for (const auto& v : p.polygon)
      out << "      - [" << v.x << ", " << v.y << ", " << v.z << "]\n";
  }
  return out.str();
}

visualization_msgs::Marker deleteAllMarker(const std_msgs::Header& header) {
  visualization_msgs::Marker clear;
  clear.header = header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  return clear;
}

visualization_msgs::MarkerArrayPtr toMarkers(const std_msgs::Header& header, const PlaneMap& map,
                                             std::set<int>& shown) {
  visualization_msgs::MarkerArrayPtr markers(new visualization_msgs::MarkerArray);
  std::set<int> now;
  const Pose& ros_from_target = rosMapFromTarget();
  for (const MapPlane& plane : map.planes()) {
    if (plane.polygon.size() < 3) continue;
    const cv::Vec3d normal = ros_from_target.R * plane.normal;
    std::vector<cv::Vec3d> polygon;
    for (const auto& v : plane.polygon) polygon.push_back(ros_from_target.apply(v));
    now.insert(plane.id);
    const double alpha = 0.15 + 0.5 * plane.confidence;
    visualization_msgs::Marker surface;
    surface.header = header;
    surface.ns = "planes";
    surface.id = plane.id;
    surface.type = visualization_msgs::Marker::TRIANGLE_LIST;
    surface.action = visualization_msgs::Marker::ADD;
    surface.pose.orientation.w = 1;
    surface.scale.x = surface.scale.y = surface.scale.z = 1;
    surface.color = colourOf(plane.id, alpha);
    cv::Vec3d centre(0, 0, 0);
    for (const auto& v : polygon) centre += v;
    centre /= static_cast<double>(polygon.size());
    // A fan from the centre, each triangle twice: rviz lights a triangle by its winding's
    // normal (the light comes from the viewer), so a plane seen from behind, as walls are
    // from rviz's orbit view above the room, is drawn nearly black. The copy wound towards
    // the side the plane was seen from comes second, on top: from there (and the floor from
    // above) in full colour, from behind in about half of it.
    for (size_t k = 0; k < polygon.size(); ++k) {
      const cv::Vec3d& a = polygon[k];
      const cv::Vec3d& b = polygon[(k + 1) % polygon.size()];
      const bool facing = (a - centre).cross(b - centre).dot(normal) >= 0;
      for (const auto& [first, second] : {std::make_pair(facing ? b : a, facing ? a : b),
                                          std::make_pair(facing ? a : b, facing ? b : a)}) {
        surface.points.push_back(point(centre));
        surface.points.push_back(point(first));
        surface.points.push_back(point(second));
      }
    }
    markers->markers.push_back(surface);

    visualization_msgs::Marker arrow = surface;
    arrow.ns = "normals";
    arrow.type = visualization_msgs::Marker::ARROW;
    arrow.points = {point(centre), point(centre + 0.3 * normal)};
    arrow.scale.x = 0.02;
    arrow.scale.y = 0.04;
    arrow.scale.z = 0.06;
    arrow.color.a = 1;
    markers->markers.push_back(arrow);

    visualization_msgs::Marker label = surface;
    label.ns = "labels";
    label.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    label.points.clear();
    label.scale.z = 0.12;
    // A wall's label just above its top edge, a floor's or ceiling's off its centre: the
    // centres of a floor and a wall standing on it often fall on one spot of rviz's view
    // from above, and their texts were drawn over each other.
    cv::Vec3d at = centre + 0.35 * normal;
    if (planeKind(normal) == PlaneKind::kWall) {
      double top = polygon.front()[2];
      for (const auto& v : polygon) top = std::max(top, v[2]);
      at = centre + 0.05 * normal;
      at[2] = top + label.scale.z;
    }
    label.pose.position = point(at);
    label.color.r = label.color.g = label.color.b = label.color.a = 1;
    std::ostringstream text;
    text.precision(2);
    text << planeKindName(planeKind(normal)) << " " << plane.id << " (" << plane.observations
         << (plane.confirmed(map.params()) ? ")" : ", tentative)");
    label.text = text.str();
    markers->markers.push_back(label);
  }
  for (int id : shown) {
    if (now.count(id)) continue;
    for (const char* ns : {"planes", "normals", "labels"}) {
      visualization_msgs::Marker gone;
      gone.header = header;
      gone.ns = ns;
      gone.id = id;
      gone.action = visualization_msgs::Marker::DELETE;
      markers->markers.push_back(gone);
    }
  }
  shown = now;
  return markers;
}

sensor_msgs::PointCloud2Ptr toCloud(const std_msgs::Header& header, const PoseEstimator& pose,
                                    const PlaneMap& map) {
  std::unordered_map<std::uint64_t, int> plane_of;
  for (const MapPlane& plane : map.planes())
    for (const auto& entry : plane.points) plane_of[entry.first] = plane.id;
  size_t count = 0;
  for (const auto& entry : pose.landmarks())
    count += entry.second.triangulated || entry.second.fixed;

  sensor_msgs::PointCloud2Ptr cloud(new sensor_msgs::PointCloud2);
  cloud->header = header;
  sensor_msgs::PointCloud2Modifier modifier(*cloud);
  modifier.setPointCloud2FieldsByString(2, "xyz", "rgb");
  modifier.resize(count);
  sensor_msgs::PointCloud2Iterator<float> x(*cloud, "x"), y(*cloud, "y"), z(*cloud, "z");
  sensor_msgs::PointCloud2Iterator<uint8_t> r(*cloud, "r"), g(*cloud, "g"), b(*cloud, "b");
  const Pose& ros_from_target = rosMapFromTarget();
  for (const auto& [id, l] : pose.landmarks()) {
    if (!(l.triangulated || l.fixed)) continue;
    const cv::Vec3d position = ros_from_target.apply(l.position);
    *x = static_cast<float>(position[0]);
    *y = static_cast<float>(position[1]);
    *z = static_cast<float>(position[2]);
    const auto it = plane_of.find(id);
    const cv::Scalar bgr =
        it != plane_of.end() ? planeColour(it->second) : cv::Scalar(200, 200, 200);
    *r = static_cast<uint8_t>(bgr[2]);
    *g = static_cast<uint8_t>(bgr[1]);
    *b = static_cast<uint8_t>(bgr[0]);
    ++x, ++y, ++z, ++r, ++g, ++b;
  }
  return cloud;
}

}  // namespace mono_plane_detection
