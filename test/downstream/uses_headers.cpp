// Includes the exported headers a user would: messages, the ROS frame helpers and the
// core's C++17 API (std::optional results, std::variant parameter fields).
#include <mono_plane_detection/PlaneArray.h>
#include <mono_plane_detection/SaveMap.h>
#include <mono_plane_detection/Tracks.h>
#include <mono_plane_detection/mapping/plane_pipeline.h>
#include <mono_plane_detection/params/param_table.h>
#include <mono_plane_detection/ros/map_frame.h>
#include <mono_plane_detection/ros/pose_msg.h>

#if __cplusplus < 201703L
#error "mono_plane_detection's export did not raise the C++ standard to 17"
#endif

int usesHeaders() {
  mono_plane_detection::PlaneNodeParams params;
  const std::optional<mono_plane_detection::Pose> none;
  return static_cast<int>(mono_plane_detection::validate(params).size()) + (none ? 1 : 0);
}
