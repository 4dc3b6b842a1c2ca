#include "mono_plane_detection/params/param_table.h"

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mono_plane_detection {

std::string toString(const ParamField& value) {
  return std::visit(
      [](auto* v) -> std::string {
        using T = std::remove_pointer_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>) {
          return *v ? "true" : "false";
        } else if constexpr (std::is_same_v<T, std::string>) {
          return "\"" + *v + "\"";
        } else {
          // (A NaN is "nan" whatever its sign bit: rosservice's .nan printed "-nan".)
          if constexpr (std::is_floating_point_v<T>)
            if (std::isnan(*v)) return "nan";
          std::ostringstream out;
          out << *v;
          return out.str();
        }
      },
      value);
}

std::string setFromText(const ParamField& field, const std::string& text, double min,
                        double max) {
  return std::visit(
      [&](auto* target) -> std::string {
        using T = std::remove_pointer_t<decltype(target)>;
        if constexpr (std::is_same_v<T, std::string>) {
          *target = text;
          return {};
        } else if constexpr (std::is_same_v<T, bool>) {
          if (text == "true" || text == "True" || text == "1") *target = true;
          else if (text == "false" || text == "False" || text == "0") *target = false;
          else return "'" + text + "' is not true or false";
          return {};
        } else {
          char* end = nullptr;
          const double v = std::strtod(text.c_str(), &end);
          if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v))
            return "'" + text + "' is not a number";
          if constexpr (std::is_floating_point_v<T>) {
            *target = v;
          } else {
            // Checked before the cast: a value outside the type would be undefined.
            if (v != std::floor(v) || v < min || v > max) {
              std::ostringstream why;
              why << "'" << text << "' is not a whole number in [" << min << ", " << max << "]";
              return why.str();
            }
            *target = static_cast<T>(v);
          }
          return {};
        }
      },
      field);
}

bool isNumber(const ParamField& value) {
  return !std::holds_alternative<bool*>(value) && !std::holds_alternative<std::string*>(value);
}

double numericValue(const ParamField& value) {
  return std::visit(
      [](auto* v) -> double {
        using T = std::remove_pointer_t<decltype(v)>;
        if constexpr (std::is_same_v<T, std::string>)
          return std::numeric_limits<double>::quiet_NaN();
        else
          return static_cast<double>(*v);
      },
      value);
}

// Ranges: what the algorithm accepts without an OpenCV assert, bounded above where a
// larger value only costs time (an LK window of 2001 px took 8 s per image).
const ParamTable<TrackerParams>& trackerParamTable() {
  using P = TrackerParams;
  static const ParamTable<P> table{
      {"max_features", field(&P::max_features), 1, 5000, "", "corners kept per image (paper: 50)"},
      {"min_distance_px", field(&P::min_distance_px), 0, 200, "px",
       "minimum spacing between corners (paper: 15)"},
      {"quality_level", field(&P::quality_level), 1e-6, 0.999, "",
       "corner score threshold, fraction of the strongest corner's score"},
      {"block_size", field(&P::block_size), 1, 31, "px", "corner score neighbourhood"},
      {"spread_grid_columns", field(&P::spread_grid_columns), 0, 100, "",
       "new corners go first to the cells with the fewest points, on a grid of this many "
       "columns of square cells (0: strongest in the image first, the paper)"},
      {"corner_noise_margin", field(&P::corner_noise_margin), 0, 1000, "",
       "each grid cell also takes corners above quality_level of its own strongest, never "
       "under this many times the strongest response of the image's noise (0: the image's "
       "bar alone, the paper)"},
      {"pyramid_levels", field(&P::pyramid_levels), 1, 10, "",
       "LK pyramid levels including full resolution (paper: 5)"},
      {"window_size_px", field(&P::window_size_px), 3, 51, "px",
       "LK window side (paper: 3); the cost grows with its square"},
      {"max_iterations", field(&P::max_iterations), 1, 100, "", "LK iterations per level"},
      {"epsilon_px", field(&P::epsilon_px), 1e-6, 10, "px", "LK stops when the step is below this"},
      {"min_eigen_threshold", field(&P::min_eigen_threshold), 0, 1, "",
       "LK drops points whose gradient matrix is flatter"},
      {"predict_motion", field(&P::predict_motion), 0, 1, "",
       "LK measures the image's motion on 12 points, starts the others from it on the "
       "pyramid levels its spread needs; the points this short pass loses get the full "
       "pyramid (faster; docs/benchmarks.md, eighth round)"},
      {"redetect_lost_fraction", field(&P::redetect_lost_fraction), 0, 1, "",
       "search again when this share of the last search's points is lost (paper: 2/3)"},
      {"redetect_every", field(&P::redetect_every), 1, 100000, "images",
       "search again at the latest after this many images (paper: 10)"},
      {"search_spread_images", field(&P::search_spread_images), 1, 10, "images",
       "a search's work runs over this many images: the corner response in bands of rows, "
       "the choice of corners as on the whole search image, their adoption (1: all on the "
       "search image; 5: flat frame times, but the furnished room's maps were worse)"},
      {"match_radius_px", field(&P::match_radius_px), 0, 100, "px",
       "a new corner this close to a live point is that point (paper II-D)"},
      {"forward_backward_check", field(&P::forward_backward_check), 0, 1, "",
       "track back to the previous image and drop points that do not return"},
      {"forward_backward_max_px", field(&P::forward_backward_max_px), 0, 100, "px",
       "allowed round-trip error"},
      {"reanchor_on_search", field(&P::reanchor_on_search), 0, 1, "",
       "at each search pull live points back onto their corner (bounds LK drift)"},
      {"reanchor_window_px", field(&P::reanchor_window_px), 1, 15, "px",
       "half-size of that cornerSubPix window; images need 2 x this + 5 px per side"},
      {"reanchor_max_shift_px", field(&P::reanchor_max_shift_px), 0, 100, "px",
       "larger corrections are not trusted"},
      {"mask_existing", field(&P::mask_existing), 0, 1, "",
       "no new corner within min_distance_px of a live point"},
      {"reidentify", field(&P::reidentify), 0, 1, "",
       "a lost point found again gets its old id back"},
      {"reid_memory_frames", field(&P::reid_memory_frames), 0, 100000, "images",
       "how long a lost point is remembered"},
      {"reid_max_hamming", field(&P::reid_max_hamming), 0, 256, "bits",
       "ORB descriptor distance to accept, of 256"},
      {"reid_ratio", field(&P::reid_ratio), 0, 1, "",
       "best / second-best descriptor distance must be below this"},
      {"reid_max_radius_px", field(&P::reid_max_radius_px), 0, 1000, "px",
       "how far from its expected place a lost point may come back"},
  };
  return table;
}

