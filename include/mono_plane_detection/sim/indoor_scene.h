// A room of textured planes with the start-up target painted on one of them: the
// ground truth every synthetic sequence is rendered from. World frame: metres, z up,
// the floor at z = 0, the robot starts at the origin looking along +y. ROS-free.
#pragma once

#include <array>
#include <limits>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "mono_plane_detection/geometry/pose.h"

namespace mono_plane_detection {

// A bounded plane: points origin + a * u_axis + b * v_axis, 0 <= a <= width_m,
// 0 <= b <= height_m. normal = u x v points into the room.
struct ScenePlane {
  int id = 0;
  std::string name;
  cv::Vec3d origin, u_axis, v_axis;
  double width_m = 0, height_m = 0;
  cv::Mat texture;  // CV_8UC1; texel (col, row) = (a, b) * texels_per_m
  double texels_per_m = 200;

  cv::Vec3d normal() const { return u_axis.cross(v_axis); }
  double distance() const { return normal().dot(origin); }  // plane: normal . X = distance
  std::array<cv::Vec3d, 4> corners() const;
};

// The white rectangle on a black border that fixes the metric scale (paper II-A).
struct StartTarget {
  int plane_index = 0;                       // the plane it is painted on
  double width_m = 0.297, height_m = 0.210;  // white rectangle (A4)
  double border_m = 0.05;                    // black border around it
  cv::Vec3d centre;                          // world frame
  std::array<cv::Vec3d, 4>
      corners;  // white rectangle, world frame: (-u,-v) (+u,-v) (+u,+v) (-u,+v)
  // The map frame is the target's frame: origin at its centre, x along the plane's
  // u axis, y along its v axis, z = x cross y, the normal pointing into the room.
  Pose world_from_map;
};

struct RoomParams {
  double width_m = 6.0;  // along x, centred on the start
  double front_m = 2.0;  // front wall at y = front_m (the robot looks at it first)
  double back_m = 6.0;   // back wall at y = -back_m
  double height_m = 2.6;
  int walls = 4;  // 0-4: front, left, right, back
  bool ceiling = true;
  std::string target_on = "wall";       // "wall": front wall; "floor": 1 m ahead on the floor
  double target_centre_height_m = 0.8;  // on the wall
  double texels_per_m = 200;
  unsigned seed = 1;  // textures
};

struct IndoorScene {
  std::vector<ScenePlane> planes;
  StartTarget target;
};

IndoorScene makeRoom(const RoomParams& params);

struct RayHit {
  int plane = -1;  // index into scene.planes, -1 when nothing is hit
  double distance = std::numeric_limits<double>::infinity();  // along the unit direction
  double a = 0, b = 0;  // plane coordinates of the hit, metres
};

// Nearest plane hit by the ray origin + s * direction (direction of unit length), s > 0.
RayHit castRay(const IndoorScene& scene, const cv::Vec3d& origin, const cv::Vec3d& direction);

}  // namespace mono_plane_detection
