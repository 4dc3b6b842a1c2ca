// The metric map of planes over time: each image's planes (with the 3D points of their
// tracks) are associated to the planes already mapped, fused, keep a stable id, and
// fade when no longer confirmed. Memory is bounded. ROS-free.
#pragma once

#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "mono_plane_detection/geometry/plane_fit.h"

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
  // An observation counts only from a viewpoint at least this share of the plane's
  // distance away from every view counted before (3 images of one spot do not confirm).
  double view_spacing = 0.03;
  // A point is on a plane within this many standard deviations of its position along
  // the viewing ray (PlaneObservation::sigma_m), never beyond max_residual_m.
  double coplanar_sigmas = 3.0;
  double min_residual_m = 0.005;      // the tolerance of a perfectly triangulated point
  // Points known less well than this across the plane (their uncertainty along the ray
  // times the ray's angle to the plane) cannot test coplanarity: they wait outside the
  // map until retriangulated with more parallax.
  double max_point_sigma_m = 0.05;  // = max_residual_m: 0.02-0.03 lost far walls (measured)
  // A plane whose points fall into two groups this far apart, one of which alone is not
  // that plane (or only a strip), is two surfaces: not taken.
  double min_gap_m = 0.25;
  // And only once its points fix its normal to this (1 sigma, normal_sigma_deg): half the
  // 2 deg a mapped plane may be off. A strip of points leaves the plane free to turn.
  double max_normal_sigma_deg = 1.0;
  // A plane whose points fix its normal to max_normal_sigma_deg is held at right angles
  // to (or parallel to) better-known confirmed planes while its points do not reject that
  // at this many of their standard deviations (mapping/structure_fit.h); 0: off.
  double structure_sigmas = 3.0;
  // How far the map's up (PlaneMap::setVertical: the start-up target's y, hung upright on
  // a wall, or the odometry frame's z) may be from the room's vertical, 1 sigma (deg).
  // Floors, ceilings and walls are held level or upright by it as by a confirmed plane,
  // while their points allow (structure_sigmas). 0.2: a target hung level with a spirit
  // level (1 mm over an A4 sheet's long edge); hung by eye, 0.5; 0: off. At or above
  // max_normal_sigma_deg it does nothing (only planes fixed to that are held).
  double up_sigma_deg = 0.2;
  // Whether the map's up can hold any plane: it is offered only to planes known worse than
  // up_sigma_deg, and only planes known to max_normal_sigma_deg are held, by structure_sigmas.
  bool upCanHold() const {
    return up_sigma_deg > 0 && structure_sigmas > 0 && up_sigma_deg < max_normal_sigma_deg;
  }
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
  // Per point: standard deviation of its position along the viewing ray (m), from the
  // landmark's parallax and the pose's reprojection error. Empty: unknown, every point
  // gets max_residual_m.
  std::vector<double> sigma_m;
  // A plane from the tracks' motion (PipelineParams::motion_plane_images): the camera
  // centres its fit took the tracks from, counted as views besides `viewpoint`, and its
  // normal's sigma from that fit (deg; -1: none, the points' spread decides). Its points
  // lie on the plane by construction and say nothing about how well it is known.
  std::vector<cv::Vec3d> measured_from;
  double normal_sigma_deg = -1;
};

struct MapPlane {
  int id = 0;                      // stable, never reused
  cv::Vec3d normal{0, 0, 1};       // unit, towards the side it was seen from
  double distance = 0;             // m: the plane is {x : normal . x = distance}
  double rms_m = 0;                // fit over its points
  // Its points' own plane, before the room's right angles (MapParams::structure_sigmas)
  // hold it: what the views it counts are spaced by, as its confirmation is its points'.
  cv::Vec3d own_normal{0, 0, 1};
  double own_distance = 0;
  // How well its points fix the normal (deg): rms / sqrt(points) against their spread
  // across the plane's long axis.
  double normal_sigma_deg = 180;
  double motion_sigma_deg = 180;   // the best fit from the tracks' motion that joined it
  std::vector<cv::Vec3d> polygon;  // convex hull of its points, map frame
  int observations = 0;               // from distinct viewpoints (MapParams::view_spacing)
  std::vector<cv::Vec3d> views;      // the viewpoints counted, map frame
  double first_seen = 0, last_seen = 0;  // stamps, s
  double confidence = 0;                 // 0..1: grows with observations, fades unseen
  // Track id -> latest position and the stamp it was seen on the plane.
  std::map<std::uint64_t, std::pair<cv::Vec3d, double>> points;
  bool confirmed(const MapParams& p) const {
    return observations >= p.confirm_observations && normal_sigma_deg <= p.max_normal_sigma_deg;
  }
};

class PlaneMap {
 public:
  explicit PlaneMap(const MapParams& params = MapParams()) : params_(params) {}

  // Fuses one image's observations (time `stamp`); returns for each the id of the map
  // plane it went to, -1 when it was not usable (too few points, no plane fits). An
  // image plane can hold several 3D planes (under pure rotation every plane moves with
  // the same homography): each is fused; the id returned is the largest's.
  std::vector<int> update(const std::vector<PlaneObservation>& observations, double stamp);

  // Fuses points known to lie on one plane (camera_height: the floor landmarks the
  // start's check fitted the map's floor to), without the image planes' split into
  // surfaces; returns the map plane's id, -1 when they fit no plane.
  int addKnownPlane(const PlaneObservation& observation, double stamp);

  const std::vector<MapPlane>& planes() const { return planes_; }
  const MapParams& params() const { return params_; }
  // The room's vertical in the map's frame, known to MapParams::up_sigma_deg (the target's
  // or the odometry's up), or none (camera_height's own floor fit, a target on the floor):
  // planes are held level or upright by it. None until set, and after reset().
  void setVertical(const std::optional<cv::Vec3d>& up) { vertical_ = up; }
  const std::optional<cv::Vec3d>& vertical() const { return vertical_; }
  // Empties the map; plane ids go on from the last one given (never reused).
  void reset();

 private:
  // Each point's tolerance from the plane with this normal (coplanar_sigmas x its
  // uncertainty across the plane, within [min_residual_m, max_residual_m]); -1 for a
  // point too uncertain across it (max_point_sigma_m).
  std::vector<double> tolerances(const PlaneObservation& obs, const cv::Vec3d& normal) const;
  PlaneFit fitObservation(const PlaneObservation& obs, int needed) const;
  int fuse(const PlaneObservation& kept, const cv::Vec3d& normal, double distance, double stamp);
  int associate(const cv::Vec3d& normal, double distance, const PlaneObservation& obs) const;
  // `merged`: the id of a plane merged into this one (not a reference for it).
  bool refit(MapPlane& plane, const cv::Vec3d& viewpoint, int merged = -1) const;
  // Refit's first step: points on a confirmed plane across this one, off the plane of its
  // other points, that turn it (`with`: the fit of all its points) leave it; true if any.
  bool releaseToCrossingPlanes(MapPlane& plane, int merged, const PlaneFit& with) const;
  void mergeDuplicates(const cv::Vec3d& viewpoint);
  // Removes the planes whose points larger confirmed planes explain: a mixture of two of
  // their surfaces (fewer than min_points on none of them, and a strip of them on each of
  // two within 45 deg of the plane), or one's points seen leaning (most of them that
  // one's own tracks, on it, and it within 45 deg).
  void dropExplained();
  void fadeAndBound(double stamp);

  MapParams params_;
  std::vector<MapPlane> planes_;
  int next_id_ = 1;
  std::optional<cv::Vec3d> vertical_;
};

}  // namespace mono_plane_detection
