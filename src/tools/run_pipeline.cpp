// Runs the whole method in one process, without ROS, on a rendered room: tracker with
// target start-up, plane pipeline, metric map; prints the map against the ground truth.
// For tuning, the soak run (issue: long runs) and a quick look without a ROS master.
//   rosrun mono_plane_detection run_pipeline --trajectory humanoid --frames 300
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <optional>
#include <limits>
#include <string>

#include "cli_args.h"
#include "config_dir.h"
#include "profile.h"
#include "mono_plane_detection/sim/camera_trajectory.h"
#include "mono_plane_detection/eval/map_evaluation.h"
#include "mono_plane_detection/mapping/plane_pipeline.h"
#include "mono_plane_detection/sim/scene_renderer.h"
#include "mono_plane_detection/tracking/target_startup.h"
#include "mono_plane_detection/viz/draw_planes.h"
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

using namespace mono_plane_detection;

namespace {

double residentMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // peak; flat peak = no growth
}

double currentRssMb() {
  FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return residentMb();
  long pages = 0, resident = 0;
  const int n = std::fscanf(f, "%ld %ld", &pages, &resident);
  std::fclose(f);
  return n == 2 ? resident * 4096.0 / (1024 * 1024) : residentMb();
}

}  // namespace

int main(int argc, char** argv) {
  TrajectoryParams trajectory;
  CameraModel camera;
  RenderOptions render;
  render.noise_sigma = 2;
  int frames = 300, report_every = 0, loops = 1, frame_gap = 0, features = 0;
  std::string profile = "auto";
  double fps = 30;
  unsigned seed = 1;
  long noise_seed = -1;
  std::string metric_source = "target";
  cli::Parser cli(
      "run_pipeline", "[options]",
      "  Renders a room seen from a moving camera and runs tracker + planes + map on it,\n"
      "  then prints each mapped plane against the ground truth and the camera path error,\n"
      "  and how far off the metric start put the camera's orientation (the tilt the map\n"
      "  inherits from the start-up target; not with camera_height, whose map has its own\n"
      "  heading). Planes the map holds but has not confirmed (too few views, a normal\n"
      "  known worse than map/max_normal_sigma_deg) are listed as tentative, with the\n"
      "  surface they match: a missed plane the map was still confirming shows there.",
      "exit codes: 0 every true plane mapped once, 1 a plane missed or split, 2 bad usage\n");
  RoomParams room;
  std::string textures, save_dir, top_view;
  int save_every = 0;
  cli.choice("trajectory", &trajectory.name,
             {"wheeled", "humanoid", "rotation", "turn_in_place", "look_around"}, "camera motion")
      .choice("layout", &room.layout, {"bare", "furnished"}, "the room (make_sequence --layout)")
      .text("textures", &textures, "paint floor and walls with the photographs in DIR", "DIR")
      .choice("background", &room.target_background, {"black", "grey", "wood"},
              "around the start-up sheet")
      .integer("frames", &frames, 1, 1000000, "images per loop")
      .number("fps", &fps, 0.1, 1000.0, "images per second", "F")
      .number("noise", &render.noise_sigma, 0.0, 255.0, "image noise sigma, grey levels", "SIGMA")
      .integer("supersample", &render.supersample, 1, 8,
               "rays per pixel side (anti-aliasing; width x height x supersample^2 at most "
               "2^24)")
      .integer<unsigned>("seed", &seed, 0, std::numeric_limits<unsigned>::max(),
                         "room textures and humanoid jerks", "S")
      .integer<long>("noise-seed", &noise_seed, -1, std::numeric_limits<unsigned>::max(),
                     "image noise of image k seeded N * 100000 + k (-1: --seed's; the rostests' "
                     "bags are 0)", "N")
      .choice("metric-source", &metric_source, {"target", "camera_height"},
              "camera_height: no target in the room, metres from the trajectory's camera "
              "height; judged after the rigid motion that best aligns the camera paths")
      .text("profile", &profile,
            "parameters: config/{tracker,planes}.yaml with the overlay of profile P (wheeled, "
            "humanoid), or one .yaml file over both (each name where the tracker's or the "
            "planes' table has it); auto: the trajectory's profile",
            "P")
      .integer("frame-gap", &frame_gap, 0, 1000,
               "frames between the two views of the planes before the camera is placed (0: "
               "the profile's)")
      .integer("width", &camera.size.width, 64, 4096, "image width, pixels", "W")
      .integer("height", &camera.size.height, 48, 4096, "image height, pixels", "H")
      .integer("features", &features, 0, 10000, "the tracker's max_features (0: the profile's)")
      .text("save-dir", &save_dir, "write overlays (planes drawn) here, with --save-every", "DIR")
      .integer("save-every", &save_every, 0, 1000000, "an overlay every N images (0: none)")
      .text("top-view", &top_view,
            "write a top view (room, furniture, confirmed planes, camera paths) as PNG", "FILE")
      .integer("report-every", &report_every, 0, 1000000,
               "print the state every N frames (0: only the end)")
      .integer("loop", &loops, 1, 100000,
               "run the sequence N times (soak: the map is reset at each loop, as a bag loop "
               "does; prints resident memory and time per frame per loop)");
  if (const auto code = cli.parse(argc, argv)) return *code;
  if (const std::string e = renderSizeError(camera.size, render.supersample); !e.empty())
    return cli.fail(e);
  // Keep the focal length's field of view when the size changes.
  camera.fx = camera.fy = 525.0 * camera.size.width / 640.0;
  camera.cx = (camera.size.width - 1) / 2.0;
  camera.cy = (camera.size.height - 1) / 2.0;
  trajectory.seed = seed;

  room.seed = seed;
  if (noise_seed < 0) noise_seed = seed;
  const bool floor_start = metric_source == "camera_height";
  if (floor_start) room.target_centre_height_m = 20;  // above the room: never seen
  if (!textures.empty()) {
    try {
      room.photos = loadTexturePhotos(textures);
    } catch (const std::exception& e) {
      return cli.fail(std::string("--textures: ") + e.what());
    }
  }
  const IndoorScene scene = makeRoom(room);
  const SceneRenderer renderer(scene, camera, render);
  std::vector<TruthPlane> truth = truthPlanes(scene);
  const Pose map_from_world = scene.target.world_from_map.inverse();

  // The nodelets' settings for this robot, so that a run here is a run there.
  if (profile == "auto")
    profile = trajectory.name == "humanoid" || trajectory.name == "look_around" ? "humanoid"
              : trajectory.name == "wheeled" || trajectory.name == "turn_in_place" ? "wheeled"
                                                                                  : "default";
  TrackerNodeParams tracker_node;
  PlaneNodeParams plane_node;
  const std::vector<std::string> errors =
      loadProfiles(toolConfigDir(MPD_CONFIG_DIR), profile, "tracker", trackerNodeParamTable(), tracker_node,
                   "planes", planeNodeParamTable(), plane_node);
  if (!errors.empty()) {
    for (const std::string& e : errors) std::fprintf(stderr, "run_pipeline: %s\n", e.c_str());
    return 2;
  }
  TrackerParams tracker_params = tracker_node.tracker;
  if (features > 0) tracker_params.max_features = features;
  PipelineParams params = plane_node.pipeline;
  if (frame_gap > 0) params.frame_gap = frame_gap;
  if (floor_start) {
    params.pose.metric_source = "camera_height";
    params.pose.floor.camera_height_m = trajectoryPose(trajectory, 0).t[2];
  }

  using Clock = std::chrono::steady_clock;
  std::printf("run_pipeline: %s, profile %s, %d frames x %d loop(s), %dx%d, noise %.1f\n",
              trajectory.name.c_str(), profile.c_str(), frames, loops, camera.size.width,
              camera.size.height, render.noise_sigma);
  FeatureTracker tracker(tracker_params);
  TargetStartup startup(tracker_node.target);
  PlanePipeline pipeline(params);
  pipeline.setCamera(camera.K(), camera.distortion());
  const double start_rss = currentRssMb();
  int exit_code = 0;
  for (int loop = 0; loop < loops; ++loop) {
    tracker.reset();
    startup.reset();
    double track_ms = 0, plane_ms = 0, travelled = 0, pos_err_sum = 0, pos_err_max = 0;
    std::vector<cv::Vec3d> path_truth, path_estimate;  // world frame
    std::vector<cv::Vec3d> est_map, truth_map;          // posed images: estimate, truth
    int first_posed = -1;
    double start_error_deg = -1;  // the first posed image's orientation against the truth
    int posed = 0, tracking = 0;
    cv::Vec3d last_position;
    for (int k = 0; k < frames; ++k) {
      const double t = k / fps;
      const Pose world_from_camera = trajectoryPose(trajectory, t);
      if (loop == 0) {
        const std::vector<double> shares = imageShares(scene, camera, world_from_camera, 16);
        for (size_t p = 0; p < truth.size(); ++p)
          if (shares[p] > truth[p].max_image_share) {
            truth[p].max_image_share = shares[p];
            truth[p].range_m = scene.planes[p].distanceFrom(world_from_camera.t);
          }
      }
      const cv::Mat image = renderer.render(world_from_camera,
                                            static_cast<unsigned>(noise_seed) * 100000u + k);
      const auto t0 = Clock::now();
      tracker.process(image);
      startup.process(image, tracker);
      const auto t1 = Clock::now();
      // Every loop starts over in time: a bag loop.
      const TrackFrame frame = trackFrameOf(tracker.current(), 1000.0 + t, image.size());
      const PipelineResult result = pipeline.process(frame);
      const auto t2 = Clock::now();
      track_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
      plane_ms += std::chrono::duration<double, std::milli>(t2 - t1).count();
      const Pose truth_pose = map_from_world * world_from_camera;
      path_truth.push_back(world_from_camera.t);
      if (result.pose)
        path_estimate.push_back(scene.target.world_from_map.apply(result.pose->map_from_camera.t));
      if (k > 0) travelled += cv::norm(truth_pose.t - last_position);
      last_position = truth_pose.t;
      double frame_err = -1;
      if (result.pose) {
        if (first_posed < 0) {
          first_posed = k;
          start_error_deg = rotationAngleDeg(result.pose->map_from_camera.R * truth_pose.R.t());
        }
        est_map.push_back(result.pose->map_from_camera.t);
        truth_map.push_back(truth_pose.t);
      }
      if (result.pose && !floor_start) {
        const double err = cv::norm(result.pose->map_from_camera.t - truth_pose.t);
        pos_err_sum += err;
        pos_err_max = std::max(pos_err_max, err);
        frame_err = err;
        ++posed;
      }
      tracking += result.state == PipelineState::kTracking;
      if (save_every > 0 && !save_dir.empty() && k % save_every == 0 && loop == 0) {
        char name[64];
        std::snprintf(name, sizeof(name), "/overlay_%04d.png", k);
        cv::imwrite(save_dir + name, drawPlanes(image, result));
      }
      if (report_every > 0 && (k + 1) % report_every == 0)
        std::printf(
            "  frame %d: %s, %zu image planes, %zu map planes, %zu points, "
            "position error %.3f m%s\n",
            k + 1, result.status.c_str(), result.planes.size(), pipeline.map().planes().size(),
            frame.ids.size(), frame_err,
            result.pose && floor_start
                ? cv::format(", map position (%.3f %.3f %.3f)", result.pose->map_from_camera.t[0],
                             result.pose->map_from_camera.t[1], result.pose->map_from_camera.t[2])
                      .c_str()
                : "");
    }
    const double rss = currentRssMb();
    std::printf(
        "loop %d: tracker %.2f ms/frame, planes+map %.2f ms/frame, RSS %.1f MB "
        "(start %.1f), landmarks %zu, map planes %zu\n",
        loop + 1, track_ms / frames, plane_ms / frames, rss, start_rss,
        pipeline.poseEstimator()->landmarks().size(), pipeline.map().planes().size());
    if (std::vector<double> t = pipeline.poseEstimator()->bundleTimesMs(); !t.empty()) {
      std::sort(t.begin(), t.end());
      double sum = 0;
      for (double v : t) sum += v;
      const PoseEstimator::BundleCounts& c = pipeline.poseEstimator()->bundleCounts();
      std::printf("bundle adjustment: %zu keyframes, %.2f ms mean, %.2f ms p95, %.2f ms max; "
                  "refused %d%s%s, observations behind a camera after %d, steps refused for "
                  "it %d\n",
                  t.size(), sum / static_cast<double>(t.size()), t[t.size() * 95 / 100], t.back(),
                  c.refused, c.refused ? " (last: " : "",
                  c.refused ? (c.last_reason + ")").c_str() : "", c.behind_after, c.refused_behind);
    }
    // (camera_height's map has its own heading: its start is not compared.)
    if (first_posed >= 0 && !floor_start)
      std::printf("start: image %d, camera orientation %.2f deg off\n", first_posed, start_error_deg);
    if (loop + 1 < loops) continue;
    // camera_height's map has its own origin and heading: the rigid motion that best
    // aligns the camera paths (as the rostest judges it), its up judged on its own.
    std::optional<Pose> truth_from_map;
    if (floor_start && est_map.size() >= 3) {
      truth_from_map = rigidAlign(est_map, truth_map);
      posed = static_cast<int>(est_map.size());
      for (size_t i = 0; i < est_map.size(); ++i) {
        const double err = cv::norm(truth_from_map->apply(est_map[i]) - truth_map[i]);
        pos_err_sum += err;
        pos_err_max = std::max(pos_err_max, err);
      }
      const cv::Vec3d up = truth_from_map->R * cv::Vec3d(0, 1, 0);
      double y_min = 1e9, y_max = -1e9;
      for (const cv::Vec3d& e : est_map) {
        y_min = std::min(y_min, e[1]);
        y_max = std::max(y_max, e[1]);
      }
      std::printf("camera_height: metric from image %d, map up tilted %.2f deg, camera height "
                  "in the map %.3f..%.3f m\n",
                  first_posed, std::acos(std::min(1.0, up[1])) * 180 / CV_PI, y_min, y_max);
    }
    std::printf(
        "camera: placed in %d/%d frames, position error mean %.3f m, max %.3f m, "
        "travelled %.2f m (max error %.1f %% of it)\n",
        posed, frames, posed ? pos_err_sum / posed : 0.0, pos_err_max, travelled,
        travelled > 0 ? 100 * pos_err_max / travelled : 0.0);
    // Tentative planes are judged apart: they tell a missed plane the map was still
    // confirming (too few views, a loose normal) from one it never held.
    std::vector<MapPlane> confirmed, tentative;
    for (const MapPlane& p : pipeline.map().planes())
      (p.confirmed(pipeline.map().params()) ? confirmed : tentative).push_back(p);
    std::vector<TruthPlane> judged = truth;
    const auto truthPlane = [&](int id) -> const TruthPlane* {  // null: no such id
      for (const TruthPlane& t : judged)
        if (t.id == id) return &t;
      return nullptr;
    };
    // Distances from the first camera position (the target frame's origin is 20 m up).
    const cv::Vec3d shift = truth_from_map ? cv::Vec3d(-truth_map.front()) : cv::Vec3d(0, 0, 0);
    // A map point in the frame the planes are judged in.
    const auto judgedFrame = [&](const cv::Vec3d& x) {
      return truth_from_map ? cv::Vec3d(truth_from_map->apply(x) + shift) : x;
    };
    if (truth_from_map) {
      for (std::vector<MapPlane>* planes : {&confirmed, &tentative})
        for (MapPlane& p : *planes) {
          p.normal = truth_from_map->R * p.normal;
          p.distance += p.normal.dot(truth_from_map->t) + p.normal.dot(shift);
          for (cv::Vec3d& v : p.polygon) v = truth_from_map->apply(v);
        }
      for (size_t t = 0; t < judged.size(); ++t) {
        judged[t].distance += judged[t].normal.dot(shift);
        judged[t].range_m = std::abs(judged[t].distance);
      }
    }
    const MapEvaluation eval = evaluateMap(confirmed, judged, truth_from_map ? 0.15 : 0.10);
    std::printf("planes (confirmed %zu of %zu):\n", confirmed.size(),
                pipeline.map().planes().size());
    for (size_t i = 0; i < confirmed.size(); ++i) {
      const MapPlane& p = confirmed[i];
      const PlaneMatch& m = eval.matches[i];
      const TruthPlane* matched = truthPlane(m.truth_id);
      const double relative =
          matched && matched->range_m > 0 ? m.distance_error_m / matched->range_m : 0.0;
      std::printf(
          "  plane %d: n=(%.3f %.3f %.3f) d=%.3f m, %zu points, %d obs -> %s "
          "(normal %.2f deg, distance %.3f m = %.1f %%)\n",
          p.id, p.normal[0], p.normal[1], p.normal[2], p.distance, p.points.size(), p.observations,
          m.truth_id >= 0 ? m.truth_name.c_str() : "NO MATCH", m.normal_error_deg,
          m.distance_error_m, 100 * relative);
      // What its points are: the true surface nearest to each (a mixture shows here).
      std::map<std::string, int> made_of;
      for (const auto& [id, entry] : p.points) {
        const cv::Vec3d x = scene.target.world_from_map.apply(
            truth_from_map ? truth_from_map->apply(entry.first) : entry.first);
        std::string best = "nothing";
        double best_d = 0.05;
        for (const ScenePlane& sp : scene.planes) {
          const double dist = std::abs(sp.normal().dot(x) - sp.distance());
          const cv::Vec3d local = x - sp.origin;
          const double a = local.dot(sp.u_axis), b = local.dot(sp.v_axis);
          if (a < -0.05 || b < -0.05 || a > sp.width_m + 0.05 || b > sp.height_m + 0.05) continue;
          if (dist < best_d) {
            best_d = dist;
            best = sp.name;
          }
        }
        ++made_of[best];
      }
      // The distance error where the plane is (its points projected onto it), not at the
      // map's origin, where a small normal error grows with the lever.
      double at_points = 0;
      if (matched && !p.points.empty()) {
        for (const auto& [id, entry] : p.points) {
          cv::Vec3d y = judgedFrame(entry.first);
          y -= (p.normal.dot(y) - p.distance) * p.normal;
          at_points += std::abs(matched->normal.dot(y) - matched->distance);
        }
        at_points /= static_cast<double>(p.points.size());
      }
      std::printf("    normal sigma %.2f deg, rms %.3f m, distance error at its points %.3f m; "
                  "points on:",
                  p.normal_sigma_deg, p.rms_m, at_points);
      for (const auto& [name, count] : made_of) std::printf(" %s %d", name.c_str(), count);
      std::printf("\n");
    }
    const MapEvaluation tentative_eval =
        evaluateMap(tentative, judged, truth_from_map ? 0.15 : 0.10);
    for (size_t i = 0; i < tentative.size(); ++i) {
      const MapPlane& p = tentative[i];
      const PlaneMatch& m = tentative_eval.matches[i];
      std::printf("  tentative plane %d: %zu points, %d views, normal sigma %.2f deg -> %s", p.id,
                  p.points.size(), p.observations, p.normal_sigma_deg,
                  m.truth_id >= 0 ? m.truth_name.c_str() : "NO MATCH");
      if (m.truth_id >= 0)
        std::printf(" (normal %.2f deg, distance %.3f m)", m.normal_error_deg, m.distance_error_m);
      std::printf("\n");
    }
    for (const TruthPlane& t : truth)
      if (t.max_image_share >= 0.02)
        std::printf("  truth %s: n=(%.2f %.2f %.2f) d=%.3f, max share %.0f %%\n", t.name.c_str(),
                    t.normal[0], t.normal[1], t.normal[2], t.distance, 100 * t.max_image_share);
    int false_planes = 0;
    for (const PlaneMatch& m : eval.matches) false_planes += m.truth_id < 0;
    std::printf("false planes %d\n", false_planes);
    for (int id : eval.missed) {
      const TruthPlane* missed = truthPlane(id);
      std::printf("  missed: true plane %d (%s)\n", id, missed ? missed->name.c_str() : "?");
    }
    std::printf("missed %zu, split %zu, worst normal %.2f deg, worst distance %.3f m\n",
                eval.missed.size(), eval.split.size(), eval.worst_normal_error_deg,
                eval.worst_distance_error_m);
    exit_code = eval.missed.empty() && eval.split.empty() ? 0 : 1;
    if (!top_view.empty()) {
      // Seen from above, world x to the right, y up the image, 80 px per metre.
      const double scale = 80, x0 = -room.width_m / 2 - 0.3, y1 = room.front_m + 0.3;
      cv::Mat view(static_cast<int>((room.front_m + room.back_m + 0.6) * scale),
                   static_cast<int>((room.width_m + 0.6) * scale), CV_8UC3, cv::Scalar(255, 255, 255));
      auto px = [&](const cv::Vec3d& x) {
        return cv::Point(static_cast<int>((x[0] - x0) * scale), static_cast<int>((y1 - x[1]) * scale));
      };
      for (const ScenePlane& sp : scene.planes) {
        if (sp.name == "ceiling") continue;
        const auto c = sp.corners();
        std::vector<cv::Point> poly;
        for (const auto& v : c) poly.push_back(px(v));
        if (std::abs(sp.normal()[2]) > 0.9) {
          if (sp.name != "floor") cv::fillConvexPoly(view, poly, cv::Scalar(225, 225, 225));
        } else {
          cv::polylines(view, poly, true, cv::Scalar(0, 0, 0), 2);
        }
      }
      for (const MapPlane& p : confirmed) {
        std::vector<cv::Point> poly;
        for (const auto& v : p.polygon) poly.push_back(px(scene.target.world_from_map.apply(v)));
        if (poly.size() >= 2) cv::polylines(view, poly, true, planeColour(p.id), 2);
      }
      for (size_t k = 1; k < path_truth.size(); ++k)
        cv::line(view, px(path_truth[k - 1]), px(path_truth[k]), cv::Scalar(120, 120, 120), 2);
      for (size_t k = 1; k < path_estimate.size(); ++k)
        cv::line(view, px(path_estimate[k - 1]), px(path_estimate[k]), cv::Scalar(0, 0, 255), 1);
      cv::imwrite(top_view, view);
    }
  }
  return exit_code;
}
