// End-to-end latency of the running pipeline: images of a bag are published at their
// rate with the current time as stamp; the time from that stamp to the arrival of the
// plane message with the same stamp is measured (through the nodelet manager, both
// nodelets, two ROS hops). Prints mean, p50, p95 and max; with --pid, the resident
// memory of that process (the manager) along the run; with --plot, both against time.
// A measurement, not a test.
//   rosrun mono_plane_detection benchmark_latency --bag seq.bag [--rate 30] [--pid N]
//     [--plot latency.png]
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "cli_args.h"
#include "mono_plane_detection/PlaneArray.h"
#include "mono_plane_detection/Tracks.h"

using namespace mono_plane_detection;

namespace {

// Resident memory of a process in MiB (VmRSS of /proc/PID/status), -1 when unreadable.
double residentMiB(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      double kb = 0;
      status >> kb;
      return kb / 1024.0;
    }
    status.ignore(4096, '\n');
  }
  return -1;
}

// Two panels against the image index: latency (tracks, planes) and resident memory.
void plot(const std::vector<double>& tracks_ms, const std::vector<double>& planes_ms,
          const std::vector<double>& rss, double rate, const std::string& path) {
  const int w = 720, ph = 240, left = 55, right = 15;
  cv::Mat img(2 * ph + 30, w, CV_8UC3, cv::Scalar::all(255));
  auto panel = [&](int y0, const std::vector<std::pair<std::vector<double>, cv::Scalar>>& series,
                   const std::string& title, const char* unit) {
    double hi = 1e-9;
    size_t n = 1;
    for (const auto& [v, c] : series) {
      for (double x : v) hi = std::max(hi, x);
      n = std::max(n, v.size());
    }
    hi *= 1.1;
    auto at = [&](size_t i, double y) {
      return cv::Point(left + static_cast<int>((w - left - right) * i / std::max<size_t>(1, n - 1)),
                       y0 + ph - 30 - static_cast<int>((ph - 60) * y / hi));
    };
    cv::line(img, at(0, 0), at(n - 1, 0), cv::Scalar::all(0));
    cv::line(img, at(0, 0), at(0, hi), cv::Scalar::all(0));
    for (int k = 0; k <= 4; ++k)
      cv::putText(img, cv::format("%.0f", hi * k / 4), at(0, hi * k / 4) + cv::Point(-45, 4),
                  cv::FONT_HERSHEY_SIMPLEX, 0.35, cv::Scalar::all(0));
    cv::putText(img, title + cv::format(" (%s; x: image, %.0f per s)", unit, rate),
                {left, y0 + 20}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar::all(0), 1,
                cv::LINE_AA);
    for (const auto& [v, colour] : series)
      for (size_t i = 1; i < v.size(); ++i)
        if (v[i - 1] >= 0 && v[i] >= 0) cv::line(img, at(i - 1, v[i - 1]), at(i, v[i]), colour, 1, cv::LINE_AA);
  };
  panel(0, {{tracks_ms, {200, 0, 0}}, {planes_ms, {0, 0, 200}}},
        "latency, image stamp -> tracks (blue), -> planes (red)", "ms");
  panel(ph + 30, {{rss, {0, 120, 0}}}, "resident memory of the manager", "MiB");
  cv::imwrite(path, img);
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "benchmark_latency");
  std::string bag_path, plot_path;
  double rate = 30;
  int pid = 0;
  cli::Parser cli(
      "benchmark_latency", "--bag FILE.bag [options]",
      "  End-to-end latency of a running pipeline: the bag's images are published at RATE\n"
      "  with the current time as stamp; prints the time until the tracks and planes with\n"
      "  that stamp arrive (mean, p50, p95, max). A measurement, never pass/fail.",
      "exit codes: 0 measured, 1 no plane message arrived, 2 bad usage or unreadable bag\n");
  cli.text("bag", &bag_path, "bag with /camera/image_raw and /camera/camera_info (required)",
           "FILE.bag")
      .number("rate", &rate, 0.1, 1000.0, "images published per second", "HZ")
      .integer("pid", &pid, 0, 1 << 30, "process whose resident memory to follow (the manager)")
      .text("plot", &plot_path, "where to write latency and memory against time", "FILE.png");
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
  std::vector<ros::Time> sent_stamps;
  std::vector<double> rss;  // MiB, at each image sent
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
      sent_stamps.push_back(now);
      if (pid > 0) rss.push_back(residentMiB(pid));
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
  if (pid > 0 && !rss.empty() && rss.front() >= 0) {
    const double peak = *std::max_element(rss.begin(), rss.end());
    // The second half shows whether memory keeps growing once running.
    const double half = rss[rss.size() / 2];
    std::printf("%-28s at the first image %.1f MiB, at the middle %.1f, at the end %.1f, peak %.1f\n",
                "manager resident memory", rss.front(), half, rss.back(), peak);
  }
  if (!plot_path.empty()) {
    auto series = [&](const std::map<ros::Time, double>& latencies) {
      std::vector<double> v;
      for (const ros::Time& t : sent_stamps) {
        const auto it = latencies.find(t);
        v.push_back(it == latencies.end() ? -1.0 : it->second);  // -1: never arrived
      }
      return v;
    };
    plot(series(tracks_latency_ms), series(plane_latency_ms), rss, rate, plot_path);
    std::printf("plot: %s\n", plot_path.c_str());
  }
  return plane_latency_ms.empty() ? 1 : 0;
}
