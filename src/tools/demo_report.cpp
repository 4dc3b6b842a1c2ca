// Listens to a running pipeline (tracks, planes, image) and, when the input ends, prints
// what it found and writes results: an overlay of a late image, a top-down map and the
// planes as YAML. With the ground truth of a generated sequence it also prints each
// plane's errors and the camera path error. Used by `make demo`.
//   rosrun mono_plane_detection demo_report --out results --truth seq.yaml --frames 300
#include <cv_bridge/cv_bridge.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <sys/stat.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "../sim/bag/ground_truth.h"
#include "cli_args.h"
#include "mono_plane_detection/Tracks.h"
#include "mono_plane_detection/ros/map_frame.h"
#include "mono_plane_detection/viz/draw_planes.h"

using namespace mono_plane_detection;

namespace {

struct Timing {
  std::vector<double> ms;
  double mean() const {
    double s = 0;
    for (double v : ms) s += v;
    return ms.empty() ? 0 : s / ms.size();
  }
  double p95() const {
    if (ms.empty()) return 0;
    std::vector<double> v = ms;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<size_t>(0.95 * v.size()))];
  }
};

struct ReportOptions {
  std::string out = "results", truth;
  int frames = 0;                      // expected plane messages; 0: unknown
  double idle_timeout_s = 10;          // silence after the last message that ends the input
  double first_message_timeout_s = 60; // no first message by then: the pipeline is not running
};

class Report {
 public:
  Report(ros::NodeHandle& nh, const ReportOptions& options)
      : out_(options.out),
        truth_path_(options.truth),
        expected_(options.frames),
        idle_timeout_s_(options.idle_timeout_s),
        first_message_timeout_s_(options.first_message_timeout_s) {
    if (!truth_path_.empty()) truth_ = loadGroundTruth(truth_path_);
    planes_sub_ = nh.subscribe("planes", 50, &Report::onPlanes, this);
    tracks_sub_ = nh.subscribe("tracks", 50, &Report::onTracks, this);
    image_sub_ = nh.subscribe("image", 50, &Report::onImage, this);
    image_planes_sub_ = nh.subscribe("image_planes", 50, &Report::onImagePlanes, this);
  }

  // True when no message came within the first-message timeout.
  bool timedOut() const {
    return planes_seen_ == 0 && (ros::WallTime::now() - started_).toSec() > first_message_timeout_s_;
  }

  // True when the input has ended (all frames, or silence after the first message).
  bool done() const {
    if (expected_ > 0 && planes_seen_ >= expected_) return true;
    return planes_seen_ > 0 && (ros::WallTime::now() - last_message_).toSec() > idle_timeout_s_;
  }