const ParamTable<TargetParams>& targetParamTable() {
  using P = TargetParams;
  static const ParamTable<P> table{
      {"width_m", field(&P::width_m), 0.01, 10, "m",
       "start-up target's white rectangle, the longer side", "target_width_m"},
      {"height_m", field(&P::height_m), 0.01, 10, "m", "its shorter side", "target_height_m"},
      {"target_type", field(&P::target_type), 0, 0, "",
       "start-up target: sheet (white sheet on a darker surface) or aruco (fiducial marker)"},
      {"min_area_px", field(&P::min_area_px), 1, 1e8, "px^2", "smaller candidates are ignored"},
      {"max_surround_ratio", field(&P::max_surround_ratio), 0.01, 1, "",
       "sheet: surround over sheet brightness along its outline (median), at most"},
      {"dark_surround_ratio", field(&P::dark_surround_ratio), 0, 1, "",
       "sheet: at or below this surround/sheet ratio the surround vouches for the sheet; "
       "above it (a wall, a light table) its corners must also fix its shape "
       "(corner_sigma_px)"},
      {"min_edge_snr", field(&P::min_edge_snr), 0, 1000, "",
       "sheet: each side's brightness step in noise standard deviations, at least"},
      {"max_aspect_error", field(&P::max_aspect_error), 0.001, 1, "",
       "sheet: rectified width/height vs width_m/height_m, relative error allowed (paper, "
       "calibration, corners)"},
      {"corner_sigma_px", field(&P::corner_sigma_px), 0, 10, "px",
       "sheet: how far a found corner may be off; on a light surround a candidate whose "
       "width/height this moves by more than max_aspect_error is too small or oblique to be "
       "judged, and refused"},
      {"dictionary", field(&P::dictionary), 0, 0, "",
       "aruco: OpenCV predefined dictionary (DICT_4X4_50, DICT_6X6_250, ...)"},
      {"marker_id", field(&P::marker_id), 0, 999, "", "aruco: the marker's id"},
      {"marker_size_m", field(&P::marker_size_m), 0.005, 10, "m",
       "aruco: printed side of the black square"},
      {"confirm_frames", field(&P::confirm_frames), 1, 1000, "",
       "consecutive images with consistently tracked corners before the target fixes the map"},
      {"confirm_tolerance_px", field(&P::confirm_tolerance_px), 0.01, 100, "px",
       "detected vs Lucas-Kanade-tracked corner, largest distance, to count as consistent"},
      {"redetect_tracked", field(&P::redetect_tracked), 0, 1, "",
       "tracker: after confirmation, find the target again in each image and move its tracked "
       "corners onto the detected ones (same ids) when they agree within confirm_tolerance_px"},
  };
  return table;
}

