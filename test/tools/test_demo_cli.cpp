// `make demo` fails fast with a clear message (issue 14 item 9): scripts/demo.sh on a
// missing bag, a file that is not a bag, a bag without the camera's image topic, an
// unknown profile; demo_report gives up when no message arrives. Each of these hung for
// ever before (the error only in pipeline.log, the report waiting for a first message).
// Run by rostest: the demo_report case needs the master rostest starts.
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

#include "mono_plane_detection/PlaneArray.h"

#include "support/run_program.h"

using namespace mono_plane_detection;

namespace {

std::string temp(const std::string& name) { return tempPath(name); }

// demo.sh with RESULTS PROFILE FRAMES RVIZ [BAG]; `timeout` turns a hang into exit 124.
ProgramRun demo(const std::string& profile, const std::string& bag,
                const std::string& env = "") {
  return runProgram("PATH=/usr/bin:$PATH " + env + " timeout 60 bash " DEMO_SCRIPT_PATH,
                    temp("demo_results") + " " + profile + " 5 false " + bag);
}

// A bag with an image and its camera_info under namespace `camera`.
std::string writeBag(const std::string& name, const std::string& camera) {
  const std::string path = temp(name);
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  sensor_msgs::Image image;
  image.header.stamp = ros::Time(1000);
  image.width = image.height = 16;
  image.encoding = "mono8";
  image.step = 16;
  image.data.assign(256, 0);
  sensor_msgs::CameraInfo info;
  info.header.stamp = image.header.stamp;
  bag.write("/" + camera + "/image_raw", image.header.stamp, image);
  bag.write("/" + camera + "/camera_info", info.header.stamp, info);
  bag.close();
  return path;
}

}  // namespace

TEST(DemoCli, MissingBagFailsFast) {
  const ProgramRun r = demo("humanoid", "/no/such/file.bag");
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("no bag file /no/such/file.bag"), std::string::npos) << r.err;
}

TEST(DemoCli, AFileThatIsNotABagFailsFast) {
  const std::string path = writeTempFile("not_a.bag", "hello\n");
  const ProgramRun r = demo("humanoid", path);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("cannot read the bag"), std::string::npos) << r.err;
}

TEST(DemoCli, ABagWithoutTheImageTopicFailsFastAndNamesTheChoice) {
  const std::string bag = writeBag("other_camera.bag", "front");
  ProgramRun r = demo("humanoid", bag);
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("no topic /camera/image_raw"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/front/image_raw"), std::string::npos) << r.err;  // what it has
  EXPECT_NE(r.err.find("CAMERA="), std::string::npos) << r.err;
  // Naming another image topic of the right camera: still refused, by that name.
  r = demo("humanoid", bag, "DEMO_CAMERA=front DEMO_IMAGE=image_rect");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("no topic /front/image_rect"), std::string::npos) << r.err;
}

TEST(DemoCli, UnknownProfileFailsFastAndListsTheProfiles) {
  const ProgramRun r = demo("rotation", "");
  EXPECT_EQ(r.code, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("unknown profile 'rotation'"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("humanoid"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("wheeled"), std::string::npos) << r.err;
}

TEST(DemoCli, ReportGivesUpWhenNoMessageArrives) {
  const auto start = std::chrono::steady_clock::now();
  const ProgramRun r = runProgram(std::string("timeout 60 ") + DEMO_REPORT_PATH,
                                  "planes:=/nobody/planes --first-message-timeout 2 --out " +
                                      temp("report_results"));
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("no message on /nobody/planes within 2 s"), std::string::npos) << r.err;
  EXPECT_LT(seconds, 30);  // not a timing assertion: a hang would be 60 s (timeout)
}

// A pipeline that runs but never starts the map (a bag without the start-up target, no
// odometry): the report says so and what would start it, and counts the image planes.
TEST(DemoCli, ReportSaysWhyTheMapIsEmpty) {
  ros::NodeHandle nh;
  ros::Publisher planes = nh.advertise<PlaneArray>("/no_start/planes", 10);
  ros::Publisher image_planes = nh.advertise<PlaneArray>("/no_start/image_planes", 10);
  std::atomic<bool> stop{false};
  std::thread publisher([&] {
    PlaneArray map, image;
    map.status = image.status = "waiting for target";
    image.planes.resize(1);
    // Both of the report's subscriptions connected before the first plane message counts
    // towards its --frames (else a late image_planes connection would count nothing).
    while (!stop && (planes.getNumSubscribers() == 0 || image_planes.getNumSubscribers() == 0))
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    while (!stop) {
      map.header.stamp = image.header.stamp = ros::Time::now();
      image_planes.publish(image);
      planes.publish(map);
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  const ProgramRun r = runProgram(std::string("timeout 60 ") + DEMO_REPORT_PATH,
                                  "planes:=/no_start/planes image_planes:=/no_start/image_planes "
                                  "--frames 5 --out " + temp("no_start_results"));
  stop = true;
  publisher.join();
  EXPECT_EQ(r.code, 1) << r.out << r.err;  // no map plane
  EXPECT_NE(r.out.find("no metric start (waiting for target): the map needs the start-up target"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("pose/metric_source camera_height with pose/camera_height_m"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("images had planes in image space"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("image planes: 0 of"), std::string::npos) << r.out;
}

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_demo_cli");
  return RUN_ALL_TESTS();
}
