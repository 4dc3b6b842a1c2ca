// writeSequence: what the bag and the ground-truth YAML hold, read back.
#include <gtest/gtest.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>
#include <yaml-cpp/yaml.h>

#include <fstream>
#include <iterator>

#include "../../src/sim/bag/ground_truth.h"
#include "../../src/sim/bag/sequence_writer.h"
#include "support/temp_path.h"

using namespace mono_plane_detection;

namespace {

std::string temp(const std::string& name) { return tempPath(name); }

std::string bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

SequenceSpec shortSpec() {
  SequenceSpec spec;
  spec.frames = 10;
  spec.trajectory.name = "humanoid";
  spec.render.noise_sigma = 2;
  return spec;
}

}  // namespace

TEST(SequenceWriter, BagHoldsImagesInfoAndGroundTruthAtTheRightStamps) {
  const SequenceSpec spec = shortSpec();
  const SequenceReport report = writeSequence(spec, temp("seq.bag"), temp("seq.yaml"));
  EXPECT_EQ(report.frames, 10);
  EXPECT_GT(report.render_ms_mean, 0.0);

  rosbag::Bag bag(temp("seq.bag"));
  int images = 0, infos = 0, tfs = 0;
  const IndoorScene scene = makeRoom(spec.room);
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (auto image = m.instantiate<sensor_msgs::Image>()) {
      EXPECT_EQ(m.getTopic(), "/camera/image_raw");
      EXPECT_NEAR(image->header.stamp.toSec(), 1000.0 + images / 30.0, 1e-6);
      EXPECT_EQ(image->header.frame_id, "camera_optical");
      EXPECT_EQ(image->encoding, "mono8");
      EXPECT_EQ(image->width, 640u);
      EXPECT_EQ(image->height, 480u);
      EXPECT_EQ(image->data.size(), 640u * 480u);
      ++images;
    } else if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      EXPECT_EQ(info->K[0], 525.0);
      EXPECT_EQ(info->K[2], 319.5);
      EXPECT_EQ(info->width, 640u);
      EXPECT_NEAR(info->header.stamp.toSec(), 1000.0 + infos / 30.0, 1e-6);
      ++infos;
    } else if (auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      ASSERT_EQ(tf->transforms.size(), 1u);
      const auto& t = tf->transforms[0];
      EXPECT_EQ(t.header.frame_id, "map");
      EXPECT_EQ(t.child_frame_id, "camera_gt");
      const Pose gt = groundTruthPose(spec, scene, tfs);
      EXPECT_NEAR(t.transform.translation.x, gt.t[0], 1e-12);
      EXPECT_NEAR(t.transform.translation.z, gt.t[2], 1e-12);
      // The quaternion rotates the optical axis as the pose does.
      const auto& q = t.transform.rotation;
      const double zx = 2 * (q.x * q.z + q.w * q.y), zy = 2 * (q.y * q.z - q.w * q.x),
                   zz = 1 - 2 * (q.x * q.x + q.y * q.y);
      EXPECT_NEAR(zx, gt.R(0, 2), 1e-9);
      EXPECT_NEAR(zy, gt.R(1, 2), 1e-9);
      EXPECT_NEAR(zz, gt.R(2, 2), 1e-9);
      ++tfs;
    }
  }
  EXPECT_EQ(images, 10);
  EXPECT_EQ(infos, 10);
  EXPECT_EQ(tfs, 10);
}