const ParamTable<GroupParams>& groupParamTable() {
  using P = GroupParams;
  static const ParamTable<P> table{
      {"max_groups", field(&P::max_groups), 1, 100000, "",
       "coplanar groups kept per image (bounds the time)", "max_groups"},
      {"groups_per_point", field(&P::groups_per_point), 1, 1000, "",
       "fewer points, fewer groups (max_groups still caps)"},
      {"max_tries", field(&P::max_tries), 1, 10000000, "", "groups tried per image at most",
       "max_tries"},
      {"tries_per_point", field(&P::tries_per_point), 1, 100000, "",
       "fewer points, fewer tries (max_tries still caps)"},
      {"min_tries", field(&P::min_tries), 0, 10000000, "",
       "but at least this many tries (few points need them)"},
      {"max_seeds", field(&P::max_seeds), 1, 1000000, "",
       "seed points with a neighbour list (bounds memory)"},
      {"neighbours", field(&P::neighbours), 4, 1000, "",
       "a group is a seed and 4 of its nearest neighbours"},
      {"fifth_points", field(&P::fifth_points), 1, 100, "",
       "groups per four points drawn: the seed's other neighbours as the fifth point"},
      {"min_neighbour_distance_px", field(&P::min_neighbour_distance_px), 0, 100000, "px",
       "closer neighbours are passed over (invariant noise grows as the group shrinks)"},
      {"min_shape", field(&P::min_shape), 0, 1, "",
       "triangle shape below this is collinear (paper IV-A)"},
      {"coplanarity_test", field(&P::coplanarity_test), 0, 0, "",
       "five-point test: transfer (fifth point under the other four's homography, in noise "
       "scales) or cross_ratio (paper IV-B)"},
      {"transfer_threshold_sigma", field(&P::transfer_threshold_sigma), 0.1, 1000, "sigma",
       "transfer test: the fifth point within this many noise scales"},
      {"invariant_threshold", field(&P::invariant_threshold), 1e-6, 10, "",
       "cross_ratio test: five-point invariants equal within this (relative)",
       "invariant_threshold"},
      {"seed", field(&P::seed), 0, 4294967295.0, "", "random choices are repeatable", "group_seed"},
  };
  return table;
}

// The noise scale estimate's bounds (planes/noise_scale.h); a part of the plane table.
static const ParamTable<NoiseScaleParams>& noiseScaleParamTable() {
  using P = NoiseScaleParams;
  static const ParamTable<P> table{
      {"min_inliers", field(&P::min_inliers), 5, 100000, "",
       "the noise scale rests on at least this many points"},
      {"stop_sigmas", field(&P::stop_sigmas), 1, 20, "sigma",
       "noise estimate (MSSE): a residual beyond this many scales is not an inlier"},
      {"tail_sigmas", field(&P::tail_sigmas), 1, 50, "sigma",
       "noise estimate (median scale): heavy-tailed residuals count up to this many scales"},
      {"min_sigma_px", field(&P::min_sigma_px), 0.001, 100, "px",
       "the estimated noise scale is at least this"},
      {"max_sigma_px", field(&P::max_sigma_px), 0.001, 1000, "px", "and at most this"},
  };
  return table;
}

const ParamTable<PlaneParams>& planeParamTable() {
  using P = PlaneParams;
  static const ParamTable<P> table = [] {
    ParamTable<P> t{
        {"vote_threshold_px", field(&P::vote_threshold_px), 0, 100, "px",
         "transfer error below which a point votes / belongs; 0: inlier_threshold_sigma x the "
         "noise scale estimated per image pair (paper: 2 fixed)",
         "vote_threshold_px"},
        {"inlier_threshold_sigma", field(&P::inlier_threshold_sigma), 0.5, 50, "sigma",
         "estimated scale: a point belongs to a plane within this many of the plane's own "
         "noise scales"},
        {"vote_threshold_sigma", field(&P::vote_threshold_sigma), 0.5, 50, "sigma",
         "estimated scale: the vote counts within this many of the image pair's noise scales "
         "(fixed threshold: the threshold is this many noise scales)"},
        {"plane_penalty", field(&P::plane_penalty), 0, 1000, "sigma^2",
         "model selection (add, drop, split, merge): a plane costs this x ln(points) squared "
         "noise scales"},
        {"min_plane_support", field(&P::min_plane_support), 5, 100000, "",
         "points a plane needs", "min_plane_support"},
        {"max_planes", field(&P::max_planes), 1, 1000, "", "planes per image at most",
         "max_planes"},
        {"refit_iterations", field(&P::refit_iterations), 0, 100, "",
         "refit on inliers / recompute inliers rounds"},
        {"robust_refit", field(&P::robust_refit), 0, 1, "", "Cauchy re-weighting in the refit"},
        {"noise_pilot_groups", field(&P::noise_pilot_groups), 1, 10000, "",
         "candidate first planes the noise scale is estimated from"},
        {"epipolar_check", field(&P::epipolar_check), 0, 1, "",
         "F from the planes' points: drop planes off it, use its homographies when cheaper"},
    };
    appendNested(t, "groups/", &P::groups, groupParamTable());
    appendNested(t, "noise/", &P::noise, noiseScaleParamTable());
    return t;
  }();
  return table;
}

const ParamTable<TwoViewParams>& twoViewParamTable() {
  using P = TwoViewParams;
  static const ParamTable<P> table{
      {"min_parallax_deg", field(&P::min_parallax_deg), 0.01, 90, "deg",
       "median parallax before the two-view metric start", "start_parallax_deg"},
      {"min_inliers", field(&P::min_inliers), 4, 100000, "", "tracks on the target's plane needed"},
      {"max_error_px", field(&P::max_error_px), 0.01, 100, "px",
       "homography RANSAC threshold, triangulation check / 2"},
      {"max_target_error_px", field(&P::max_target_error_px), 0.01, 1000, "px",
       "target corners transferred by the target's plane"},
  };
  return table;
}

