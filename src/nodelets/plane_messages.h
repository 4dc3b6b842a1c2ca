// Conversions between the plane stage's ROS messages and the core's types: Tracks in,
// PlaneArray, rviz markers and the map's point cloud out. Everything metric leaves in
// the ROS map frame (ros/map_frame.h: REP 103, z up), never in the core's target frame.
#pragma once

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include <optional>
#include <set>
#include <string>

#include "mono_plane_detection/PlaneArray.h"
#include "mono_plane_detection/Tracks.h"
#include "mono_plane_detection/mapping/plane_pipeline.h"

namespace mono_plane_detection {

// The frame, or an error naming what is wrong (array lengths, values).
TrackFrame toTrackFrame(const Tracks& msg, std::string& error);

// Empty when the tracker's start-up target (as Tracks says: type and size) is the one
// `own` describes, or when the message does not say (empty target_type); else both,
// for the user to fix.
// Sizes agree within 1e-4 relative (Tracks carries float32).
std::string targetMismatch(const Tracks& msg, const TargetParams& own);

// Empty when an odometry pose can be used: finite, and no further than max_jump_m from
// the previous one (when there is one); else why not.
std::string odometryError(const Pose& odom_from_camera, const std::optional<Pose>& previous,
                          double max_jump_m);

// The map's planes (observed ones first, with homography and inliers) in the ROS map
// frame `map_header.frame_id`; the camera pose when this image has one.
PlaneArrayPtr toMapPlanes(const std_msgs::Header& map_header, const PipelineResult& result,
                          const PlaneMap& map);

// This image's planes in image space (homography, inliers), in the tracks' header.
PlaneArrayPtr toImagePlanes(const std_msgs::Header& image_header, const PipelineResult& result);

// A map plane as the message gives it (ROS map frame, shape_msgs sign, label).
PlaneEstimate toPlaneEstimate(const MapPlane& plane);

// Planes as YAML (~save_map): frame, stamp and per plane id, label, normal, d,
// observations, confidence, confirmed, polygon.
std::string planesYaml(const PlaneArray& planes);

// A translucent polygon, a normal arrow and a label ("wall 3 (12)"; "wall 4 (1, tentative)"
// until confirmed) per map plane, in the ROS map frame `header.frame_id`; DELETE markers
// for planes that were published before and are gone (`shown` is updated).
visualization_msgs::MarkerArrayPtr toMarkers(const std_msgs::Header& header, const PlaneMap& map,
                                             std::set<int>& shown);

// One DELETEALL marker: rviz drops every plane of the map it had.
visualization_msgs::Marker deleteAllMarker(const std_msgs::Header& header);

// Triangulated landmarks (x, y, z, rgb), coloured by the map plane they are on.
sensor_msgs::PointCloud2Ptr toCloud(const std_msgs::Header& header, const PoseEstimator& pose,
                                    const PlaneMap& map);

}  // namespace mono_plane_detection
