// Issue 18: the whole ROS-free method (tracker with target start-up, plane pipeline,
// metric map) on the furnished room with real photographs on floor and walls
// (test/data/textures), 300 rendered images, judged against the ground truth: no
// confirmed plane that matches no surface, no surface mapped twice, accurate planes,
// the camera within a few percent of its path. The figures are printed per plane
// (docs/mapping.md reports them).
#include <gtest/gtest.h>

#include <cstdio>

#include "mono_plane_detection/eval/map_evaluation.h"
#include "mono_plane_detection/mapping/plane_pipeline.h"
#include "mono_plane_detection/sim/scene_renderer.h"
#include "mono_plane_detection/tracking/target_startup.h"

using namespace mono_plane_detection;

namespace {

struct RoomRun {
  MapEvaluation eval;
  std::vector<TruthPlane> truth;
  double worst_camera_m = 0, travelled_m = 0;
  int posed = 0;
  int odometry_checks = 0, odometry_disagreeing = 0;  // odometry_check.h's, decided
  bool odometry_alarm = false;                         // the monitor's, at any image
};

// odometry: the true camera poses as tf odom -> camera (metric_source odometry), the map
// from the first image on and in the world frame; judged in the target's frame.
// size: the images' (the field of view kept: the focal length scales with the width).
// noise_seed: image k's noise is seeded noise_seed * 100000 + k (run_pipeline --noise-seed).
RoomRun runFurnished(const std::string& path, bool odometry = false,
                     cv::Size size = cv::Size(640, 480), unsigned noise_seed = 1) {
  RoomParams room;
  room.layout = "furnished";
  room.photos = loadTexturePhotos(std::string(TEST_DATA_DIR) + "/textures");
  const IndoorScene scene = makeRoom(room);
  CameraModel camera;
  camera.size = size;
  camera.fx = camera.fy = 525.0 * size.width / 640.0;
  camera.cx = (size.width - 1) / 2.0;
  camera.cy = (size.height - 1) / 2.0;
  RenderOptions render;
  render.noise_sigma = 2;
  const SceneRenderer renderer(scene, camera, render);
  TrajectoryParams trajectory;
  trajectory.name = path;
  TrackerParams tracker_params;  // the profiles' 150 corners (config/tracker_*.yaml)
  tracker_params.max_features = 150;
  if (path == "humanoid") {
    tracker_params.pyramid_levels = 6;
    tracker_params.window_size_px = 15;
  }
  FeatureTracker tracker(tracker_params);
  TargetStartup startup;
  PipelineParams params;
  if (odometry) {
    params.pose.metric_source = "odometry";
    params.motion_plane_images = 5;  // exact odometry: planes before landmarks (docs/mapping.md)
  }
  PlanePipeline pipeline(params);
  pipeline.setCamera(camera.K(), camera.distortion());
  RoomRun run;
  run.truth = truthPlanes(scene);
  const Pose map_from_world = scene.target.world_from_map.inverse();
  cv::Vec3d last;
  for (int k = 0; k < 300; ++k) {
    const Pose world_from_camera = trajectoryPose(trajectory, k / 30.0);
    const std::vector<double> shares = imageShares(scene, camera, world_from_camera, 16);
    for (size_t p = 0; p < shares.size(); ++p)
      run.truth[p].max_image_share = std::max(run.truth[p].max_image_share, shares[p]);
    const cv::Mat image = renderer.render(world_from_camera, noise_seed * 100000u + k);
    tracker.process(image);
    startup.process(image, tracker);
    const TrackFrame frame = trackFrameOf(tracker.current(), 1000.0 + k / 30.0, image.size());
    const PipelineResult result =
        odometry ? pipeline.process(frame, world_from_camera) : pipeline.process(frame);
    const Pose truth = odometry ? world_from_camera : map_from_world * world_from_camera;
    run.odometry_checks += result.odometry_check.decided;
    run.odometry_disagreeing += result.odometry_check.decided && !result.odometry_check.agrees;
    run.odometry_alarm |= pipeline.odometryMonitor().disagrees();
    if (k > 0) run.travelled_m += cv::norm(truth.t - last);
    last = truth.t;
    if (result.pose) {
      ++run.posed;
      run.worst_camera_m =
          std::max(run.worst_camera_m, cv::norm(result.pose->map_from_camera.t - truth.t));
    }
  }
  std::vector<MapPlane> confirmed;
  for (const MapPlane& p : pipeline.map().planes())
    if (p.confirmed(pipeline.map().params())) confirmed.push_back(p);
  if (odometry)
    for (MapPlane& p : confirmed) {  // world -> the target's frame, as the truth
      p.normal = map_from_world.R * p.normal;
      p.distance += p.normal.dot(map_from_world.t);
      for (cv::Vec3d& v : p.polygon) v = map_from_world.apply(v);
    }
  run.eval = evaluateMap(confirmed, run.truth, 0.10, 20.0, 0.3);
  std::printf("%s%s: camera worst %.3f m over %.2f m (%.1f %%), placed in %d images\n",
              path.c_str(), odometry ? " (odometry)" : "", run.worst_camera_m, run.travelled_m,
              100 * run.worst_camera_m / run.travelled_m, run.posed);
  for (size_t i = 0; i < confirmed.size(); ++i)
    std::printf("  plane %d (%zu points, %d views) -> %s: normal %.2f deg, distance %.3f m\n",
                confirmed[i].id, confirmed[i].points.size(), confirmed[i].observations,
                run.eval.matches[i].truth_id >= 0 ? run.eval.matches[i].truth_name.c_str()
                                                  : "NO SURFACE",
                run.eval.matches[i].normal_error_deg, run.eval.matches[i].distance_error_m);
  for (int id : run.eval.missed)
    for (const TruthPlane& t : run.truth)
      if (t.id == id)
        std::printf("  missed %s (up to %.0f %% of an image)\n", t.name.c_str(),
                    100 * t.max_image_share);
  return run;
}

int falsePlanes(const MapEvaluation& e) {
  int n = 0;
  for (const PlaneMatch& m : e.matches) n += m.truth_id < 0;
  return n;
}

bool found(const RoomRun& run, const std::string& name) {
  for (const PlaneMatch& m : run.eval.matches)
    if (m.truth_name == name) return true;
  return false;
}

// Issue 18's bounds on every run: no false plane, no split, the room's four planes that
// fill 10 % of an image and have corners found, every normal within 2 deg.
void expectTheRoomsPlanes(const RoomRun& run) {
  EXPECT_EQ(falsePlanes(run.eval), 0);
  EXPECT_TRUE(run.eval.split.empty());
  for (const std::string name : {"front_wall", "floor", "shelf_+x", "left_wall"})
    EXPECT_TRUE(found(run, name)) << name;
  EXPECT_LT(run.eval.worst_normal_error_deg, 2.0);
}

}  // namespace

