// libFuzzer: message-level input to both nodelets, without ROS transport. The bytes are
// read as a sequence of sensor_msgs/Image, sensor_msgs/CameraInfo and Tracks messages
// (field by field, lengths bounded so that a length field cannot ask for gigabytes the
// way a wire message of that size could not either) and handed to exactly what the
// nodelets call: TrackerFrontEnd (tracker nodelet), fromCameraInfo + PlanePipeline and
// toTrackFrame + PlanePipeline (plane nodelet). A last section sets parameters from the
// bytes and runs validate(): nothing may throw, assert or hang.
#include <boost/make_shared.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include <algorithm>
#include <string>
#include <vector>

#include "../../src/nodelets/camera_info_check.h"
#include "../../src/nodelets/plane_messages.h"
#include "../../src/nodelets/tracker_front_end.h"
#include "fuzz_input.h"
#include "mono_plane_detection/Tracks.h"
#include "mono_plane_detection/mapping/plane_pipeline.h"
#include "mono_plane_detection/params/param_table.h"

using namespace mono_plane_detection;

namespace {

const char* const kEncodings[] = {"mono8", "bgr8", "rgb8", "bgra8", "mono16", "16UC1",
                                  "32FC1", "8UC3", "yuv422", "", "junk"};
const char* const kModels[] = {"plumb_bob", "rational_polynomial", "equidistant", "", "fisheye",
                               "junk"};
const char* const kFrames[] = {"camera_optical", "rear_optical", ""};

template <class T, size_t N>
const T& pick(FuzzInput& in, const T (&options)[N]) {
  return options[in.nextByte() % N];
}

uint32_t nextU32(FuzzInput& in) {
  uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v = (v << 8) | in.nextByte();
  return v;
}

std_msgs::Header nextHeader(FuzzInput& in) {
  std_msgs::Header h;
  h.stamp.sec = nextU32(in);
  h.stamp.nsec = nextU32(in) % 1000000000u;
  h.frame_id = pick(in, kFrames);
  return h;
}

sensor_msgs::ImagePtr nextImage(FuzzInput& in) {
  auto msg = boost::make_shared<sensor_msgs::Image>();
  msg->header = nextHeader(in);
  // Small sizes are where OpenCV's window checks bite; up to 255 x 255 keeps runs fast.
  msg->width = in.nextByte();
  msg->height = in.nextByte();
  msg->encoding = pick(in, kEncodings);
  msg->is_bigendian = in.nextByte() & 1;
  const uint8_t step_kind = in.nextByte() % 4;  // right, short, long, arbitrary
  const uint32_t row = msg->width * std::max(1, static_cast<int>(in.nextByte() % 5));
  msg->step = step_kind == 0 ? row : step_kind == 1 ? row / 2 : step_kind == 2 ? row + 7 : in.nextByte();
  const size_t wanted = in.nextByte() % 2 ? size_t(msg->step) * msg->height : in.nextByte() * 37u;
  msg->data.resize(std::min<size_t>(wanted, 1 << 17));
  for (uint8_t& b : msg->data) b = in.nextByte() ^ static_cast<uint8_t>(&b - msg->data.data());
  return msg;
}

sensor_msgs::CameraInfo nextCameraInfo(FuzzInput& in) {
  sensor_msgs::CameraInfo info;
  info.header = nextHeader(in);
  info.width = in.nextByte() * 4;
  info.height = in.nextByte() * 4;
  info.distortion_model = pick(in, kModels);
  info.D.resize(in.nextByte() % 16);
  for (double& d : info.D) d = in.nextByte() % 2 ? in.nextFloat() : 0.01 * (in.nextByte() % 10);
  const bool plausible = in.nextByte() % 2;
  for (double& k : info.K) k = in.nextFloat();
  for (double& p : info.P) p = in.nextFloat();
  for (double& r : info.R) r = in.nextFloat();
  if (plausible) {  // mostly a real camera, so the later stages are reached too
    info.K = {500, 0, 320, 0, 500, 240, 0, 0, 1};
    info.P = {500, 0, 320, 0, 0, 500, 240, 0, 0, 0, 1, 0};
    info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    info.width = 640;
    info.height = 480;
  }
  return info;
}

Tracks nextTracks(FuzzInput& in) {
  Tracks msg;
  msg.header = nextHeader(in);
  msg.width = in.nextByte() % 2 ? 640 : nextU32(in);
  msg.height = in.nextByte() % 2 ? 480 : nextU32(in);
  const size_t n = in.nextByte() % 80;
  // Array lengths disagree now and then: toTrackFrame must refuse those.
  const size_t skew = in.nextByte() % 8 == 0 ? in.nextByte() % 3 : 0;
  for (size_t i = 0; i < n; ++i) {
    msg.id.push_back(in.nextByte() % 100);
    const cv::Point2d p = in.nextPoint();
    msg.u.push_back(static_cast<float>(p.x));
    msg.v.push_back(static_cast<float>(p.y));
    msg.prev_index.push_back(static_cast<int8_t>(in.nextByte()));
    msg.flags.push_back(in.nextByte() & 0x0f);
    msg.age.push_back(in.nextByte());
  }
  msg.u.resize(n + skew);
  return msg;
}

// Parameters as a user's YAML could give them: any number, in or out of range.
template <class P>
void fuzzParams(FuzzInput& in, P& params, const ParamTable<P>& table) {
  for (const ParamSpec<P>& spec : table) {
    if (in.empty()) break;
    if (in.nextByte() % 4) continue;
    const double v = in.nextFloat();
    std::visit(
        [v](auto* target) {
          using T = std::remove_pointer_t<decltype(target)>;
          if constexpr (std::is_same_v<T, bool>) {
            *target = v > 0;
          } else if constexpr (std::is_same_v<T, std::string>) {
            *target = std::to_string(v);
          } else if constexpr (std::is_floating_point_v<T>) {
            *target = v;
          } else if (std::isfinite(v) && v > -1e9 && v < 1e9) {
            *target = static_cast<T>(v);  // what the ROS reader does for an int in range of int
          }
        },
        spec.field(params));
  }
  validate(params);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FuzzInput in(data, size);
  TrackerNodeParams tracker_params;
  PlaneNodeParams plane_params;
  if (in.nextByte() % 4 == 0) {
    fuzzParams(in, tracker_params, trackerNodeParamTable());
    fuzzParams(in, plane_params, planeNodeParamTable());
  }
  plane_params.pipeline.planes.groups.max_tries =
      std::min(plane_params.pipeline.planes.groups.max_tries, 300);
  TrackerFrontEnd tracker(tracker_params);
  PlanePipeline pipeline(plane_params.pipeline);
  for (int message = 0; message < 8 && !in.empty(); ++message) {
    switch (in.nextByte() % 3) {
      case 0:
        tracker.process(nextImage(in));
        break;
      case 1: {
        const sensor_msgs::CameraInfo info = nextCameraInfo(in);
        tracker.setCameraInfo(info);
        cv::Matx33d K;
        cv::Mat D;
        if (fromCameraInfo(info, K, D).empty()) pipeline.setCamera(K, D);
        break;
      }
      default: {
        std::string error;
        const TrackFrame frame = toTrackFrame(nextTracks(in), error);
        if (error.empty()) pipeline.process(frame);
        break;
      }
    }
  }
  return 0;
}
