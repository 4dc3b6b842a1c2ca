// A room of textured planes with the start-up target painted on one of them: the
// ground truth every synthetic sequence is rendered from. World frame: metres, z up,
// the floor at z = 0, the robot starts at the origin looking along +y. ROS-free.
#pragma once

#include <array>
#include <cmath>
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
  // Openings (plane coordinates, metres: x = a, y = b) where rays pass through, e.g. a
  // door recess in a wall.
  std::vector<cv::Rect2d> holes;
  std::string surface = "generated";  // generated | photo | paint | wood | books: what covers it

  cv::Vec3d normal() const { return u_axis.cross(v_axis); }
  // True when (a, b) lies on the plane's rectangle and not in a hole.
  bool contains(double a, double b) const;
  double distance() const { return normal().dot(origin); }  // plane: normal . X = distance
  // How far a point (a camera centre) is from the plane, m.
  double distanceFrom(const cv::Vec3d& point) const { return std::abs(normal().dot(point) - distance()); }
  std::array<cv::Vec3d, 4> corners() const;
};

// The start-up target that fixes the metric scale: the paper's white rectangle (II-A) on
// a black border, on a mid-grey wall or on wood, or an ArUco marker; or none at all (its
// geometry still defines the map frame of the ground truth).
struct StartTarget {
  std::string type = "sheet";                // none | sheet | aruco
  int plane_index = 0;                       // the plane it is painted on
  double width_m = 0.297, height_m = 0.210;  // white rectangle (A4); the marker's side
  double border_m = 0.05;                    // black border around it (background black)
  int aruco_dictionary = 0, aruco_id = -1;   // cv::aruco::PREDEFINED_DICTIONARY_NAME, id
  cv::Vec3d centre;                          // world frame
  // White rectangle (or the marker's outer black square), world frame:
  // (-u,-v) (+u,-v) (+u,+v) (-u,+v). The marker's own order (top-left, top-right,
  // bottom-right, bottom-left as OpenCV reports it) is corners 3, 2, 1, 0.
  std::array<cv::Vec3d, 4> corners;
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
  // furnished: a sideboard (cabinet) and a bookshelf against the walls, a table with a
  // top, a door recess in the right wall; plain painted walls with posters next to
  // richly textured ones; shading by a light from above. bare: the six planes only.
  std::string layout = "bare";
  // Grey photographs painted on the walls and floor instead of generated texture (each
  // tiled at photo_tile_m wide); empty: generated texture.
  std::vector<cv::Mat> photos;
  double photo_tile_m = 1.6;
  std::string target_type = "sheet";        // none | sheet | aruco
  std::string target_background = "black";  // sheet: black border | grey wall | wood table
  int aruco_dictionary = 0;                 // cv::aruco::DICT_4X4_50
  int aruco_id = 0;
  double aruco_size_m = 0.15;  // side of the marker's black square
};

struct IndoorScene {
  std::vector<ScenePlane> planes;
  StartTarget target;
};

// Throws std::invalid_argument on an unknown layout, target type or background.
IndoorScene makeRoom(const RoomParams& params);

// The images (png, jpg, jpeg, bmp, pgm; sorted by name) of a folder, grey. Throws
// std::runtime_error when the folder holds none that can be read.
std::vector<cv::Mat> loadTexturePhotos(const std::string& folder);

struct RayHit {
  int plane = -1;  // index into scene.planes, -1 when nothing is hit
  double distance = std::numeric_limits<double>::infinity();  // along the unit direction
  double a = 0, b = 0;  // plane coordinates of the hit, metres
};

// Nearest plane hit by the ray origin + s * direction (direction of unit length), s > 0.
RayHit castRay(const IndoorScene& scene, const cv::Vec3d& origin, const cv::Vec3d& direction);

}  // namespace mono_plane_detection