  int write() {
    mkdir(out_.c_str(), 0755);
    std::printf("\n=== mono_plane_detection demo: %d frames processed ===\n", planes_seen_);
    // A partial run must not read as a whole one (what follows is about these frames).
    if (expected_ > 0 && planes_seen_ < expected_)
      std::printf("WARNING: planes heard for %d of the %d images: the rest were dropped by the "
                  "pipeline (queues full under load) or came before this report subscribed\n",
                  planes_seen_, expected_);
    std::printf("tracker nodelet: %.2f ms mean, %.2f ms p95 per frame\n", tracker_ms_.mean(),
                tracker_ms_.p95());
    std::printf("plane nodelet:   %.2f ms mean, %.2f ms p95 per frame\n", planes_ms_.mean(),
                planes_ms_.p95());
    std::printf("status at the end: %s\n", last_planes_ ? last_planes_->status.c_str() : "-");
    const std::vector<MapPlane> planes =
        last_planes_ ? mapPlanesOf(*last_planes_) : std::vector<MapPlane>{};
    MapEvaluation eval;
    if (truth_) eval = evaluateMap(planes, truth_->planes);
    std::printf("image planes: %d of %d images had planes in image space\n", with_image_planes_,
                image_plane_messages_);
    std::printf("planes in the map (confirmed): %zu\n", planes.size());
    // An empty map without a metric start: say what starts one (docs/start_up.md).
    if (planes.empty() && last_planes_ && !last_planes_->metric)
      std::printf("  no metric start (%s): the map needs the start-up target in view, odometry "
                  "(pose/metric_source odometry with odom_frame) or the camera height "
                  "(pose/metric_source camera_height with pose/camera_height_m)\n",
                  last_planes_->status.c_str());
    YAML::Node yaml;
    for (size_t i = 0; i < planes.size(); ++i) {
      const MapPlane& p = planes[i];
      std::printf("  plane %2d: normal (%6.3f %6.3f %6.3f)  distance %6.3f m  seen %4d times", p.id,
                  p.normal[0], p.normal[1], p.normal[2], p.distance, p.observations);
      YAML::Node node;
      node["id"] = p.id;
      node["normal"].push_back(p.normal[0]);
      node["normal"].push_back(p.normal[1]);
      node["normal"].push_back(p.normal[2]);
      node["distance_m"] = p.distance;
      node["observations"] = p.observations;
      node["confidence"] = p.confidence;
      for (const auto& v : p.polygon) {
        YAML::Node corner;
        corner.push_back(v[0]);
        corner.push_back(v[1]);
        corner.push_back(v[2]);
        node["polygon_map"].push_back(corner);
      }
      if (truth_) {
        const PlaneMatch& m = eval.matches[i];
        if (m.truth_id >= 0) {
          std::printf("  -> %-10s normal error %.2f deg, distance error %.3f m",
                      m.truth_name.c_str(), m.normal_error_deg, m.distance_error_m);
          node["truth"] = m.truth_name;
          node["normal_error_deg"] = m.normal_error_deg;
          node["distance_error_m"] = m.distance_error_m;
        } else {
          std::printf("  -> no true plane matches");
        }
      }
      std::printf("\n");
      yaml["planes"].push_back(node);
    }
    if (truth_) {
      for (const TruthPlane& t : truth_->planes)
        if (std::find(eval.missed.begin(), eval.missed.end(), t.id) != eval.missed.end())
          std::printf("  missed: %s (covers up to %.0f %% of an image)\n", t.name.c_str(),
                      100 * t.max_image_share);
      double sum = 0, worst = 0;
      for (const auto& e : position_errors_) {
        sum += e;
        worst = std::max(worst, e);
      }
      const double mean = position_errors_.empty() ? 0 : sum / position_errors_.size();
      std::printf(
          "camera: placed in %zu of %d images; position error mean %.3f m, max %.3f m "
          "over %.2f m travelled (max %.1f %%)\n",
          position_errors_.size(), planes_seen_, mean, worst, truth_->travelled_m,
          truth_->travelled_m > 0 ? 100 * worst / truth_->travelled_m : 0.0);
      yaml["camera_position_error_mean_m"] = mean;
      yaml["camera_position_error_max_m"] = worst;
      yaml["missed_planes"] = static_cast<int>(eval.missed.size());
      yaml["split_planes"] = static_cast<int>(eval.split.size());
    }
    // In the target's frame (y up), as the ground truth; the planes topic has them z up.
    std::ofstream(out_ + "/planes.yaml") << "# mono_plane_detection demo: the map's confirmed "
                                            "planes (start-up target's frame, y up, metres)\n"
                                         << yaml << "\n";
    writeOverlay();
    writeTopDown(planes);
    std::printf("wrote %s/overlay.png, %s/map_top.png, %s/planes.yaml\n", out_.c_str(),
                out_.c_str(), out_.c_str());
    return planes.empty() ? 1 : 0;
  }

 private:
  void touched() { last_message_ = ros::WallTime::now(); }

  void onTracks(const TracksConstPtr& msg) {
    touched();
    tracker_ms_.ms.push_back(msg->processing_ms);
    tracks_[msg->header.stamp] = msg;
    while (tracks_.size() > 60) tracks_.erase(tracks_.begin());
  }

  void onImagePlanes(const PlaneArrayConstPtr& msg) {
    ++image_plane_messages_;
    with_image_planes_ += !msg->planes.empty();
  }

  void onImage(const sensor_msgs::ImageConstPtr& msg) {
    images_[msg->header.stamp] = msg;
    while (images_.size() > 60) images_.erase(images_.begin());
  }