TEST(SequenceWriter, GroundTruthYamlDescribesTheScene) {
  const SequenceSpec spec = shortSpec();
  writeSequence(spec, temp("gt.bag"), temp("gt.yaml"));
  const YAML::Node gt = YAML::LoadFile(temp("gt.yaml"));
  EXPECT_EQ(gt["trajectory"].as<std::string>(), "humanoid");
  EXPECT_EQ(gt["frames"].as<int>(), 10);
  EXPECT_EQ(gt["camera"]["fx"].as<double>(), 525.0);
  ASSERT_EQ(gt["planes"].size(), 6u);
  for (const auto& plane : gt["planes"]) {
    const auto n = plane["normal"].as<std::vector<double>>();
    EXPECT_NEAR(std::hypot(n[0], n[1], n[2]), 1.0, 1e-12);
    ASSERT_GE(plane["polygon_map"].size(), 3u);
    for (const auto& corner : plane["polygon_map"]) {
      const auto c = corner.as<std::vector<double>>();
      EXPECT_NEAR(n[0] * c[0] + n[1] * c[1] + n[2] * c[2], plane["distance_m"].as<double>(), 1e-9);
    }
  }
  // The map frame is the target's: its corners at z = 0, the front wall through the origin.
  ASSERT_EQ(gt["target"]["corners_map"].size(), 4u);
  for (const auto& corner : gt["target"]["corners_map"])
    EXPECT_NEAR(corner[2].as<double>(), 0.0, 1e-12);
  EXPECT_EQ(gt["planes"][1]["name"].as<std::string>(), "front_wall");
  EXPECT_NEAR(gt["planes"][1]["distance_m"].as<double>(), 0.0, 1e-12);
  EXPECT_EQ(gt["camera_gt_in_map"].size(), 10u);
  // The robot starts 2 m in front of the target, at the target's height (0.8 + 0.4 m humanoid).
  const auto start = gt["camera_gt_in_map"][0]["position"].as<std::vector<double>>();
  EXPECT_NEAR(start[2], 2.0, 1e-9);
  EXPECT_NEAR(start[1], 0.4, 0.03);
  // Each plane in view: the camera's distance from it where it covered the most of an
  // image (the reference of relative distance errors), read back by loadGroundTruth.
  const GroundTruth truth = loadGroundTruth(temp("gt.yaml"));
  ASSERT_EQ(truth.planes.size(), 6u);
  for (const TruthPlane& t : truth.planes) {
    if (t.max_image_share <= 0) continue;
    double nearest = 1e9, farthest = 0;  // over the images: the range is one of them
    for (const Pose& pose : truth.poses) {
      const double d = std::abs(t.normal.dot(pose.t) - t.distance);
      nearest = std::min(nearest, d);
      farthest = std::max(farthest, d);
    }
    EXPECT_GE(t.range_m, nearest - 1e-9) << t.name;
    EXPECT_LE(t.range_m, farthest + 1e-9) << t.name;
  }
  EXPECT_NEAR(truth.planes[1].range_m, 2.0, 0.1);  // the front wall, seen from the start
}

TEST(SequenceWriter, SameSeedSameBytes) {
  SequenceSpec spec = shortSpec();
  spec.frames = 4;
  writeSequence(spec, temp("a.bag"), temp("a.yaml"));
  writeSequence(spec, temp("b.bag"), temp("b.yaml"));
  EXPECT_EQ(bytes(temp("a.bag")), bytes(temp("b.bag")));
  EXPECT_EQ(bytes(temp("a.yaml")), bytes(temp("b.yaml")));
  spec.room.seed = 2;
  writeSequence(spec, temp("c.bag"), temp("c.yaml"));
  EXPECT_NE(bytes(temp("a.bag")), bytes(temp("c.bag")));
}

TEST(SequenceWriter, ExposureSwingBrightensAndDarkens) {
  SequenceSpec spec;
  spec.frames = 91;  // 3 s at 30 fps: the gain peaks at 1 s and bottoms at 3 s
  spec.trajectory.name = "rotation";
  spec.trajectory.rotation_amplitude_deg = 0;  // a still camera: only the exposure changes
  spec.exposure_swing = 0.3;
  writeSequence(spec, temp("exp.bag"), temp("exp.yaml"));
  rosbag::Bag bag(temp("exp.bag"));
  std::vector<double> means;
  for (const auto& m : rosbag::View(bag, rosbag::TopicQuery("/camera/image_raw"))) {
    const auto image = m.instantiate<sensor_msgs::Image>();
    double sum = 0;
    for (uint8_t v : image->data) sum += v;
    means.push_back(sum / image->data.size());
  }
  ASSERT_EQ(means.size(), 91u);
  EXPECT_NEAR(means[30] / means[0], 1.3, 0.03);  // saturation at 255 keeps it a little under
  EXPECT_NEAR(means[90] / means[0], 0.7, 0.02);
}

TEST(SequenceWriter, ColourEncodingAndBadSpecs) {
  SequenceSpec spec = shortSpec();
  spec.frames = 2;
  spec.encoding = "bgr8";
  writeSequence(spec, temp("bgr.bag"), temp("bgr.yaml"));
  rosbag::Bag bag(temp("bgr.bag"));
  int images = 0;
  for (const auto& m : rosbag::View(bag, rosbag::TopicQuery("/camera/image_raw"))) {
    const auto image = m.instantiate<sensor_msgs::Image>();
    ASSERT_TRUE(image);
    ++images;
    EXPECT_EQ(image->encoding, "bgr8");
    EXPECT_EQ(image->step, 640u * 3u);
  }
  EXPECT_EQ(images, 2);
  spec.encoding = "rgb16";
  EXPECT_THROW(writeSequence(spec, temp("x.bag"), temp("x.yaml")), std::runtime_error);
  spec = shortSpec();
  spec.trajectory.name = "flying";
  EXPECT_THROW(writeSequence(spec, temp("x.bag"), temp("x.yaml")), std::runtime_error);
  spec = shortSpec();
  EXPECT_THROW(writeSequence(spec, "/no/such/folder/x.bag", temp("x.yaml")), std::runtime_error);
}