const ParamTable<PoseParams>& poseParamTable() {
  using P = PoseParams;
  static const ParamTable<P> table = [] {
    ParamTable<P> t{
        {"min_parallax_deg", field(&P::min_parallax_deg), 0.01, 90, "deg",
         "a track is triangulated once its two rays differ this much", "min_parallax_deg"},
        {"retriangulate_factor", field(&P::retriangulate_factor), 1, 100, "",
         "and again each time its parallax grows by this factor"},
        {"max_reprojection_px", field(&P::max_reprojection_px), 0.01, 100, "px",
         "PnP inlier threshold and triangulation check", "max_reprojection_px"},
        {"min_pnp_points", field(&P::min_pnp_points), 6, 100000, "",
         "mapped points needed to place the camera without the target", "min_pnp_points"},
        {"min_inlier_share", field(&P::min_inlier_share), 0, 1, "",
         "of the landmarks in view, else the PnP pose is refused"},
        {"max_jump_m", field(&P::max_jump_m), 0.001, 1000, "m",
         "a PnP pose further than this from the last one is refused"},
        {"min_depth_m", field(&P::min_depth_m), 0, 1000, "m",
         "triangulated points must be this far in front of both views"},
        {"max_landmarks", field(&P::max_landmarks), 1, 10000000, "",
         "least recently seen 3D points dropped beyond this", "max_landmarks"},
        {"metric_source", field(&P::metric_source), 0, 0, "",
         "where the metres come from: target, odometry (tf odom_frame -> camera; the map is "
         "the odometry frame), camera_height (the floor lies camera_height_m below the "
         "camera) or auto (the first of them available)"},
        {"camera_height_m", [](P& p) -> ParamField { return &p.floor.camera_height_m; }, 0, 100,
         "m", "camera_height: the optical centre's height above the floor (0: unknown)"},
        {"camera_pitch_deg", [](P& p) -> ParamField { return &p.floor.pitch_down_deg; }, -90, 90,
         "deg", "camera_height: nominal camera tilt below the horizon, to tell the floor"},
        {"floor_max_angle_deg", [](P& p) -> ParamField { return &p.floor.max_floor_angle_deg; }, 1,
         89, "deg",
         "camera_height: the floor's normal is within this of the nominal down direction"},
        {"bundle_window", field(&P::bundle_window), 0, 30, "",
         "keyframes refined together with their landmarks at each new keyframe (local bundle "
         "adjustment, the oldest two fixed; 0: off; 1-3 all mean 3, one free keyframe; at "
         "most 30: a dense solve in the image callback, 20 took 4-27 ms per keyframe)"},
    };
    appendNested(t, "two_view/", &P::two_view, twoViewParamTable());
    return t;
  }();
  return table;
}

const ParamTable<MapParams>& mapParamTable() {
  using P = MapParams;
  static const ParamTable<P> table{
      {"max_residual_m", field(&P::max_residual_m), 1e-4, 10, "m",
       "a 3D point belongs to a plane within this distance", "plane_max_residual_m"},
      {"min_points", field(&P::min_points), 3, 100000, "",
       "3D points needed to put a plane into the map", "plane_min_points"},
      {"min_share", field(&P::min_share), 0, 1, "",
       "and this share of the image plane's 3D points", "plane_min_share"},
      {"max_angle_deg", field(&P::max_angle_deg), 0, 90, "deg",
       "an observation joins a mapped plane within this angle", "associate_max_angle_deg"},
      {"max_offset_m", field(&P::max_offset_m), 0, 100, "m",
       "and this distance (also the merge rule)", "associate_max_offset_m"},
      {"min_shared_ids", field(&P::min_shared_ids), 0, 1, "",
       "or this share of the observation's tracks already on the plane"},
      {"confirm_observations", field(&P::confirm_observations), 1, 10000, "",
       "a plane is confirmed after observations from this many viewpoints",
       "confirm_observations"},
      {"view_spacing", field(&P::view_spacing), 0, 10, "",
       "an observation counts only from this share of the plane's distance away from the "
       "viewpoints counted before"},
      {"coplanar_sigmas", field(&P::coplanar_sigmas), 0.1, 100, "",
       "a 3D point is on a plane within this many standard deviations of its depth"},
      {"min_residual_m", field(&P::min_residual_m), 0, 10, "m",
       "the coplanarity tolerance of a perfectly triangulated point"},
      {"max_point_sigma_m", field(&P::max_point_sigma_m), 0, 10, "m",
       "points less certain across a plane than this do not test it"},
      {"max_normal_sigma_deg", field(&P::max_normal_sigma_deg), 0, 180, "deg",
       "and only once its points fix its normal to this (1 sigma)"},
      {"min_gap_m", field(&P::min_gap_m), 0, 100, "m",
       "a plane's points in two groups this far apart, one not that plane alone: refused"},
      {"structure_sigmas", field(&P::structure_sigmas), 0, 10, "",
       "a plane is held at right angles to or parallel to better-known confirmed planes "
       "while its points do not reject that at this many standard deviations (0: off)"},
      {"up_sigma_deg", field(&P::up_sigma_deg), 0, 10, "deg",
       "how far the map's up (the target's y hung landscape on a wall, the odometry's z; "
       "taken when the map's first camera stands upright along it) may be from the room's "
       "vertical, 1 sigma: planes known worse are held level or upright by it while their "
       "points allow (0.2: target hung with a spirit level; by eye 0.5; 0 or from "
       "map/max_normal_sigma_deg on: no effect)"},
      {"tentative_timeout_s", field(&P::tentative_timeout_s), 0, 1e6, "s",
       "unconfirmed planes unseen for this long are removed", "tentative_timeout_s"},
      {"fade_time_s", field(&P::fade_time_s), 1e-3, 1e6, "s",
       "confidence decays as exp(-unseen / fade_time_s)", "fade_time_s"},
      {"max_planes", field(&P::max_planes), 1, 10000, "",
       "the least confident plane is removed beyond this", "max_map_planes"},
      {"max_points_per_plane", field(&P::max_points_per_plane), 3, 1000000, "",
       "least recently seen points of a plane dropped beyond this", "max_points_per_plane"},
  };
  return table;
}

