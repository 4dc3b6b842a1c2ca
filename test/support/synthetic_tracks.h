// Track frames of a room seen along a trajectory, without rendering: fixed random
// points on the room's planes (per_m2 per square metre, ids from 100) and the target's corners (ids
// 1-4, flagged), projected with pixel noise, kept when visible and not hidden. Ground truth for the
// pose, pipeline and map tests.
#pragma once

#include <random>
#include <vector>

#include "mono_plane_detection/sim/camera_trajectory.h"
#include "mono_plane_detection/sim/indoor_scene.h"
#include "mono_plane_detection/tracking/track_frame.h"

namespace mono_plane_detection {

struct SyntheticTracks {
  IndoorScene scene;
  CameraModel camera;
  TrajectoryParams trajectory;
  std::vector<cv::Vec3d> points;  // world frame; id = 100 + index
  std::vector<int> plane_of;      // scene plane index of each point
  Pose map_from_world;

  explicit SyntheticTracks(const std::string& path = "wheeled", double per_m2 = 25,
                           unsigned seed = 1) {
    scene = makeRoom(RoomParams());
    trajectory.name = path;
    map_from_world = scene.target.world_from_map.inverse();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.02, 0.98);
    for (size_t p = 0; p < scene.planes.size(); ++p) {
      const ScenePlane& plane = scene.planes[p];
      const int count = static_cast<int>(per_m2 * plane.width_m * plane.height_m);
      for (int k = 0; k < count; ++k) {
        points.push_back(plane.origin + unit(rng) * plane.width_m * plane.u_axis +
                         unit(rng) * plane.height_m * plane.v_axis);
        plane_of.push_back(static_cast<int>(p));
      }
    }
  }

  Pose truthMapFromCamera(double t) const { return map_from_world * trajectoryPose(trajectory, t); }

  // The frame at time t (s); stamps start at 1000 s.
  TrackFrame frame(double t, double noise_px = 0.2, unsigned seed = 7) const {
    return frameAt(trajectoryPose(trajectory, t), 1000 + t, noise_px, seed);
  }

  // The frame seen from any camera pose (world_from_camera), stamped `stamp`.
  TrackFrame frameAt(const Pose& world_from_camera, double stamp, double noise_px = 0.2,
                     unsigned seed = 7) const {
    const double t = stamp - 1000;
    const Pose camera_from_world = world_from_camera.inverse();
    std::mt19937 rng(seed + static_cast<unsigned>(t * 1000));
    std::normal_distribution<double> noise(0.0, noise_px);
    TrackFrame f;
    f.stamp = stamp;
    f.size = camera.size;
    auto add = [&](std::uint64_t id, const cv::Vec3d& x, bool corner) {
      const cv::Vec3d c = camera_from_world.apply(x);
      if (c[2] < 0.1) return;
      const cv::Point2d px = camera.project(c) + cv::Point2d(noise(rng), noise(rng));
      if (px.x < 0 || px.y < 0 || px.x > camera.size.width - 1 || px.y > camera.size.height - 1)
        return;
      const cv::Vec3d ray = x - world_from_camera.t;
      const RayHit hit = castRay(scene, world_from_camera.t, ray / cv::norm(ray));
      if (hit.distance < cv::norm(ray) - 1e-3) return;  // hidden behind another plane
      f.ids.push_back(id);
      f.pixels.push_back(px);
      f.target_corner.push_back(corner);
    };
    for (int k = 0; k < 4; ++k) add(1 + k, scene.target.corners[k], true);
    for (size_t i = 0; i < points.size(); ++i) add(100 + i, points[i], false);
    return f;
  }
};

// The room as if no target hung there: the frame without the target's corners.
inline TrackFrame withoutTarget(const TrackFrame& f) {
  TrackFrame out = f;
  out.ids.clear();
  out.pixels.clear();
  out.target_corner.clear();
  out.reidentified.clear();
  for (size_t i = 0; i < f.ids.size(); ++i)
    if (!f.target_corner[i]) {
      out.ids.push_back(f.ids[i]);
      out.pixels.push_back(f.pixels[i]);
      out.target_corner.push_back(false);
      if (!f.reidentified.empty()) out.reidentified.push_back(f.reidentified[i]);
    }
  return out;
}

}  // namespace mono_plane_detection
