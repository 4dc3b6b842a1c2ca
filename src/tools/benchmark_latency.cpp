// End-to-end latency of the running pipeline: images of a bag are published at their
// rate with the current time as stamp; the time from that stamp to the arrival of the
// plane message with the same stamp is measured (through the nodelet manager, both
// nodelets, two ROS hops). Prints mean, p50, p95 and max. A measurement, not a test.
//   rosrun mono_plane_detection benchmark_latency --bag seq.bag [--rate 30]
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>

#include "cli_args.h"
#include "mono_plane_detection/PlaneArray.h"
#include "mono_plane_detection/Tracks.h"

using namespace mono_plane_detection;

int main(int argc, char** argv) {
  ros::init(argc, argv, "benchmark_latency");
  std::string bag_path;
  double rate = 30;
  cli::Parser cli(
      "benchmark_latency", "--bag FILE.bag [options]",
      "  End-to-end latency of a running pipeline: the bag's images are published at RATE\n"
      "  with the current time as stamp; prints the time until the tracks and planes with\n"
      "  that stamp arrive (mean, p50, p95, max). A measurement, never pass/fail.",
      "exit codes: 0 measured, 1 no plane message arrived, 2 bad usage or unreadable bag\n");
  cli.text("bag", &bag_path, "bag with /camera/image_raw and /camera/camera_info (required)",
           "FILE.bag")
      .number("rate", &rate, 0.1, 1000.0, "images published per second", "HZ");
  if (const auto code = cli.parse(argc, argv)) return *code;
  if (bag_path.empty()) return cli.fail("--bag FILE.bag is required");
  rosbag::Bag bag;
  try {
    bag.open(bag_path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    return cli.fail("cannot read " + bag_path + ": " + e.what());
  }
  ros::NodeHandle nh;
  ros::Publisher image_pub = nh.advertise<sensor_msgs::Image>("/camera/image_raw", 5);
  ros::Publisher info_pub = nh.advertise<sensor_msgs::CameraInfo>("/camera/camera_info", 5);
  std::mutex mutex;
  std::map<ros::Time, double> plane_latency_ms, tracks_latency_ms;
  ros::Subscriber planes =
      nh.subscribe<PlaneArray>("/camera/planes", 50, [&](const PlaneArrayConstPtr& m) {
        std::lock_guard<std::mutex> lock(mutex);
        plane_latency_ms[m->header.stamp] = (ros::Time::now() - m->header.stamp).toSec() * 1e3;
      });
  ros::Subscriber tracks = nh.subscribe<Tracks>("/camera/tracks", 50, [&](const TracksConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    tracks_latency_ms[m->header.stamp] = (ros::Time::now() - m->header.stamp).toSec() * 1e3;
  });
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const ros::WallTime ready = ros::WallTime::now() + ros::WallDuration(30);
  while (ros::ok() && (image_pub.getNumSubscribers() == 0 || planes.getNumPublishers() == 0) &&
         ros::WallTime::now() < ready)
    ros::WallDuration(0.05).sleep();
  ros::WallDuration(1.0).sleep();

  rosbag::View view(bag, rosbag::TopicQuery(
                             std::vector<std::string>{"/camera/image_raw", "/camera/camera_info"}));
  ros::WallRate pace(rate);
  int sent = 0;
  for (const rosbag::MessageInstance& m : view) {
    if (!ros::ok()) break;
    const ros::Time now = ros::Time::now();
    if (auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      sensor_msgs::CameraInfo copy = *info;
      copy.header.stamp = now;
      info_pub.publish(copy);
    } else if (auto image = m.instantiate<sensor_msgs::Image>()) {
      sensor_msgs::ImagePtr copy(new sensor_msgs::Image(*image));
      copy->header.stamp = now;
      image_pub.publish(copy);
      ++sent;
      pace.sleep();
    }
  }
  ros::WallDuration(2.0).sleep();
  auto report = [&](const char* what, const std::map<ros::Time, double>& latencies) {
    std::vector<double> v;
    for (const auto& [stamp, ms] : latencies) v.push_back(ms);
    if (v.empty()) {
      std::printf("%-28s no messages\n", what);
      return;
    }
    std::sort(v.begin(), v.end());
    double mean = 0;
    for (double x : v) mean += x / v.size();
    std::printf("%-28s %4zu of %d images: mean %.1f ms, p50 %.1f, p95 %.1f, max %.1f\n", what,
                v.size(), sent, mean, v[v.size() / 2],
                v[std::min(v.size() - 1, v.size() * 95 / 100)], v.back());
  };
  std::lock_guard<std::mutex> lock(mutex);
  std::printf("End-to-end latency at %.0f images/s (image stamp -> message received):\n", rate);
  report("image -> tracks", tracks_latency_ms);
  report("image -> planes", plane_latency_ms);
  return plane_latency_ms.empty() ? 1 : 0;
}