const ParamTable<PipelineParams>& pipelineParamTable() {
  using P = PipelineParams;
  static const ParamTable<P> table = [] {
    ParamTable<P> t{
        {"frame_gap", field(&P::frame_gap), 1, 1000, "images",
         "without intrinsics: homographies map the image this many images back to this one"},
        {"keyframe_parallax_px", field(&P::keyframe_parallax_px), 0, 1000, "px",
         "the reference image is the most recent one with this much rotation-free parallax"},
        {"min_parallax_px", field(&P::min_parallax_px), 0, 1000, "px",
         "less to every image within reach (pure rotation, standing still): no planes"},
        {"max_keyframe_age", field(&P::max_keyframe_age), 1, 1000, "images",
         "images kept to choose the reference from"},
        {"min_keyframe_shared", field(&P::min_keyframe_shared), 0, 1, "",
         "share of this image's tracks a reference must still hold"},
        {"max_gap_s", field(&P::max_gap_s), 1e-3, 1e6, "s",
         "a longer pause between tracks messages (and over 3 of their periods; 3 x this "
         "before the first 3) is a tracking loss"},
        {"motion_plane_images", field(&P::motion_plane_images), 0, 1000, "images",
         "an image plane with too few landmarks: a plane from its tracks' motion and the "
         "known poses, mapped after this many fits once its normal is known to "
         "map/max_normal_sigma_deg (0: off; only for odometry right at the centimetre "
         "scale, docs/mapping.md)"},
    };
    appendNested(t, "planes/", &P::planes, planeParamTable());
    appendNested(t, "pose/", &P::pose, poseParamTable());
    appendNested(t, "map/", &P::map, mapParamTable());
    appendNested(t, "target/", &P::target, targetParamTable());
    return t;
  }();
  return table;
}

const ParamTable<TrackerNodeParams>& trackerNodeParamTable() {
  using P = TrackerNodeParams;
  static const ParamTable<P> table = [] {
    ParamTable<P> t;
    appendNested(t, "", &P::tracker, trackerParamTable());
    appendNested(t, "target/", &P::target, targetParamTable());
    t.push_back({"lazy", field(&P::lazy), 0, 1, "",
                 "subscribe to the image only while tracks or debug_image have listeners"});
    t.push_back({"detect_target", field(&P::detect_target), 0, 1, "",
                 "look for the start-up target (paper II-A) until found, then around its "
                 "tracked corners (target/redetect_tracked); false: neither"});
    t.push_back({"rectified", field(&P::rectified), 0, 1, "",
                 "the images are rectified: camera_info's P, no distortion, for the start-up "
                 "target (also when the image topic is image_rect*)"});
    t.push_back({"max_gap_s", field(&P::max_gap_s), 1e-3, 1e6, "s",
                 "a longer pause between images (and over 3 of their periods; 3 x this before "
                 "the first 3) is a tracking loss (start over)"});
    t.push_back({"target_timeout_s", field(&P::target_timeout_s), 0.1, 1e6, "s",
                 "diagnostics WARN (with the reason) when images arrive this long without a "
                 "start-up target"});
    t.push_back({"image_transport", field(&P::image_transport), 0, 0, "",
                 "image_transport hint for the image"});
    t.push_back({"expected_min_rate_hz", field(&P::expected_min_rate_hz), 0, 1e6, "Hz",
                 "diagnostics: an input rate below this is a warning"});
    t.push_back({"expected_max_rate_hz", field(&P::expected_max_rate_hz), 0, 1e6, "Hz",
                 "diagnostics: an input rate above this is a warning"});
    return t;
  }();
  return table;
}

