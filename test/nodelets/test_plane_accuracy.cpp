// Accuracy of the whole pipeline (tracker + plane nodelets, as launched for users) on a
// rendered 300-image sequence with ground truth: planes found, normal and distance
// errors, camera path error, no plane split in two. The bounds here are looser than the
// figures reported in README ("Plane map accuracy"); param ~trajectory picks the path.
// ~metric_source (target | odometry | camera_height) says where the metres come from:
// without the target the room is rendered with the target outside it; odometry is the
// true camera path on tf (odom -> camera_optical), stopped for 1 s mid-way (the pose
// must carry on from vision without a jump); camera_height's map has its own origin and
// heading, so it is judged after the rigid motion (no scale) that best aligns its camera
// path with the true one. auto: odometry on tf, no target: odometry must be chosen.
// ~target_type aruco: the start-up target is the ArUco marker (DICT_4X4_50, id 0, 0.15 m)
// where the sheet hangs, and both nodelets are told so.
// ~layout furnished: issue 18's room (furniture, real photographs from test/data/textures,
// plain painted walls), held to that bounds: normal < 2 deg, camera < 1 % of the
// path, distance error (the plane's offset at the map's origin as evaluateMap takes it, or
// at the first camera without a target, below)
// < 3 % of the camera's distance from the plane where it filled an image most (as
// run_pipeline reports it; ~max_distance_share); the
// planes covering >= 10 % of an image that are missed are printed (the sideboard front
// and the back wall, docs/mapping.md), those covering >= 15 % asserted.
// camera_height is held to the bounds: normal < 3 deg, distance < 5 % of the
// plane's distance from the first camera, camera < 5 % of the path (held on every
// image-noise seed that starts); its map up < 3 deg as every source's. The humanoid's
// camera_height map (an up-to-scale start whose floor is mapped only after the turn)
// meets the normal bound since the local bundle adjustment (worst 2.66 deg on
// this seed; 1.25 deg since the floor's gate is one for all landmarks; docs/mapping.md).
#include <geometry_msgs/TransformStamped.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <map>
#include <optional>
#include <set>

#include "../../src/sim/bag/ground_truth.h"
#include "../../src/sim/bag/sequence_writer.h"
#include "mono_plane_detection/PlaneArray.h"
#include "mono_plane_detection/eval/map_evaluation.h"
#include "mono_plane_detection/ros/map_frame.h"
#include "mono_plane_detection/ros/pose_msg.h"
#include "support/diagnostics_probe.h"
#include "support/test_timeouts.h"
#include "support/temp_path.h"

using namespace mono_plane_detection;

namespace {

std::string g_trajectory = "wheeled";
std::string g_metric_source = "target";
std::string g_target_type = "sheet";  // ~target_type: sheet | aruco (the start-up target)
// ~tracker_target: when given, the tracker's "start-up target" diagnostics at the end
// ("not searched": metric_source camera_height or odometry given to plane_detection.launch).
std::string g_tracker_target;
std::string g_layout = "bare";        // ~layout: bare | furnished (issue 18's room, real photos)
// ~max_distance_share (furnished only): a plane's distance error over the camera's distance
// from it where it filled an image most; the 3 % unless the .test file says why not.
double g_max_distance_share = 0.03;
// ~width: the rendered images' width in px (the height 3/4 of it, the field of view kept);
// with plane_detection.launch's resize_scale the pipeline sees them resized.
int g_width = 640;

TEST(PlaneAccuracy, RenderedSequence) {
  SequenceSpec spec;
  spec.trajectory.name = g_trajectory;
  spec.frames = 300;
  spec.render.noise_sigma = 2;
  spec.camera.size = cv::Size(g_width, g_width * 3 / 4);
  spec.camera.fx = spec.camera.fy = 525.0 * g_width / 640.0;
  spec.camera.cx = (spec.camera.size.width - 1) / 2.0;
  spec.camera.cy = (spec.camera.size.height - 1) / 2.0;
  const bool with_target = g_metric_source == "target";
  // auto with odometry on tf and no target: the odometry must be the one chosen.
  const std::string source = g_metric_source == "auto" ? "odometry" : g_metric_source;
  if (!with_target) spec.room.target_centre_height_m = 20;  // above the room: never seen
  spec.room.target_type = g_target_type;
  const bool furnished = g_layout == "furnished";
  if (furnished) {
    spec.room.layout = "furnished";
    spec.room.photos = loadTexturePhotos(std::string(TEST_DATA_DIR) + "/textures");
  }
  const std::string base = tempPath("accuracy_" + g_layout + "_" + g_trajectory + "_" +
                                    g_metric_source + "_" + g_target_type + "_" +
                                    std::to_string(g_width));
  writeSequence(spec, base + ".bag", base + ".yaml");
  const GroundTruth truth = loadGroundTruth(base + ".yaml");

  ros::NodeHandle nh;
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/camera/image_raw", 5);
  // Latched: a nodelet whose subscription joins late still gets the camera.
  ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 5, true);
  std::map<uint64_t, PlaneArrayConstPtr> planes;
  ros::Subscriber sub = nh.subscribe<PlaneArray>(
      "/camera/planes", 50,
      [&](const PlaneArrayConstPtr& m) { planes[m->header.stamp.toNSec()] = m; });
  int image_plane_messages = 0, with_image_planes = 0;
  ros::Subscriber image_sub = nh.subscribe<PlaneArray>(
      "/camera/image_planes", 50, [&](const PlaneArrayConstPtr& m) {
        ++image_plane_messages;
        with_image_planes += !m->planes.empty();
      });
  // Whether each nodelet has the camera, from its diagnostics.
  DiagnosticsProbe tracker_status(nh, "tracker: tracking");
  DiagnosticsProbe plane_status(nh, "plane_detector: planes");
  auto both_have_camera = [&] {
    const std::string model = plane_status.value("camera model");
    return tracker_status.value("camera_info") == "ok" && !model.empty() && model != "none";
  };
  tf2_ros::TransformBroadcaster odometry;
  spinUntil(
      [&] {
        return image_pub.getNumSubscribers() > 0 && info_pub.getNumSubscribers() > 0 &&
               sub.getNumPublishers() > 0;
      },
      30.0);
  ASSERT_GT(image_pub.getNumSubscribers(), 0u) << "the pipeline never subscribed";