// Figures on this commit (normal deg / distance m), wheeled: front wall 0.95 / 0.000, floor
// 0.41 / 0.002, shelf front 1.06 / 0.010, left wall 1.30 / 0.021, camera 0.5 % of the path
// (2.0 % before the start averaged its orientation over the images, 1.4 % before the
// sheet was re-detected around its tracks, 1.1 % before the local bundle adjustment:
// left wall 1.96 / 0.096); humanoid: front wall 0.06 / 0.003, shelf front 0.72 / 0.009,
// left wall 0.73 / 0.018, floor 0.14 / 0.019, camera 0.4 % (0.6 % before). Missed, and not
// mappable here (docs/mapping.md): the
// sideboard front (wheeled: in view only before the metric start, and placing those
// images afterwards does not help: its tracks cover a 0.2-0.3 m strip of its 1.3 m face;
// with exact odometry it is mapped from its tracks' motion) and the back wall (humanoid: plain paint, no corner on it).
TEST(FurnishedRoom, WheeledPath) {
  const RoomRun run = runFurnished("wheeled");
  // The left wall: 18 points in 7 views, 0.1 m off, before the corners were spread over
  // the image (TrackerParams::spread_grid_columns); 53 points in 10 views since.
  expectTheRoomsPlanes(run);
  // 0.096 m (left wall) before the local bundle adjustment, 0.021 m since (0.015 m in
  // run_pipeline's profiles, noise seed 2).
  EXPECT_LT(run.eval.worst_distance_error_m, 0.05);
  EXPECT_GE(run.posed, 250);
  // The target seen face-on from 2 m tilts the map (1.9 deg with the corners averaged,
  // 2.0 % of the path; 1.4 % with the orientations averaged, 1.1 % with the corners
  // re-detected: docs/mapping.md "The wheeled start's tilt"); the worst was then at the
  // end of the path: the poses' drift, 0.5 % with the local bundle adjustment (0.4 % in
  // run_pipeline's profiles; the bare room's noise seeds 0-3 0.3-0.5 %). Issue 18's 1 %.
  EXPECT_LT(run.worst_camera_m, 0.01 * run.travelled_m);
}

