#include "mono_plane_detection/eval/map_evaluation.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "mono_plane_detection/geometry/plane_fit.h"

namespace mono_plane_detection {

std::vector<TruthPlane> truthPlanes(const IndoorScene& scene) {
  const Pose map_from_world = scene.target.world_from_map.inverse();
  std::vector<TruthPlane> out;
  for (const ScenePlane& p : scene.planes) {
    TruthPlane t;
    t.id = p.id;
    t.name = p.name;
    t.normal = map_from_world.R * p.normal();
    t.distance = t.normal.dot(map_from_world.apply(p.origin));
    out.push_back(t);
  }
  return out;
}

std::vector<double> imageShares(const IndoorScene& scene, const CameraModel& camera,
                                const Pose& world_from_camera, int step) {
  std::vector<double> hits(scene.planes.size(), 0.0);
  double samples = 0;
  for (int v = step / 2; v < camera.size.height; v += step)
    for (int u = step / 2; u < camera.size.width; u += step) {
      cv::Vec3d ray((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
      ray = world_from_camera.R * (ray / cv::norm(ray));
      const RayHit hit = castRay(scene, world_from_camera.t, ray);
      if (hit.plane >= 0) hits[hit.plane] += 1;
      samples += 1;
    }
  for (double& h : hits) h /= std::max(1.0, samples);
  return hits;
}

MapEvaluation evaluateMap(const std::vector<MapPlane>& planes, const std::vector<TruthPlane>& truth,
                          double min_share, double max_angle_deg, double max_offset_m) {
  MapEvaluation eval;
  std::map<int, int> matched;  // truth id -> mapped planes matched to it
  for (const MapPlane& plane : planes) {
    PlaneMatch m;
    m.map_id = plane.id;
    // Parallel surfaces (a wall and the door recessed in it, a shelf front before the
    // wall) differ only in offset: the best match weighs both gates.
    double best_cost = 2.0;
    for (const TruthPlane& t : truth) {
      const double angle = normalAngleDeg(plane.normal, t.normal);
      const double offset = std::abs(plane.distance - t.distance);
      if (angle > max_angle_deg || offset > max_offset_m) continue;
      const double cost = angle / max_angle_deg + offset / max_offset_m;
      if (cost < best_cost) {
        best_cost = cost;
        m.truth_id = t.id;
        m.truth_name = t.name;
        m.normal_error_deg = angle;
        m.distance_error_m = offset;
      }
    }
    if (m.truth_id >= 0) {
      ++matched[m.truth_id];
      eval.worst_normal_error_deg = std::max(eval.worst_normal_error_deg, m.normal_error_deg);
      eval.worst_distance_error_m = std::max(eval.worst_distance_error_m, m.distance_error_m);
    }
    eval.matches.push_back(m);
  }
  for (const TruthPlane& t : truth) {
    if (matched[t.id] > 1) eval.split.push_back(t.id);
    if (t.max_image_share >= min_share && matched[t.id] == 0) eval.missed.push_back(t.id);
  }
  return eval;
}

Pose rigidAlign(const std::vector<cv::Vec3d>& from, const std::vector<cv::Vec3d>& to) {
  cv::Vec3d cf(0, 0, 0), ct(0, 0, 0);
  for (size_t i = 0; i < from.size(); ++i) {
    cf += from[i];
    ct += to[i];
  }
  cf /= static_cast<double>(from.size());
  ct /= static_cast<double>(to.size());
  cv::Matx33d S = cv::Matx33d::zeros();
  for (size_t i = 0; i < from.size(); ++i) S += (to[i] - ct) * (from[i] - cf).t();
  cv::Mat W, U, Vt;
  cv::SVD::compute(cv::Mat(S), W, U, Vt);
  cv::Matx33d D = cv::Matx33d::eye();
  if (cv::determinant(cv::Mat(U * Vt)) < 0) D(2, 2) = -1;  // a rotation, not a reflection
  const cv::Matx33d R(cv::Mat(U * cv::Mat(D) * Vt));
  return {R, ct - R * cf};
}

}  // namespace mono_plane_detection