  // Play the bag image by image, each after the previous one's planes arrived: the
  // result does not depend on this machine's load.
  rosbag::Bag bag(base + ".bag");
  rosbag::View view(bag, rosbag::TopicQuery({spec.image_topic, spec.info_topic}));
  PlaneArrayConstPtr last;
  std::vector<double> position_errors;
  std::vector<cv::Vec3d> est_path, true_path;  // camera positions, core frames
  double worst_step = 0;
  std::set<std::string> sources;
  std::optional<Pose> odom_from_truth;
  int images = 0;
  for (const rosbag::MessageInstance& m : view) {
    if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      info_pub.publish(info);
      // The first camera on its own, until both nodelets say they have it: camera_info
      // and tracks come on separate connections, so the first image's tracks could
      // reach the plane nodelet before it (a different start: 174 instead of 182 images
      // placed, once too few under load); the rest are ordered by the lock-step below.
      if (images == 0) {
        spinUntil(both_have_camera, 30.0);
        ASSERT_TRUE(both_have_camera())
            << "the nodelets never reported the camera in their diagnostics";
      }
      continue;
    }
    auto image = m.instantiate<sensor_msgs::Image>();
    if (!image) continue;
    const auto truth_pose = poseAt(truth, image->header.stamp.toSec());
    // Odometry: the true path in a z-up frame, missing for 1 s (a tf that stops).
    const bool tf_stopped = images >= 90 && images < 120;
    // The odometry starts where the robot starts (its origin at the first camera).
    if (truth_pose && !odom_from_truth) odom_from_truth = Pose{cv::Matx33d::eye(), -truth_pose->t};
    if (source == "odometry" && truth_pose && !tf_stopped) {
      geometry_msgs::TransformStamped tf;
      tf.header.stamp = image->header.stamp;
      tf.header.frame_id = "odom";
      tf.child_frame_id = image->header.frame_id;
      tf.transform = toTransformMsg(rosMapFromTarget() * *odom_from_truth * *truth_pose);
      odometry.sendTransform(tf);
      ros::Duration(0.01).sleep();  // on tf before the tracks of this image
    }
    image_pub.publish(image);
    ++images;
    const uint64_t key = image->header.stamp.toNSec();
    spinUntil([&] { return planes.count(key) > 0; }, 10.0);
    ASSERT_TRUE(planes.count(key)) << "no planes for image " << images;
    const PlaneArrayConstPtr previous = last;
    last = planes[key];
    if (last->metric) sources.insert(last->metric_source);
    if (last->metric && truth_pose) {
      cv::Vec3d est = targetFromRosMap(fromPoseMsg(last->camera_pose)).t;
      if (source == "odometry") est = odom_from_truth->inverse().apply(est);
      position_errors.push_back(cv::norm(est - truth_pose->t));
      est_path.push_back(est);
      true_path.push_back(truth_pose->t);
      if (previous && previous->metric)
        worst_step = std::max(worst_step, cv::norm(targetFromRosMap(fromPoseMsg(last->camera_pose)).t -
                                                   targetFromRosMap(fromPoseMsg(previous->camera_pose)).t));
    }
  }
  spinUntil([&] { return image_plane_messages >= images; }, 5.0);
  ASSERT_EQ(images, spec.frames);
  ASSERT_TRUE(last);

  std::vector<MapPlane> mapped = mapPlanesOf(*last);
  if (source != "target" && est_path.size() >= 3) {
    // The odometry's map is the odometry frame: known. camera_height's is the floor's:
    // the rigid motion that best aligns the camera paths.
    const Pose truth_from_map = source == "odometry"
                                    ? odom_from_truth->inverse()
                                    : rigidAlign(est_path, true_path);
    // The map's up against the truth's (y up in both cores' frames): the alignment
    // would hide a tilted map, so it is judged on its own.
    const cv::Vec3d up = truth_from_map.R * cv::Vec3d(0, 1, 0);
    const double tilt_deg = std::acos(std::min(1.0, up[1])) * 180 / CV_PI;
    std::printf("  map up tilted %.2f deg\n", tilt_deg);
    // camera_height: the check sets the map's up from its floor landmarks (measured
    // 3.1 deg before the local bundle adjustment, when the map drifted in the turn; since
    // then 0.22 wheeled, 0.96 humanoid).
    EXPECT_LT(tilt_deg, 3.0);
    for (MapPlane& p : mapped) {
      p.normal = truth_from_map.R * p.normal;
      p.distance += p.normal.dot(truth_from_map.t);
      for (cv::Vec3d& v : p.polygon) v = truth_from_map.apply(v);
    }
    if (source == "camera_height")
      for (size_t i = 0; i < est_path.size(); ++i)
        position_errors[i] = cv::norm(truth_from_map.apply(est_path[i]) - true_path[i]);
  }
  std::vector<TruthPlane> truth_planes = truth.planes;
  if (!with_target && !true_path.empty()) {
    // Without the target its frame (the truth's) has its origin 20 m up, where a plane
    // distance error mostly measures the normal's error times 20 m: judge distances from
    // the first camera position instead (a pure translation of both).
    const cv::Vec3d shift = -true_path.front();
    for (MapPlane& p : mapped) p.distance += p.normal.dot(shift);
    for (TruthPlane& p : truth_planes) p.distance += p.normal.dot(shift);
  }
  const MapEvaluation e = evaluateMap(mapped, truth_planes, 0.15);
  std::printf("%s, metric source %s: %zu planes\n", g_trajectory.c_str(),
              g_metric_source.c_str(), mapped.size());
  for (size_t i = 0; i < mapped.size(); ++i)
    std::printf("  plane %d -> %s: normal %.2f deg, distance %.3f m (%d observations)\n",
                mapped[i].id, e.matches[i].truth_name.c_str(), e.matches[i].normal_error_deg,
                e.matches[i].distance_error_m, mapped[i].observations);

  double worst = 0;
  for (double err : position_errors) worst = std::max(worst, err);
  std::printf("  camera placed in %zu images, worst %.3f m over %.2f m, worst step %.3f m\n",
              position_errors.size(), worst, truth.travelled_m, worst_step);
  std::printf("  image_planes: %d messages, %d with planes\n", image_plane_messages,
              with_image_planes);
  if (furnished) {
    // Issue 18's targets: planes covering >= 10 % of an image missed, printed (the
    // sideboard front and back wall are, docs/mapping.md); each mapped plane's distance
    // error relative to the camera's distance from it where it filled an image most.
    const MapEvaluation at10 = evaluateMap(mapped, truth_planes, 0.10);
    for (int id : at10.missed)
      for (const TruthPlane& t : truth_planes)
        if (t.id == id)
          std::printf("  missed %s (up to %.0f %% of an image)\n", t.name.c_str(),
                      100 * t.max_image_share);
    for (size_t i = 0; i < mapped.size(); ++i)
      for (const TruthPlane& t : truth_planes)
        if (t.id == e.matches[i].truth_id) {
          // A plane mapped is one seen: it has a range (0 would divide below).
          ASSERT_GT(t.range_m, 0.0) << t.name << " never in view";
          const double relative = e.matches[i].distance_error_m / t.range_m;
          std::printf("  plane %d: distance error %.1f %% of %.2f m\n", mapped[i].id,
                      100 * relative, t.range_m);
          EXPECT_LT(relative, g_max_distance_share) << t.name;
        }
    EXPECT_LT(e.worst_normal_error_deg, 2.0);  // the bound
    EXPECT_LT(worst, 0.01 * truth.travelled_m);
  }

  if (!g_tracker_target.empty()) {
    ASSERT_TRUE(tracker_status.waitFresh());
    EXPECT_EQ(tracker_status.value("start-up target"), g_tracker_target);
  }

  // Image-space planes every image, whatever the metric start does.
  EXPECT_EQ(image_plane_messages, images);
  EXPECT_GE(with_image_planes, images * 9 / 10);
  EXPECT_EQ(sources, std::set<std::string>{source});
  EXPECT_LT(worst_step, 0.1);  // 0.01 m per image: a jump is a failure

  EXPECT_TRUE(e.missed.empty()) << e.missed.size() << " plane(s) covering >= 15 % missed";
  EXPECT_TRUE(e.split.empty()) << "a true plane has two map planes";
  for (const PlaneMatch& m : e.matches) EXPECT_GE(m.truth_id, 0) << "plane " << m.map_id;
  if (source != "camera_height") {
    EXPECT_LT(e.worst_normal_error_deg, 5.0);  // camera_height: below
  }
  EXPECT_LT(e.worst_distance_error_m, 0.15);
  // camera_height: nothing is given out before the start's check (wheeled: one camera
  // height of motion after the start, 169 images placed; humanoid: once its floor is
  // mapped after the turn, 75 images placed).
  const bool humanoid_height = source == "camera_height" && g_trajectory == "humanoid";
  EXPECT_GE(position_errors.size(), humanoid_height             ? 60u
                                    : source == "camera_height" ? 150u
                                                                : 200u);
  EXPECT_LT(worst, 0.08 * truth.travelled_m);
  if (source == "camera_height") {
    // The bounds: camera < 5 % of the path, normal < 3 deg, distance < 5 %.
    // Measured after the floor check (wheeled): camera 0.4 %, worst normal 1.4 deg (front
    // wall), worst distance 2.8 % (front wall); on the four other image-noise seeds
    // within 0.9 %, 2.1 deg and 3.5 % (docs/mapping.md); with the tracker's corner spread
    // (spread_grid_columns) 1.9 deg (left wall), 0.8 %. Humanoid (the check's camera set
    // from the floor landmarks' anchors when the drifted path finds no floor): camera
    // 0.1 %, normals 2.0 (front wall), 3.45 (left wall), 2.05 deg (floor), distances 3.4 %
    // (front wall), 2.6 %, 2.4 %; image-noise seeds 1-4 within 3.23 deg and 3.1 %
    // (run_pipeline). The up-to-scale map drifted between the left wall, mapped before
    // the turn, and the floor after it: the 3 deg was missed (held to 4 deg).
    // With the local bundle adjustment (pose/bundle_window): wheeled left wall 0.79 deg,
    // 0.9 %; humanoid normals 0.78 (front wall), 1.85 (left wall), 2.66 deg (floor),
    // distances 0.5 / 0.4 / 0.4 %; image-noise seeds 1-4 within 1.61 deg and 2.4 %
    // (run_pipeline). Seed 0's floor moves by about a degree with small solver changes.
    // With one gate for all floor landmarks (fitFloorToLandmarks): humanoid 0.20 / 0.46 /
    // 1.25 deg, 0.6 / 0.2 / 0.1 %, map up 0.96 deg; wheeled unchanged (left wall 0.98 deg,
    // worst distance 1.0 %). With F by USAC in the plane core: humanoid floor 1.33 deg /
    // 0.4 %, wheeled left wall 1.04 deg.
    EXPECT_LT(worst, 0.05 * truth.travelled_m);
    EXPECT_LT(e.worst_normal_error_deg, 3.0);
    for (size_t i = 0; i < mapped.size(); ++i)
      for (const TruthPlane& t : truth_planes)
        if (t.id == e.matches[i].truth_id) {
          const double relative = e.matches[i].distance_error_m / std::abs(t.distance);
          std::printf("  plane %d: distance error %.1f %% of %.2f m\n", mapped[i].id,
                      100 * relative, std::abs(t.distance));
          EXPECT_LT(relative, 0.05) << t.name;
        }
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_plane_accuracy");
  ros::NodeHandle pnh("~");
  pnh.param<std::string>("trajectory", g_trajectory, g_trajectory);
  pnh.param<std::string>("metric_source", g_metric_source, g_metric_source);
  pnh.param<std::string>("target_type", g_target_type, g_target_type);
  pnh.param<std::string>("layout", g_layout, g_layout);
  pnh.param("width", g_width, g_width);
  pnh.param<std::string>("tracker_target", g_tracker_target, g_tracker_target);
  pnh.param("max_distance_share", g_max_distance_share, g_max_distance_share);
  return RUN_ALL_TESTS();
}
