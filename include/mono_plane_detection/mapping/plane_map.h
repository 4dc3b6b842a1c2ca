// The metric map of planes over time: each image's planes (with the 3D points of their
// tracks) are associated to the planes already mapped, fused, keep a stable id, and
// fade when no longer confirmed. Memory is bounded. ROS-free.
#pragma once

#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

namespace mono_plane_detection {

struct MapParams {
  double max_residual_m = 0.05;       // a point belongs to a plane within this distance
  int min_points = 6;                 // 3D points needed to put a plane into the map
  double min_share = 0.3;             // and this share of the image plane's points (a chance
                                      // alignment of scattered points explains few of them)
  double max_angle_deg = 12.0;        // association / merge gate on the normals
  double max_offset_m = 0.15;         // association / merge gate on the distance between planes
  double min_shared_ids = 0.3;        // or: this share of the observation's tracks already on it
  int confirm_observations = 3;       // a plane is confirmed after this many observations
  double tentative_timeout_s = 2.0;   // unconfirmed planes not seen for this long are removed
  double fade_time_s = 20.0;          // confidence halves roughly every 0.7 x this unseen
  size_t max_planes = 32;             // lowest confidence removed beyond this
  size_t max_points_per_plane = 400;  // least recently seen points dropped beyond this
};

// One image plane with the metric positions of its tracks.
struct PlaneObservation {
  std::vector<std::uint64_t> ids;  // tracks on the plane with a 3D position
  std::vector<cv::Vec3d> points;   // their positions, map frame, m
  cv::Vec3d viewpoint;             // camera centre, map frame (orients the normal)
};

struct MapPlane {
  int id = 0;                      // stable, never reused
  cv::Vec3d normal{0, 0, 1};       // unit, towards the side it was seen from
  double distance = 0;             // m: the plane is {x : normal . x = distance}
  double rms_m = 0;                // fit over its points
  std::vector<cv::Vec3d> polygon;  // convex hull of its points, map frame
  int observations = 0;
  double first_seen = 0, last_seen = 0;  // stamps, s
  double confidence = 0;                 // 0..1: grows with observations, fades unseen
  // Track id -> latest position and the stamp it was seen on the plane.
  std::map<std::uint64_t, std::pair<cv::Vec3d, double>> points;
  bool confirmed(const MapParams& p) const { return observations >= p.confirm_observations; }
};

class PlaneMap {
 public:
  explicit PlaneMap(const MapParams& params = MapParams()) : params_(params) {}

  // Fuses one image's observations (time `stamp`); returns for each the id of the map
  // plane it went to, -1 when it was not usable (too few points, no plane fits). An
  // image plane can hold several 3D planes (under pure rotation every plane moves with
  // the same homography): each is fused; the id returned is the largest's.
  std::vector<int> update(const std::vector<PlaneObservation>& observations, double stamp);

  const std::vector<MapPlane>& planes() const { return planes_; }
  const MapParams& params() const { return params_; }
  void reset();

 private:
  int fuse(const PlaneObservation& kept, const cv::Vec3d& normal, double distance, double stamp);
  int associate(const cv::Vec3d& normal, double distance, const PlaneObservation& obs) const;
  bool refit(MapPlane& plane, const cv::Vec3d& viewpoint) const;
  void mergeDuplicates(const cv::Vec3d& viewpoint);
  void fadeAndBound(double stamp);

  MapParams params_;
  std::vector<MapPlane> planes_;
  int next_id_ = 1;
};

}  // namespace mono_plane_detection