// The same path seen at 1280x960: finer pixels, the same 150 corners. The left wall's
// sparse landmarks fell into bands the map took for strips of two surfaces (a fixed
// width of 20 cm) and it was missed in 2 of 3 noise seeds; a band is a strip now only
// when its own points do not fix its normal (docs/mapping.md, step 4). Noise seed 0
// (seed 1 found it either way): front wall 0.56 deg, floor 0.05, shelf front 0.32, left
// wall 0.40 deg / 0.001 m (missed before), camera 0.4 % of the path.
TEST(FurnishedRoom, WheeledPathAt1280x960) {
  const RoomRun run = runFurnished("wheeled", false, cv::Size(1280, 960), 0);
  expectTheRoomsPlanes(run);
  EXPECT_LT(run.eval.worst_distance_error_m, 0.05);
  EXPECT_LT(run.worst_camera_m, 0.01 * run.travelled_m);
}

TEST(FurnishedRoom, HumanoidPath) {
  const RoomRun run = runFurnished("humanoid");
  expectTheRoomsPlanes(run);
  // The floor (25 points in 7 views, the least supported plane) moves by centimetres with
  // the start: 0.003 m with the start's corners averaged, 0.022 m with its orientations;
  // 0.029 m held to the room's right angles (map/structure_sigmas: its strip leans with
  // the left wall and shelf front it is held to; 0.025 m without); 0.023 m held level by
  // the map's up too (map/up_sigma_deg).
  EXPECT_LT(run.eval.worst_distance_error_m, 0.03);
  EXPECT_GE(run.posed, 250);
  // 0.5 % before the sheet was re-detected, 0.3-0.6 % since (with the search region's
  // margin): the 1 % with room to move.
  EXPECT_LT(run.worst_camera_m, 0.008 * run.travelled_m);
}

// The same wheeled path with the map from the first image (odometry): the planes without
// the target start's tilt (normals within 0.5 deg instead of 1.2-1.5). The sideboard front's
// tracks reach the 3 deg triangulation parallax only from image 17, when 6-8 are left and
// the image-space vote no longer separates them: it is mapped from its tracks' motion
// (PipelineParams::motion_plane_images, set here: the true poses are odometry right at
// the centimetre scale; 0.70 deg / 0.014 m, 10 points in 3 views) and missed without.
TEST(FurnishedRoom, WheeledPathWithOdometry) {
  const RoomRun run = runFurnished("wheeled", true);
  EXPECT_EQ(falsePlanes(run.eval), 0);
  EXPECT_TRUE(run.eval.split.empty());
  for (const std::string name : {"front_wall", "floor", "shelf_+x", "left_wall", "sideboard_-y"})
    EXPECT_TRUE(found(run, name)) << name;
  EXPECT_LT(run.eval.worst_normal_error_deg, 0.8);
  EXPECT_LT(run.eval.worst_distance_error_m, 0.02);
  EXPECT_EQ(run.posed, 300);
  // The true odometry agrees with the tracks of real textures (odometry_check.h).
  std::printf("odometry checks: %d, %d disagreeing\n", run.odometry_checks,
              run.odometry_disagreeing);
  EXPECT_GT(run.odometry_checks, 5);
  EXPECT_FALSE(run.odometry_alarm);
}
