// The plane nodelet's diagnostics task ("planes"): what a user at the robot reads. The
// nodelet keeps a PlaneRunState as tracks, camera_info and tf come, gathers a
// PlaneStatusView when the diagnostics ask, and reportPlaneStatus turns both into the
// status; kept apart from the nodelet so that each problem's level and text is tested
// without a ROS master (test_message_checks, PlaneStatus).
#pragma once

#include <diagnostic_updater/DiagnosticStatusWrapper.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mono_plane_detection/mapping/plane_pipeline.h"

namespace mono_plane_detection {

// Written by the nodelet under its lock; the last tracks' state and totals since the start.
struct PlaneRunState {
  PipelineState state = PipelineState::kNoCamera;
  std::string status;  // the pipeline's status of the last tracks ("" before any)
  double start_wait_s = 0, start_target_unseen_s = 0;  // PipelineResult's, last tracks
  size_t observed = 0;                                 // planes in the last image
  std::string metric_source;                           // the source that started the map, "" before
  // The odometry (odom_frame set) for the last tracks.
  std::string odom_tf_problem;    // why tf links no odometry to their camera at all
  bool odom_rigid = false;        // ...because odom_frame is rigid with the camera
  bool odometry_stopped = false;  // tf links it, but had nothing at their stamp
  std::string odom_stale_link;    // then the link on tf that lacked the stamp, if found
  // The start-up target.
  std::string target_mismatch;  // the tracker's target is not ours (last flagged tracks)
  // The last tracks with the target's corners came without a camera (no camera_info): the
  // map never saw the target (hostile try: camera_info 2.5 s late).
  bool target_missed = false;
  // tf.
  std::string tf_conflict;       // why tf was refused; "" when fine
  std::string tf_edge;           // what is published ("" before anything)
  std::string map_frame_shared;  // others' links into map_frame ("" when none)
  // Totals.
  long frames = 0;               // tracks processed
  long dropped = 0;              // tracks messages refused on arrival
  long dropped_info = 0;         // camera_info messages refused
  long refused_odom = 0;         // odometry refused (a jump, a non-finite pose)
  long camera_switches = 0;      // tracks of another camera than the last
  long missing_tracks = 0;       // tracks missing from the stream by their stamps
  long info_size_mismatch = 0;   // tracks whose camera_info was of another size
  long info_frame_mismatch = 0;  // tracks whose camera_info names another frame
  long resets = 0;               // every start over of the map
  long backwards_resets = 0;     // ...because time went backwards
  long tracker_restarts = 0;     // ...because the tracker started over
  long reconfigures = 0;         // dynamic_reconfigure calls after the server's start
};

// Gathered from the nodelet's configuration, calibration and pipeline when asked.
struct PlaneStatusView {
  std::string map_frame, odom_frame;  // odom_frame "" when not set
  std::string metric_source_param;    // pose/metric_source as configured
  std::string config_blocked;         // why the metric source cannot give metres ("" when it can)
  std::vector<std::string> refused_params;  // replaced by their defaults (start, reconfigure)
  double odom_wait_s = 0.25;                // as configured
  double target_timeout_s = 30;             // as configured
  bool publish_tf = true;
  std::string info_mismatch;         // camera_info of another size than the tracks
  bool camera_info_overdue = false;  // tracks, but no usable camera_info within the grace
  std::string camera_model;          // cameraModelName
  std::string odometry_mismatch;     // "" unless the odometry moves the camera otherwise
  double target_waited_s = 0;        // waiting for the metric start, in tracks stamps
  long exceptions = 0;
  std::string last_exception;
  long odom_waits_in_vain = 0;
  std::string map_up;  // mapUpText
  size_t map_planes = 0;
  std::optional<size_t> landmarks;  // none before the pose estimator starts
  // (key, text) WARNs of the stream lately and of recent refusals (the totals stay).
  std::vector<std::pair<std::string, std::string>> stream_problems, recent_problems;
};

// Whether loose floors and walls are held level / upright by the map's up (mapping.md,
// rule 7), and if not why: a user whose sheet lies on the floor sees it.
std::string mapUpText(const PlanePipeline& pipeline, const std::string& metric_source);

// Another broadcaster's links into map_frame (foreign: "a -> b, ..."), said as a problem.
std::string mapFrameSharedText(const std::string& map_frame, const std::string& foreign);

// The status: every problem now under "problem: <key>" (the present state before what
// happened lately; the summary is the most severe), then the state and the totals.
void reportPlaneStatus(const PlaneRunState& run, const PlaneStatusView& view,
                       diagnostic_updater::DiagnosticStatusWrapper& status);

}  // namespace mono_plane_detection
