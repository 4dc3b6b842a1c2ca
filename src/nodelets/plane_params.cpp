#include "plane_params.h"

#include "param_check.h"

namespace mono_plane_detection {
namespace {

// ros::param has no size_t overload.
void paramSize(const ros::NodeHandle& pnh, const std::string& name, size_t& value) {
  int v = static_cast<int>(value);
  pnh.param(name, v, v);
  value = v > 0 ? static_cast<size_t>(v) : value;
}

}  // namespace

PipelineParams readPipelineParams(const ros::NodeHandle& pnh, const std::string& logger) {
  PipelineParams p;
  pnh.param("frame_gap", p.frame_gap, p.frame_gap);
  pnh.param("max_gap_s", p.max_gap_s, p.max_gap_s);
  // Plane core (paper III-IV).
  pnh.param("vote_threshold_px", p.planes.vote_threshold_px, p.planes.vote_threshold_px);
  pnh.param("min_plane_support", p.planes.min_plane_support, p.planes.min_plane_support);
  pnh.param("max_planes", p.planes.max_planes, p.planes.max_planes);
  pnh.param("invariant_threshold", p.planes.groups.invariant_threshold,
            p.planes.groups.invariant_threshold);
  pnh.param("max_groups", p.planes.groups.max_groups, p.planes.groups.max_groups);
  pnh.param("max_tries", p.planes.groups.max_tries, p.planes.groups.max_tries);
  int seed = static_cast<int>(p.planes.groups.seed);
  pnh.param("group_seed", seed, seed);
  p.planes.groups.seed = static_cast<unsigned>(seed);
  // Camera pose.
  pnh.param("min_parallax_deg", p.pose.min_parallax_deg, p.pose.min_parallax_deg);
  pnh.param("max_reprojection_px", p.pose.max_reprojection_px, p.pose.max_reprojection_px);
  pnh.param("min_pnp_points", p.pose.min_pnp_points, p.pose.min_pnp_points);
  pnh.param("start_parallax_deg", p.pose.two_view.min_parallax_deg,
            p.pose.two_view.min_parallax_deg);
  paramSize(pnh, "max_landmarks", p.pose.max_landmarks);
  pnh.param("target_width_m", p.target.width_m, p.target.width_m);
  pnh.param("target_height_m", p.target.height_m, p.target.height_m);
  // Map.
  pnh.param("plane_max_residual_m", p.map.max_residual_m, p.map.max_residual_m);
  pnh.param("plane_min_points", p.map.min_points, p.map.min_points);
  pnh.param("plane_min_share", p.map.min_share, p.map.min_share);
  pnh.param("associate_max_angle_deg", p.map.max_angle_deg, p.map.max_angle_deg);
  pnh.param("associate_max_offset_m", p.map.max_offset_m, p.map.max_offset_m);
  pnh.param("confirm_observations", p.map.confirm_observations, p.map.confirm_observations);
  pnh.param("tentative_timeout_s", p.map.tentative_timeout_s, p.map.tentative_timeout_s);
  pnh.param("fade_time_s", p.map.fade_time_s, p.map.fade_time_s);
  paramSize(pnh, "max_map_planes", p.map.max_planes);
  paramSize(pnh, "max_points_per_plane", p.map.max_points_per_plane);

  const PipelineParams d;
  const ParamCheck fix(logger);
  fix(p.frame_gap < 1, "frame_gap", p.frame_gap, d.frame_gap);
  fix(!(p.max_gap_s > 0), "max_gap_s", p.max_gap_s, d.max_gap_s);
  fix(!(p.planes.vote_threshold_px > 0), "vote_threshold_px", p.planes.vote_threshold_px,
      d.planes.vote_threshold_px);
  fix(p.planes.min_plane_support < 5, "min_plane_support", p.planes.min_plane_support,
      d.planes.min_plane_support);
  fix(p.planes.max_planes < 1, "max_planes", p.planes.max_planes, d.planes.max_planes);
  fix(!(p.target.width_m > 0), "target_width_m", p.target.width_m, d.target.width_m);
  fix(!(p.target.height_m > 0), "target_height_m", p.target.height_m, d.target.height_m);
  fix(p.pose.min_pnp_points < 6, "min_pnp_points", p.pose.min_pnp_points, d.pose.min_pnp_points);
  fix(p.map.min_points < 3, "plane_min_points", p.map.min_points, d.map.min_points);
  fix(!(p.map.max_residual_m > 0), "plane_max_residual_m", p.map.max_residual_m,
      d.map.max_residual_m);
  fix(!(p.map.fade_time_s > 0), "fade_time_s", p.map.fade_time_s, d.map.fade_time_s);
  return p;
}

}  // namespace mono_plane_detection