const ParamTable<PlaneNodeParams>& planeNodeParamTable() {
  using P = PlaneNodeParams;
  static const ParamTable<P> table = [] {
    ParamTable<P> t;
    appendNested(t, "", &P::pipeline, pipelineParamTable());
    t.push_back({"map_frame", field(&P::map_frame), 0, 0, "",
                 "the map's frame: z up (REP 103), origin at the start-up target"});
    t.push_back({"odom_frame", field(&P::odom_frame), 0, 0, "",
                 "set (e.g. odom) to take the camera pose from tf odom -> camera"});
    t.push_back({"publish_tf", field(&P::publish_tf), 0, 1, "",
                 "tf: map_frame -> odom_frame, odom_frame -> map_frame, or map_frame -> "
                 "camera_frame (tf_mode)"});
    t.push_back({"tf_mode", field(&P::tf_mode), 0, 0, "",
                 "with odom_frame: above_odom (map_frame -> odom_frame), below_odom "
                 "(odom_frame -> map_frame: another localiser owns the odom frame's parent) "
                 "or auto (below_odom when odom_frame already has a parent)"});
    t.push_back({"camera_frame", field(&P::camera_frame), 0, 0, "",
                 "without odom_frame: the camera estimate's own frame, a child of map_frame "
                 "(\"\": the tracks' frame_id + _estimate)"});
    t.push_back({"rectified", field(&P::rectified), 0, 1, "",
                 "the tracks are of rectified images: camera_info's P, no distortion (also "
                 "when the image topic is image_rect*)"});
    t.push_back({"target_timeout_s", field(&P::target_timeout_s), 0, 1e6, "s",
                 "diagnostics: waiting longer than this for the start-up target is a warning"});
    t.push_back({"image_transport", field(&P::image_transport), 0, 0, "",
                 "image_transport hint for the debug image's background"});
    t.push_back({"max_odom_jump_m", field(&P::max_odom_jump_m), 1e-3, 1e6, "m",
                 "an odometry move larger than this between two tracks messages is refused "
                 "(the visual pose is used)"});
    t.push_back({"odom_wait_s", field(&P::odom_wait_s), 0, 1, "s",
                 "with odom_frame: how long tracks wait (steady clock) for odometry at "
                 "their stamp, more than the odometry's period plus its lag (10 Hz odometry "
                 "50 ms late: 0.15 s); after one wait in vain the next tracks do not wait "
                 "until tf's odometry is within this of an image again (0: never wait)"});
    t.push_back({"expected_min_rate_hz", field(&P::expected_min_rate_hz), 0, 1e6, "Hz",
                 "diagnostics: a tracks rate below this is a warning"});
    t.push_back({"expected_max_rate_hz", field(&P::expected_max_rate_hz), 0, 1e6, "Hz",
                 "diagnostics: a tracks rate above this is a warning"});
    return t;
  }();
  return table;
}

const std::vector<std::string>& planeRuntimeParamNames() {
  // Only what PlanePipeline reads on every image (setPerImageParams): the map, pose and
  // target parameters are held by objects made once.
  static const std::vector<std::string> names{
      "frame_gap",
      "max_gap_s",
      "planes/vote_threshold_px",
      "planes/min_plane_support",
      "planes/max_planes",
      "planes/refit_iterations",
      "planes/robust_refit",
      "planes/inlier_threshold_sigma",
      "planes/vote_threshold_sigma",
      "planes/plane_penalty",
      "planes/epipolar_check",
      "planes/groups/max_groups",
      "planes/groups/max_tries",
      "planes/groups/min_neighbour_distance_px",
      "planes/groups/min_shape",
      "planes/groups/invariant_threshold",
      "planes/groups/transfer_threshold_sigma",
  };
  return names;
}

std::string runtimeCfgName(const std::string& table_name) {
  std::string name = table_name;
  for (char& c : name)
    if (c == '/') c = '_';
  return name;
}

const std::vector<std::string>& trackerRuntimeParamNames() {
  // What FeatureTracker::setParams takes between images: the corner search, its triggers,
  // Lucas-Kanade's stopping rules and checks, re-identification. Not the pyramid's levels
  // nor the windows, which size the pyramids and the smallest image (a change of those
  // needs a restart), nor the target's (its detector is made once).
  static const std::vector<std::string> names{
      "max_features",
      "min_distance_px",
      "quality_level",
      "block_size",
      "spread_grid_columns",
      "corner_noise_margin",
      "max_iterations",
      "epsilon_px",
      "min_eigen_threshold",
      "predict_motion",
      "redetect_lost_fraction",
      "redetect_every",
      "search_spread_images",
      "match_radius_px",
      "forward_backward_check",
      "forward_backward_max_px",
      "reanchor_on_search",
      "reanchor_max_shift_px",
      "mask_existing",
      "reidentify",
      "reid_memory_frames",
      "reid_max_hamming",
      "reid_ratio",
      "reid_max_radius_px",
  };
  return names;
}

