// Accuracy of the whole pipeline (tracker + plane nodelets, as launched for users) on a
// rendered 300-image sequence with ground truth: planes found, normal and distance
// errors, camera path error, no plane split in two. The bounds here are looser than the
// figures reported in README ("Plane map accuracy"); param ~trajectory picks the path.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <map>

#include "../../src/sim/bag/ground_truth.h"
#include "../../src/sim/bag/sequence_writer.h"
#include "mono_plane_detection/PlaneArray.h"
#include "mono_plane_detection/ros/map_frame.h"
#include "support/test_timeouts.h"
#include "support/temp_path.h"

using namespace mono_plane_detection;

namespace {

std::string g_trajectory = "wheeled";

TEST(PlaneAccuracy, RenderedSequence) {
  SequenceSpec spec;
  spec.trajectory.name = g_trajectory;
  spec.frames = 300;
  spec.render.noise_sigma = 2;
  const std::string base = tempPath("accuracy_" + g_trajectory);
  writeSequence(spec, base + ".bag", base + ".yaml");
  const GroundTruth truth = loadGroundTruth(base + ".yaml");

  ros::NodeHandle nh;
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/camera/image_raw", 5);
  ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 5);
  std::map<uint64_t, PlaneArrayConstPtr> planes;
  ros::Subscriber sub = nh.subscribe<PlaneArray>(
      "/camera/planes", 50,
      [&](const PlaneArrayConstPtr& m) { planes[m->header.stamp.toNSec()] = m; });
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
  int images = 0;
  for (const rosbag::MessageInstance& m : view) {
    if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      info_pub.publish(info);
      continue;
    }
    auto image = m.instantiate<sensor_msgs::Image>();
    if (!image) continue;
    image_pub.publish(image);
    ++images;
    const uint64_t key = image->header.stamp.toNSec();
    spinUntil([&] { return planes.count(key) > 0; }, 10.0);
    ASSERT_TRUE(planes.count(key)) << "no planes for image " << images;
    last = planes[key];
    if (last->metric)
      if (const auto t = poseAt(truth, image->header.stamp.toSec()))
        position_errors.push_back(cv::norm(targetFromRosMap(fromPoseMsg(last->camera_pose)).t - t->t));
  }
  ASSERT_EQ(images, spec.frames);
  ASSERT_TRUE(last);

  const std::vector<MapPlane> mapped = mapPlanesOf(*last);
  const MapEvaluation e = evaluateMap(mapped, truth.planes, 0.15);
  std::printf("%s: %zu planes\n", g_trajectory.c_str(), mapped.size());
  for (size_t i = 0; i < mapped.size(); ++i)
    std::printf("  plane %d -> %s: normal %.2f deg, distance %.3f m\n", mapped[i].id,
                e.matches[i].truth_name.c_str(), e.matches[i].normal_error_deg,
                e.matches[i].distance_error_m);
  double worst = 0;
  for (double err : position_errors) worst = std::max(worst, err);
  std::printf("  camera placed in %zu images, worst %.3f m over %.2f m\n", position_errors.size(),
              worst, truth.travelled_m);

  EXPECT_TRUE(e.missed.empty()) << e.missed.size() << " plane(s) covering >= 15 % missed";
  EXPECT_TRUE(e.split.empty()) << "a true plane has two map planes";
  for (const PlaneMatch& m : e.matches) EXPECT_GE(m.truth_id, 0) << "plane " << m.map_id;
  EXPECT_LT(e.worst_normal_error_deg, 5.0);
  EXPECT_LT(e.worst_distance_error_m, 0.15);
  EXPECT_GE(position_errors.size(), 200u);
  EXPECT_LT(worst, 0.08 * truth.travelled_m);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_plane_accuracy");
  ros::NodeHandle pnh("~");
  pnh.param<std::string>("trajectory", g_trajectory, g_trajectory);
  return RUN_ALL_TESTS();
}