  void onPlanes(const PlaneArrayConstPtr& msg) {
    touched();
    ++planes_seen_;
    planes_ms_.ms.push_back(msg->processing_ms);
    last_planes_ = msg;
    if (images_.count(msg->header.stamp) && tracks_.count(msg->header.stamp))
      overlay_ = {images_[msg->header.stamp], tracks_[msg->header.stamp], msg};
    if (truth_ && msg->metric)
      if (const auto truth = poseAt(*truth_, msg->header.stamp.toSec()))
        position_errors_.push_back(cv::norm(targetFromRosMap(fromPoseMsg(msg->camera_pose)).t - truth->t));
    if (expected_ > 0 && (planes_seen_ % 30 == 0 || planes_seen_ == expected_)) {
      std::printf("  frames %d / %d: %s, %zu planes\n", planes_seen_, expected_,
                  msg->status.c_str(), msg->planes.size());
      std::fflush(stdout);
    }
  }

  // The late image with each track coloured by the plane it is on.
  void writeOverlay() {
    if (!std::get<0>(overlay_)) return;
    const auto& [image, tracks, planes] = overlay_;
    cv::Mat out;
    try {
      out = cv_bridge::toCvCopy(image, "bgr8")->image;
    } catch (const cv_bridge::Exception&) {
      return;
    }
    std::map<std::uint64_t, int> plane_of;
    for (const auto& p : planes->planes)
      if (p.observed)
        for (auto id : p.inlier_ids) plane_of[id] = p.id;
    for (size_t i = 0; i < tracks->id.size(); ++i) {
      const auto it = plane_of.find(tracks->id[i]);
      const cv::Point2f at(tracks->u[i], tracks->v[i]);
      if (it == plane_of.end()) {  // on no plane: a hollow white ring
        cv::circle(out, at, 4, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
        cv::circle(out, at, 4, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
      } else {
        cv::circle(out, at, 5, cv::Scalar(0, 0, 0), cv::FILLED, cv::LINE_AA);
        cv::circle(out, at, 4, planeColour(it->second), cv::FILLED, cv::LINE_AA);
      }
    }
    cv::putText(out, planes->status, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {255, 255, 255}, 1,
                cv::LINE_AA);
    int row = 40;
    for (const auto& p : planes->planes)
      if (p.observed) {
        cv::putText(out, "plane " + std::to_string(p.id), {8, row}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                    planeColour(p.id), 1, cv::LINE_AA);
        row += 18;
      }
    cv::imwrite(out_ + "/overlay.png", out);
  }

  // Seen from above: the map's up axis is the target plane's y (a wall target) unless
  // the truth says otherwise; planes as segments, the camera path, the target.
  void writeTopDown(const std::vector<MapPlane>& planes) {
    const int size = 600;
    const double metres = 12.0, scale = size / metres;
    cv::Mat out(size, size, CV_8UC3, cv::Scalar(255, 255, 255));
    // Map x to the right, map z (into the room) downwards: the target's wall at the top.
    auto pixel = [&](const cv::Vec3d& p) {
      return cv::Point(cvRound(size / 2 + p[0] * scale), cvRound(40 + p[2] * scale));
    };
    for (int m = -6; m <= 6; ++m) {
      cv::line(out, pixel({double(m), 0, 0}), pixel({double(m), 0, 11}), {235, 235, 235});
      cv::line(out, pixel({-6, 0, double(m + 6)}), pixel({6, 0, double(m + 6)}), {235, 235, 235});
    }
    for (const MapPlane& p : planes) {
      if (std::abs(p.normal[1]) > 0.7) continue;  // floor / ceiling: seen from above, no segment
      double lo = 1e9, hi = -1e9;
      const cv::Vec3d along(-p.normal[2], 0, p.normal[0]);
      for (const auto& v : p.polygon) {
        lo = std::min(lo, along.dot(v));
        hi = std::max(hi, along.dot(v));
      }
      const cv::Vec3d foot(p.normal[0] * p.distance, 0, p.normal[2] * p.distance);
      cv::line(out, pixel(foot + lo * along), pixel(foot + hi * along), planeColour(p.id), 3,
               cv::LINE_AA);
      cv::putText(out, std::to_string(p.id),
                  pixel(foot + 0.5 * (lo + hi) * along) + cv::Point(4, 14),
                  cv::FONT_HERSHEY_SIMPLEX, 0.45, planeColour(p.id), 1, cv::LINE_AA);
    }
    if (truth_)
      for (size_t i = 1; i < truth_->poses.size(); ++i)
        cv::line(out, pixel(truth_->poses[i - 1].t), pixel(truth_->poses[i].t), {0, 200, 0}, 5,
                 cv::LINE_AA);
    for (size_t i = 1; i < path_.size(); ++i)
      cv::line(out, pixel(path_[i - 1]), pixel(path_[i]), {200, 0, 0}, 1, cv::LINE_AA);
    cv::rectangle(out, pixel({-0.15, 0, -0.02}), pixel({0.15, 0, 0.02}), {0, 0, 0}, cv::FILLED);
    cv::putText(out, "planes (colour), camera path (blue), truth (green), target (black)",
                {8, size - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {0, 0, 0}, 1, cv::LINE_AA);
    cv::imwrite(out_ + "/map_top.png", out);
  }

 public:
  void recordPath() {
    if (last_planes_ && last_planes_->metric && last_planes_.get() != last_recorded_) {
      path_.push_back(targetFromRosMap(fromPoseMsg(last_planes_->camera_pose)).t);
      last_recorded_ = last_planes_.get();
    }
  }

 private:
  std::string out_, truth_path_;
  int expected_ = 0, planes_seen_ = 0, image_plane_messages_ = 0, with_image_planes_ = 0;
  double idle_timeout_s_ = 10, first_message_timeout_s_ = 60;
  const ros::WallTime started_ = ros::WallTime::now();
  std::optional<GroundTruth> truth_;
  ros::Subscriber planes_sub_, tracks_sub_, image_sub_, image_planes_sub_;
  ros::WallTime last_message_ = ros::WallTime::now();
  Timing tracker_ms_, planes_ms_;
  PlaneArrayConstPtr last_planes_;
  const PlaneArray* last_recorded_ = nullptr;
  std::map<ros::Time, TracksConstPtr> tracks_;
  std::map<ros::Time, sensor_msgs::ImageConstPtr> images_;
  std::tuple<sensor_msgs::ImageConstPtr, TracksConstPtr, PlaneArrayConstPtr> overlay_;
  std::vector<double> position_errors_;
  std::vector<cv::Vec3d> path_;
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "demo_report");  // takes the remappings (planes:=...) out of argv
  ReportOptions options;
  cli::Parser cli(
      "demo_report", "[options] [planes:=TOPIC tracks:=TOPIC image:=TOPIC image_planes:=TOPIC]",
      "  Listens to a running pipeline (tracks, planes, image) and, when the input ends,\n"
      "  prints what it found and writes an overlay, a top-down map and the planes as YAML.\n"
      "  With the ground truth of a generated sequence it also prints each plane's errors.",
      "exit codes: 0 planes found, 1 no plane or no message before the timeout, 2 bad usage\n");
  cli.text("out", &options.out, "folder for the results", "DIR")
      .text("truth", &options.truth, "ground truth YAML of make_sequence", "FILE")
      .integer("frames", &options.frames, 0, 10000000,
               "plane messages to expect (0: until the input is silent)")
      .number("idle-timeout", &options.idle_timeout_s, 0.1, 3600.0,
              "silence after the last message that ends the input, s", "S")
      .number("first-message-timeout", &options.first_message_timeout_s, 0.1, 3600.0,
              "give up when no message came by then, s", "S");
  if (const auto code = cli.parse(argc, argv)) return *code;
  if (!options.truth.empty() && !std::ifstream(options.truth))
    return cli.fail("cannot read the ground truth " + options.truth);
  // Without a master, subscribing would wait for ever: wait as long as for a message.
  const ros::WallTime give_up =
      ros::WallTime::now() + ros::WallDuration(options.first_message_timeout_s);
  while (!ros::master::check()) {
    if (ros::WallTime::now() > give_up) {
      std::fprintf(stderr, "demo_report: no ROS master at %s within %.0f s\n",
                   ros::master::getURI().c_str(), options.first_message_timeout_s);
      return 1;
    }
    ros::WallDuration(0.2).sleep();
  }
  ros::NodeHandle nh;
  try {
    Report report(nh, options);
    ros::WallRate rate(200);  // wall clock: simulated time stops with the bag
    while (ros::ok() && !report.done()) {
      if (report.timedOut()) {
        std::fprintf(stderr,
                     "demo_report: no message on %s within %.0f s: is the pipeline running, "
                     "and does the bag hold the camera's image and camera_info topics?\n",
                     ros::names::resolve("planes").c_str(), options.first_message_timeout_s);
        return 1;
      }
      ros::spinOnce();
      report.recordPath();
      rate.sleep();
    }
    return report.write();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "demo_report: %s\n", e.what());
    return 2;
  }
}