namespace {

// The shortest text that reads back as the same double (2/3 printed with 6 digits read
// back as another value: the .cfg's default would not be the table's).
std::string exactText(double value) {
  for (int digits = 6;; ++digits) {
    std::ostringstream text;
    text << std::setprecision(digits) << value;
    if (digits >= 17 || std::stod(text.str()) == value) return text.str();
  }
}

// What a .cfg file says of itself and where it goes.
struct CfgFile {
  std::string nodelet;  // the class, for the header comment
  std::string node;     // gen.generate's node name
  std::string when;     // when its values are taken
  std::string name;     // cfg/<name>.cfg, the <name>Config class
  std::string flag;     // param_table's flag that prints it
  std::string test;     // the test that checks it
  std::string example;  // a name with '/' and its .cfg form
};

// A dynamic_reconfigure .cfg for the runtime parameters `names` of one nodelet's table.
template <typename P>
std::string reconfigureCfg(const ParamTable<P>& table, const std::vector<std::string>& names,
                           const CfgFile& file) {
  std::ostringstream out;
  out << "#!/usr/bin/env python3\n"
         "# "
      << file.nodelet << "'s parameters that can change while it runs (" << file.when
      << ").\n"
         "# Generated from the parameter table (src/params/param_table.cpp) by\n"
         "# `rosrun mono_plane_detection param_table "
      << file.flag << " > cfg/" << file.name
      << ".cfg`; do not edit by\n"
         "# hand ("
      << file.test
      << " fails when this file is out of date). Each name is the\n"
         "# table's with '/' -> '_' ("
      << file.example
      << ").\n"
         "PACKAGE = \"mono_plane_detection\"\n\n"
         "from dynamic_reconfigure.parameter_generator_catkin import ParameterGenerator, "
         "bool_t, double_t, int_t\n\n"
         "gen = ParameterGenerator()\n";
  P defaults;
  for (const std::string& name : names) {
    const ParamSpec<P>* spec = findParam(table, name);
    if (!spec) throw std::logic_error("runtime parameter " + name + " is not in the table");
    const ParamField value = spec->field(defaults);
    std::string description = spec->description + (spec->unit.empty() ? "" : " (" + spec->unit + ")");
    for (char& c : description)
      if (c == '"') c = '\'';
    out << "gen.add(\"" << runtimeCfgName(name) << "\", ";
    std::visit(
        [&](auto* v) {
          using T = std::remove_pointer_t<decltype(v)>;
          if constexpr (std::is_same_v<T, bool>) {
            out << "bool_t, 0, \"" << description << "\", " << (*v ? "True" : "False");
          } else if constexpr (std::is_same_v<T, double>) {
            out << "double_t, 0, \"" << description << "\", " << exactText(*v) << ", "
                << exactText(spec->min) << ", " << exactText(spec->max);
          } else if constexpr (std::is_same_v<T, std::string>) {
            throw std::logic_error("string parameter " + name + " is not for dynamic_reconfigure");
          } else {
            out << "int_t, 0, \"" << description << "\", " << *v << ", "
                << static_cast<long long>(spec->min) << ", " << static_cast<long long>(spec->max);
          }
        },
        value);
    out << ")\n";
  }
  out << "\nexit(gen.generate(PACKAGE, \"" << file.node << "\", \"" << file.name << "\"))\n";
  return out.str();
}

}  // namespace

std::string dynamicReconfigureCfg() {
  CfgFile file;
  file.nodelet = "PlaneNodelet";
  file.node = "plane_nodelet";
  file.when = "read on every image";
  file.name = "Planes";
  file.flag = "--cfg";
  file.test = "test_planes_cfg";
  file.example = "planes/vote_threshold_px: planes_vote_threshold_px";
  return reconfigureCfg(planeNodeParamTable(), planeRuntimeParamNames(), file);
}

std::string trackerReconfigureCfg() {
  CfgFile file;
  file.nodelet = "TrackerNodelet";
  file.node = "tracker_nodelet";
  file.when = "taken between images";
  file.name = "Tracker";
  file.flag = "--tracker-cfg";
  file.test = "test_planes_cfg's TrackerCfg";
  file.example = "none of these has one";
  return reconfigureCfg(trackerNodeParamTable(), trackerRuntimeParamNames(), file);
}

std::string parametersMarkdown() {
  std::ostringstream out;
  out << "# Parameters\n\n"
         "Generated from the parameter tables (`src/params/param_table.cpp`) by\n"
         "`rosrun mono_plane_detection param_table --markdown > docs/parameters.md`; do not\n"
         "edit by hand (`test_param_table` fails when this file is out of date).\n\n"
         "Each parameter is declared once: its default is the Params struct's default member\n"
         "initializer, its range, unit and meaning are in the table. The ROS name is the\n"
         "table name in the nodelet's private namespace (a `/` is a nested YAML map:\n"
         "`map/max_residual_m` is `map: {max_residual_m: ...}`). A value out of range, or of\n"
         "the wrong type, is an ERROR naming parameter, value and range, and the default is\n"
         "used. Names of earlier versions (shown as \"was\") still work, with a warning.\n"
         "Profiles (`config/*_wheeled.yaml`, `config/*_humanoid.yaml`) are overlays of these\n"
         "names. The tools read the same files through the same tables: `run_pipeline\n"
         "--profile P` (default: the trajectory's profile) and `segment_planes --profile P`\n"
         "(default `none`: the core's defaults; `default` is `config/planes.yaml` alone).\n"
         "Those marked **live** can also change while the nodelet runs (dynamic_reconfigure:\n"
         "`cfg/Tracker.cfg`, `cfg/Planes.cfg`, where a `/` is a `_`; docs/ros_interface.md).\n\n"
         "## TrackerNodelet (`config/tracker.yaml`)\n\n"
      << toMarkdown(trackerNodeParamTable(), trackerRuntimeParamNames())
      << "\n## PlaneNodelet (`config/planes.yaml`)\n\n"
      << toMarkdown(planeNodeParamTable(), planeRuntimeParamNames());
  return out.str();
}

