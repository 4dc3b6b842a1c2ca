#include "plane_status.h"

#include <diagnostic_msgs/DiagnosticStatus.h>

#include <initializer_list>
#include <iomanip>
#include <sstream>

#include "nodelet_diagnostics.h"
#include "ros_params.h"

namespace mono_plane_detection {
namespace {

// A target out of view longer than this before the start finished: WARN.
constexpr double kStartTargetGoneS = 2.0;

std::string secondsText(double s) {
  std::ostringstream text;
  text << std::setprecision(3) << s << " s";  // 0.25 s, 2.53 s, 10.5 s, 150 s
  return text.str();
}

std::string degreesText(double deg) {
  std::ostringstream text;
  text << deg << " deg";
  return text.str();
}

void addValues(diagnostic_updater::DiagnosticStatusWrapper& status,
               std::initializer_list<std::pair<const char*, long>> values) {
  for (const auto& [key, value] : values) status.add(key, value);
}

// The odometry problems: one at most, the most telling first.
void addOdometryProblem(const PlaneRunState& run, const PlaneStatusView& view,
                        StatusProblems& problems) {
  using diagnostic_msgs::DiagnosticStatus;
  const std::string without =
      run.metric_source == "odometry"
          ? std::string("camera pose from vision only")
          : "no " + view.map_frame + " <-> " + view.odom_frame + " tf for these images";
  if (!run.odom_tf_problem.empty())  // (a rigid odom_frame is a configuration error)
    problems.add(run.odom_rigid ? DiagnosticStatus::ERROR : DiagnosticStatus::WARN, "odometry",
                 "no odometry: " + run.odom_tf_problem);
  else if (!view.odometry_mismatch.empty())
    problems.add(DiagnosticStatus::ERROR, "odometry", view.odometry_mismatch);
  else if (run.odometry_stopped && !run.odom_stale_link.empty() &&
           run.odom_stale_link.find(view.odom_frame + " -> ") == std::string::npos)
    // Not the odometry's own link: another publisher between it and the camera.
    problems.add(DiagnosticStatus::WARN, "odometry",
                 "tf " + run.odom_stale_link + " (between the camera and odom_frame '" +
                     view.odom_frame + "') is more than odom_wait_s (" +
                     secondsText(view.odom_wait_s) +
                     ") behind the images: its publisher (robot_state_publisher with "
                     "/joint_states for a joint) stopped or is late; " +
                     without);
  else if (run.odometry_stopped)
    problems.add(DiagnosticStatus::WARN, "odometry",
                 "odometry (" + view.odom_frame + ") stopped, or more than odom_wait_s (" +
                     secondsText(view.odom_wait_s) + ") behind the images: " + without);
}

// The metric start that does not come or cannot finish.
void addStartProblem(const PlaneRunState& run, const PlaneStatusView& view,
                     StatusProblems& problems) {
  using diagnostic_msgs::DiagnosticStatus;
  const std::string waited = std::to_string(static_cast<long>(view.target_waited_s));
  if (run.state == PipelineState::kWaitingForTarget && view.target_waited_s > view.target_timeout_s)
    problems.add(DiagnosticStatus::WARN, "metric start",
                 view.metric_source_param == "target"
                     ? "start-up target not seen for " + waited +
                           " s: show it to the camera, or start the metres without it "
                           "(metric_source odometry with odom_frame, or camera_height "
                           "with camera_height_m)"
                     : "no metric start (" + run.status + ") for " + waited + " s");
  // The target start that cannot finish (hostile try: OK for 550 images).
  if (run.state == PipelineState::kInitialising && run.start_target_unseen_s > kStartTargetGoneS)
    problems.add(DiagnosticStatus::WARN, "metric start",
                 "the start-up target left the view " + secondsText(run.start_target_unseen_s) +
                     " ago, before the start finished (it needs the target in two views "
                     "with parallax): show it to the camera again and move a few cm "
                     "sideways; if its corners were lost, the tracker looks for it again "
                     "only after its ~reset");
  else if (run.state == PipelineState::kInitialising && run.start_wait_s > view.target_timeout_s)
    problems.add(DiagnosticStatus::WARN, "metric start",
                 "the start has waited " + secondsText(run.start_wait_s) +
                     " for parallax with the target in view: move the camera a few cm "
                     "sideways (or towards it) while it sees the target; turning on the "
                     "spot gives no parallax");
}

}  // namespace

std::string mapUpText(const PlanePipeline& pipeline, const std::string& metric_source) {
  const MapParams& map = pipeline.map().params();
  if (!map.upCanHold())
    return map.up_sigma_deg <= 0       ? "off"
           : map.structure_sigmas <= 0 ? "off (map/structure_sigmas 0)"
                                       : "no effect: not below map/max_normal_sigma_deg";
  if (!pipeline.verticalDecided()) return "not decided yet (at the first image placed in metres)";
  if (pipeline.map().vertical()) return "held to it (" + degreesText(map.up_sigma_deg) + ")";
  if (metric_source == "camera_height") return "not used: the map's up is the floor's own fit";
  if (metric_source == "odometry")
    return "not used: the camera at the map's start was not upright along the odometry's z";
  return "not used: the camera at the map's start was not upright along the target's y (a "
         "target on the floor or hung portrait?)";
}

std::string mapFrameSharedText(const std::string& map_frame, const std::string& foreign) {
  return "map_frame '" + map_frame + "' also holds " + foreign +
         " from another broadcaster on /tf: a second pipeline (another camera or robot) with "
         "the same map_frame puts a map with an unrelated origin into this frame; give each "
         "camera its own map_frame (e.g. map_frame:=robot1/plane_map)";
}

void reportPlaneStatus(const PlaneRunState& run, const PlaneStatusView& view,
                       diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  // The present state first, then what happened lately; the summary is the most severe.
  StatusProblems problems;
  if (!run.tf_conflict.empty())
    problems.add(DiagnosticStatus::ERROR, "tf", "tf conflict: " + run.tf_conflict);
  else if (!run.map_frame_shared.empty())
    problems.add(DiagnosticStatus::WARN, "tf",
                 mapFrameSharedText(view.map_frame, run.map_frame_shared));
  // A metric source that cannot give metres is an error until it is set.
  if (!view.config_blocked.empty())
    problems.add(DiagnosticStatus::ERROR, "configuration", view.config_blocked);
  if (!run.target_mismatch.empty())
    problems.add(DiagnosticStatus::ERROR, "start-up target",
                 "start-up target: " + run.target_mismatch);
  else if (run.target_missed && run.state == PipelineState::kWaitingForTarget)
    problems.add(DiagnosticStatus::WARN, "start-up target",
                 "the tracker found the start-up target before camera_info came, and it is "
                 "not tracked any more: show it again and call the tracker's ~reset (it "
                 "joins the target once), or publish camera_info with the first images");
  // (Now: a camera_info or tracks of the right size clear it at once.)
  if (!view.info_mismatch.empty())
    problems.add(DiagnosticStatus::ERROR, "camera_info", view.info_mismatch);
  if (view.camera_info_overdue)
    problems.add(DiagnosticStatus::WARN, "camera_info", "tracks arrive but no usable camera_info");
  if (run.state == PipelineState::kLost)
    problems.add(DiagnosticStatus::WARN, "tracking",
                 run.status.rfind("lost", 0) == 0 ? "tracking " + run.status
                                                  : "tracking lost: " + run.status);
  addOdometryProblem(run, view, problems);
  addStartProblem(run, view, problems);
  // The stream lately (as the tracker's).
  problems.addWarnings(view.stream_problems);
  // Other refused values were replaced by their defaults: after the present problems.
  if (view.config_blocked.empty() && !view.refused_params.empty())
    problems.add(DiagnosticStatus::WARN, "configuration", refusedParamsText(view.refused_params));
  if (view.exceptions > 0) problems.add(DiagnosticStatus::WARN, "exceptions", "exceptions caught");
  problems.addWarnings(view.recent_problems, "last 10 s, ");  // the totals stay below
  const std::string state = run.status.empty() ? "no tracks yet" : run.status;
  problems.report(status, state);
  // The state also when a problem is the summary.
  status.add("state", state);
  status.add("exceptions caught (total)", view.exceptions);
  if (view.exceptions > 0) status.add("last exception", view.last_exception);
  addValues(status, {{"camera switches (total)", run.camera_switches},
                     {"odometry refused (total)", run.refused_odom}});
  if (!view.odom_frame.empty())
    status.add("odometry waited for in vain (total)", view.odom_waits_in_vain);
  addValues(status, {{"images processed", run.frames},
                     {"tracks messages dropped", run.dropped},
                     {"tracks missing from the stream (total)", run.missing_tracks},
                     {"camera_info messages rejected", run.dropped_info}});
  // The calibration of the last tracks' size (before any: the last camera_info).
  status.add("camera model", view.camera_model);
  status.add("tf", !run.tf_conflict.empty() ? "refused: " + run.tf_conflict
                   : !view.publish_tf       ? std::string("off")
                   : run.tf_edge.empty()    ? std::string("nothing published yet")
                                            : run.tf_edge);
  status.add("metric source", run.metric_source.empty()
                                  ? "none yet (" + view.metric_source_param + ")"
                                  : run.metric_source);
  status.add("map up (map/up_sigma_deg)", view.map_up);
  addValues(status,
            {{"tracks with camera_info of another size (total)", run.info_size_mismatch},
             {"tracks with camera_info of another frame_id (total)", run.info_frame_mismatch},
             // Every start over of the map: ~reset calls and time going backwards (a bag loop).
             {"resets (total)", run.resets},
             {"resets: time went backwards (total)", run.backwards_resets},
             {"resets: the tracker started over (total)", run.tracker_restarts},
             {"reconfigurations (total)", run.reconfigures},
             {"planes in this image", static_cast<long>(run.observed)},
             {"planes in the map", static_cast<long>(view.map_planes)}});
  if (view.landmarks) status.add("landmarks", *view.landmarks);
}

}  // namespace mono_plane_detection