namespace {

template <class P>
void checkRateWindow(P& p, std::vector<std::string>& errors) {
  if (p.expected_min_rate_hz <= p.expected_max_rate_hz) return;
  std::ostringstream why;
  const P d;
  why << "expected_min_rate_hz = " << p.expected_min_rate_hz << " is above expected_max_rate_hz = "
      << p.expected_max_rate_hz << "; using the defaults " << d.expected_min_rate_hz << " and "
      << d.expected_max_rate_hz;
  errors.push_back(why.str());
  p.expected_min_rate_hz = d.expected_min_rate_hz;
  p.expected_max_rate_hz = d.expected_max_rate_hz;
}

}  // namespace

std::vector<std::string> validate(TrackerParams& params) {
  return validate(params, trackerParamTable());
}

std::vector<std::string> validate(PipelineParams& params) {
  return validate(params, pipelineParamTable());
}

// Names the table cannot range-check: target_type, dictionary, marker_id within it.
static void checkTargetNames(TargetParams& p, std::vector<std::string>& errors) {
  const std::string error = targetParamsError(p);
  if (error.empty()) return;
  const TargetParams d;
  errors.push_back("target/" + error + "; using the defaults target_type " + d.target_type +
                   ", dictionary " + d.dictionary + ", marker_id " + std::to_string(d.marker_id));
  p.target_type = d.target_type;
  p.dictionary = d.dictionary;
  p.marker_id = d.marker_id;
}

std::vector<std::string> validate(TrackerNodeParams& params) {
  auto errors = validate(params, trackerNodeParamTable());
  checkRateWindow(params, errors);
  checkTargetNames(params.target, errors);
  return errors;
}

// A metric source that cannot work says so at start rather than waiting for ever.
static void checkMetricSource(PlaneNodeParams& p, std::vector<std::string>& errors) {
  PoseParams& pose = p.pipeline.pose;
  if (const std::string error = metricSourceError(pose.metric_source); !error.empty()) {
    errors.push_back("pose/" + error + "; using target");
    pose.metric_source = "target";
  }
  if (const std::string problem = metricSourceProblem(p); !problem.empty())
    errors.push_back(problem);
}

std::string metricSourceProblem(const PlaneNodeParams& p) {
  const PoseParams& pose = p.pipeline.pose;
  if (pose.metric_source == "odometry" && p.odom_frame.empty())
    return "pose/metric_source odometry needs odom_frame: no metres until it is set";
  if (pose.metric_source == "camera_height" && !(pose.floor.camera_height_m > 0))
    return "pose/metric_source camera_height needs pose/camera_height_m > 0: no metres until set";
  return {};
}

// tf frame names the table cannot check: tf2 refuses a leading '/', an empty map frame
// would put the map on tf as "" and a map frame equal to the odometry or camera frame
// would make a link from a frame to itself.
static void checkFrames(PlaneNodeParams& p, std::vector<std::string>& errors) {
  for (std::string* frame : {&p.map_frame, &p.odom_frame, &p.camera_frame})
    if (!frame->empty() && frame->front() == '/') {
      errors.push_back("frame '" + *frame + "' starts with '/', which tf2 refuses; using '" +
                       frame->substr(1) + "'");
      frame->erase(0, 1);
    }
  if (p.map_frame.empty() || p.map_frame == p.odom_frame || p.map_frame == p.camera_frame) {
    // The default, unless that is the other frame's name too (odom_frame: plane_map).
    std::string fallback = PlaneNodeParams().map_frame;
    while (fallback == p.odom_frame || fallback == p.camera_frame) fallback += "_mono";
    errors.push_back("map_frame = '" + p.map_frame + "' " +
                     (p.map_frame.empty() ? std::string("is empty")
                                          : "is also the " + std::string(p.map_frame == p.odom_frame
                                                                             ? "odom_frame"
                                                                             : "camera_frame")) +
                     "; using '" + fallback + "'");
    p.map_frame = fallback;
  }
}

std::vector<std::string> validate(PlaneNodeParams& params) {
  auto errors = validate(params, planeNodeParamTable());
  checkFrames(params, errors);
  checkRateWindow(params, errors);
  checkTargetNames(params.pipeline.target, errors);
  checkMetricSource(params, errors);
  return errors;
}

}  // namespace mono_plane_detection
