#include "mono_plane_detection/mapping/pose_estimator.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>

#include "mono_plane_detection/geometry/plane_fit.h"
#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/geometry/triangulation.h"

namespace mono_plane_detection {
namespace {

cv::Vec3d unitRay(const Pose& map_from_camera, const cv::Point2d& n) {
  const cv::Vec3d r = map_from_camera.R * cv::Vec3d(n.x, n.y, 1.0);
  return r / cv::norm(r);
}

cv::Matx34d cameraFromMap(const Pose& map_from_camera) {
  const Pose c = map_from_camera.inverse();
  return projectionMatrix(c.R, c.t);
}

}  // namespace

const char* toString(PoseSource source) {
  switch (source) {
    case PoseSource::kTarget:
      return "target";
    case PoseSource::kLandmarks:
      return "landmarks";
    case PoseSource::kOdometry:
      return "odometry";
  }
  return "?";
}

const char* toString(MetricSource source) {
  switch (source) {
    case MetricSource::kNone:
      return "";
    case MetricSource::kTarget:
      return "target";
    case MetricSource::kOdometry:
      return "odometry";
    case MetricSource::kCameraHeight:
      return "camera_height";
  }
  return "?";
}

std::string metricSourceError(const std::string& choice) {
  if (choice == "target" || choice == "odometry" || choice == "camera_height" || choice == "auto")
    return {};
  return "metric_source '" + choice + "' is not target, odometry, camera_height or auto";
}

bool PoseEstimator::allows(MetricSource source) const {
  return params_.metric_source == "auto" || params_.metric_source == toString(source);
}

std::string PoseEstimator::waitingFor() const {
  if (scaleKnown()) return {};
  std::string what;
  if (allows(MetricSource::kTarget)) what = "target";
  if (allows(MetricSource::kOdometry)) what += std::string(what.empty() ? "" : " or ") + "odometry";
  if (allows(MetricSource::kCameraHeight))
    what += std::string(what.empty() ? "" : " or ") + "the floor (camera_height" +
            (floor_reason_.empty() ? "" : ": " + floor_reason_) + ")";
  return "waiting for " + (what.empty() ? std::string("target") : what);
}

PoseEstimator::PoseEstimator(const cv::Matx33d& K, const cv::Mat& distortion,
                             const PoseParams& params, const TargetParams& target)
    : K_(K), distortion_(distortion.clone()), params_(params), target_(target) {}

void PoseEstimator::reset() {
  target_ids_.clear();
  landmarks_.clear();
  last_pose_.reset();
  map_from_odom_.reset();
  initialised_ = false;
  first_view_.reset();
  start_first_stamp_ = start_target_stamp_ = -1;
  start_wait_s_ = start_target_unseen_s_ = 0;
  metric_ = MetricSource::kNone;
  floor_reason_.clear();
  floor_views_.clear();
  floor_check_.reset();
  checking_pose_.reset();
  correction_ = Similarity();
  checked_floor_ = CheckedFloor();
  keyframes_.clear();
}

std::optional<cv::Vec3d> PoseEstimator::landmarkPosition(std::uint64_t id) const {
  const auto it = landmarks_.find(id);
  if (it == landmarks_.end() || !(it->second.triangulated || it->second.fixed) ||
      it->second.provisional)
    return {};
  return it->second.position;
}

std::optional<PoseEstimate> PoseEstimator::update(const TrackFrame& frame,
                                                  const std::optional<Pose>& odom_from_camera) {
  ++image_index_;
  checking_pose_.reset();
  if (frame.ids.empty()) return {};
  // The target's corners become fixed landmarks whenever all four are tracked under new
  // ids (the first time, and when the tracker found the target again after a loss); the
  // tracker adds them in TargetDetection's order, so ascending ids give the corners.
  std::vector<std::uint64_t> corners;
  for (size_t i = 0; i < frame.ids.size(); ++i)
    if (frame.target_corner[i]) corners.push_back(frame.ids[i]);
  std::sort(corners.begin(), corners.end());
  // A map started by another source keeps its frame: a target seen later is tracked
  // like any other points (moving the map to it would move every plane already mapped).
  const bool target_counts = metric_ == MetricSource::kTarget ||
                             (metric_ == MetricSource::kNone && allows(MetricSource::kTarget));
  if (target_counts && corners.size() == 4 && corners != target_ids_) {
    const auto map_corners = targetCornersInMap(target_);
    for (int k = 0; k < 4; ++k) {
      Landmark& l = landmarks_[corners[k]];
      l.fixed = true;
      l.triangulated = false;
      l.position = cv::Vec3d(map_corners[k].x, map_corners[k].y, map_corners[k].z);
      l.last_seen = frame.stamp;
    }
    target_ids_ = corners;
    if (metric_ == MetricSource::kNone) first_view_.reset();  // a floor start's view
    metric_ = MetricSource::kTarget;
  }
  if (metric_ == MetricSource::kNone && odom_from_camera && allows(MetricSource::kOdometry)) {
    // The map is the odometry frame: poses come from it, landmarks are triangulated
    // between odometry-posed views once they have parallax (triangulate below).
    metric_ = MetricSource::kOdometry;
    map_from_odom_ = Pose{};
    initialised_ = true;
    first_view_.reset();
  }

  std::vector<cv::Point2d> normalized;
  cv::undistortPoints(frame.pixels, normalized, K_, distortion_);

  if (metric_ == MetricSource::kNone) {
    if (!allows(MetricSource::kCameraHeight)) return {};  // no metres without a source
    bool unscaled = false;
    const std::optional<PoseEstimate> start = startFromFloor(frame, normalized, unscaled);
    if (!start) return {};
    // Not given out before the floor landmarks have checked it (checkFloor).
    floor_check_ = FloorCheck{{start->map_from_camera.t}, cv::Vec3d(0, 1, 0), unscaled};
    if (unscaled) checking_pose_ = start;
    floor_reason_ = unscaled ? "started up to scale, waiting for the map's floor"
                             : "floor found, checking it against the map's floor";
    return {};
  }
  start_wait_s_ = start_target_unseen_s_ = 0;
  if (!initialised_) {  // nothing is triangulated before the start
    if (metric_ == MetricSource::kTarget) {
      bool in_view = target_ids_.size() == 4;
      for (std::uint64_t id : target_ids_)
        in_view = in_view && std::find(frame.ids.begin(), frame.ids.end(), id) != frame.ids.end();
      if (start_first_stamp_ < 0) start_first_stamp_ = frame.stamp;
      if (in_view) start_target_stamp_ = frame.stamp;
      start_wait_s_ = std::max(0.0, frame.stamp - start_first_stamp_);
      start_target_unseen_s_ = start_target_stamp_ < 0
                                   ? start_wait_s_
                                   : std::max(0.0, frame.stamp - start_target_stamp_);
    }
    const std::optional<PoseEstimate> start = initialise(frame, normalized);
    // With odometry, the start fixes where the odometry's origin sits in the map.
    if (start && odom_from_camera)
      map_from_odom_ = start->map_from_camera * odom_from_camera->inverse();
    return start;
  }
  std::optional<PoseEstimate> estimate;
  // The odometry's map is built from odometry poses: while its tf is missing, what vision
  // adds is provisional (measured: triangulating from those poses put a wall seen only
  // then 0.24 m off on the rendered wheeled sequence), and started again on its return.
  const bool was_vision_only = vision_only_;
  vision_only_ = metric_ == MetricSource::kOdometry && !odom_from_camera;
  if (was_vision_only && !vision_only_)
    restartProvisional(frame, normalized, *map_from_odom_ * *odom_from_camera);
  if (odom_from_camera && map_from_odom_)
    estimate = PoseEstimate{*map_from_odom_ * *odom_from_camera, PoseSource::kOdometry, 0, 0};
  else
    estimate = visualPose(frame, normalized);
  if (!estimate) {
    // An up-to-scale start waits for its floor as long as it takes: an image the
    // landmarks do not place (a jerk of the head) loses nothing while they are still in
    // view, as after the check (measured: humanoid noise seed 2 lost its first start
    // near image 65 this way, started again near image 85, after the front wall's best
    // views, and missed that wall). But a second of images none of which is placed (each
    // refused, e.g. as a jump from the last pose) is a loss: the start is made again.
    constexpr double kMaxUnplacedS = 1.0;
    if (floor_check_ && floor_check_->unscaled &&
        landmarksInView(frame) >= params_.min_pnp_points &&
        (floor_check_->last_placed_s < 0 ||
         frame.stamp - floor_check_->last_placed_s <= kMaxUnplacedS)) {
      floor_reason_ = "started up to scale, this image not placed: waiting for the map's floor";
      return {};
    }
    if (floor_check_) undoFloorStart("lost while checking the floor");
    return {};
  }
  if (floor_check_) floor_check_->last_placed_s = frame.stamp;
  last_pose_ = estimate->map_from_camera;
  for (size_t i = 0; i < frame.ids.size(); ++i) {
    const auto it = landmarks_.find(frame.ids[i]);
    if (it != landmarks_.end()) it->second.last_seen = frame.stamp;
  }
  triangulate(frame, normalized, estimate->map_from_camera);
  if (params_.bundle_window > 0 && estimate->source != PoseSource::kOdometry && !vision_only_)
    bundleAdjust(frame, normalized, *estimate);
  forgetOldLandmarks();
  if (floor_check_ && !checkFloor(*estimate, odom_from_camera)) {
    if (floor_check_ && floor_check_->unscaled) checking_pose_ = estimate;
    return {};
  }
  return estimate;
}

int PoseEstimator::landmarksInView(const TrackFrame& frame) const {
  int n = 0;
  for (std::uint64_t id : frame.ids) n += landmarkPosition(id).has_value();
  return n;
}

void PoseEstimator::undoFloorStart(const std::string& why) {
  landmarks_.clear();
  last_pose_.reset();
  map_from_odom_.reset();
  initialised_ = false;
  metric_ = MetricSource::kNone;
  floor_views_.clear();
  floor_check_.reset();
  floor_reason_ = why;
  keyframes_.clear();
}

bool PoseEstimator::checkFloor(PoseEstimate& estimate,
                               const std::optional<Pose>& odom_from_camera) {
  FloorCheck& check = *floor_check_;
  const FloorParams& p = params_.floor;
  check.cameras.push_back(estimate.map_from_camera.t);
  // An up-to-scale start waits for its floor without a time limit: the path kept for the
  // fit is bounded as the plane pipeline's waiting images (1000), the first one kept
  // (the map's origin lies below it).
  if (check.cameras.size() > 1000) check.cameras.erase(check.cameras.begin() + 1);
  // Motion in the start's units (near metres): the floor landmarks need views apart.
  double moved = 0;
  for (const cv::Vec3d& c : check.cameras)
    moved = std::max(moved, cv::norm(c - check.cameras.front()));
  // Up to scale the start's units are a guess: the motion is judged in the cameras'
  // height above the floor fitted (below), not in camera_height_m.
  if (!check.unscaled && moved < p.check_motion * p.camera_height_m) {
    floor_reason_ = "floor found, checking it: waiting for camera motion";
    return false;
  }
  std::vector<cv::Vec3d> points;
  std::vector<double> sigma;
  std::vector<cv::Vec3d> anchors;
  std::vector<std::uint64_t> ids;
  const double angle = 1.0 / K_(0, 0);  // a pixel
  for (const auto& [id, l] : landmarks_) {
    if (!l.triangulated || l.provisional || l.parallax_deg <= 0) continue;
    ids.push_back(id);
    points.push_back(l.position);
    anchors.push_back(l.anchor_pose.t);
    const double depth = cv::norm(l.position - l.anchor_pose.t);
    sigma.push_back(depth * angle / std::sin(l.parallax_deg * CV_PI / 180));
  }
  // Floor landmarks within 3 % of the height (the rendered floor's fit rms: 1.5 cm at 0.8 m).
  // Up to scale: the nominal up is only the camera's nominal pitch (a bobbing head's),
  // so the floor is looked for within max_floor_angle_deg of it, with tolerances as
  // shares of the cameras' height above each plane tried.
  std::vector<cv::Vec3d> cameras = check.cameras;
  FloorFit fit =
      check.unscaled
          ? fitFloorToLandmarks(points, sigma, cameras, check.start_up, p.max_floor_angle_deg, 0.03,
                                p.min_check_points, p.check_camera_sigma, true)
          : fitFloorToLandmarks(points, sigma, cameras, check.start_up, p.max_check_angle_deg,
                                0.03 * p.camera_height_m, p.min_check_points,
                                p.check_camera_sigma * p.camera_height_m);
  // Up to scale the map may have drifted in scale and orientation along the path since
  // its start (the humanoid: 190 images, a turn among them): then the whole path is not
  // parallel to the floor its end shows, and the fit with it finds no floor or one the
  // camera's height over varies. The positions the floor's landmarks were triangulated
  // from (their anchors, as drifted as the landmarks; a first fit with no weight on the
  // cameras finds those landmarks) are then the cameras that share its normal and give
  // its height: at least 5 of them, else the height test below could not fail.
  // Measured (docs/mapping.md): humanoid seed 0 distance 6.9 -> 3.4 %, seed 2 starts.
  if (check.unscaled &&
      (!fit.ok || relativeHeightSpread(fit, cameras) > 3 * p.check_camera_sigma)) {
    const FloorFit alone =
        fitFloorToLandmarks(points, sigma, check.cameras, check.start_up, p.max_floor_angle_deg,
                            0.03, p.min_check_points, 0, true);
    if (alone.ok) {
      // Each position once: landmarks of one image share their anchor.
      std::vector<cv::Vec3d> seen_from;
      for (int i : alone.inliers)
        if (std::find(seen_from.begin(), seen_from.end(), anchors[i]) == seen_from.end())
          seen_from.push_back(anchors[i]);
      constexpr size_t kMinPositions = 5;
      FloorFit again;
      if (seen_from.size() >= kMinPositions)
        again = fitFloorToLandmarks(points, sigma, seen_from, check.start_up, p.max_floor_angle_deg,
                                    0.03, p.min_check_points, p.check_camera_sigma, true);
      if (again.ok) {
        fit = std::move(again);
        cameras = std::move(seen_from);
      }
    }
  }
  if (check.unscaled) {
    // No start to undo: it waits for the floor landmarks (the camera's loss undoes it).
    if (!fit.ok || normalAngleDeg(fit.up, check.start_up) > p.max_floor_angle_deg) {
      floor_reason_ = "started up to scale, waiting for the map's floor: " +
                      (fit.ok ? std::string("too steep") : fit.reason);
      return false;
    }
    std::vector<double> heights;
    for (const cv::Vec3d& c : cameras) heights.push_back(fit.up.dot(c) - fit.offset);
    const double height = median(heights);
    // The camera stays at one height over the floor (within 3 sigma of its bobbing): a
    // plane through a few floor landmarks and others, tilted, has the path climb it.
    if (relativeHeightSpread(fit, cameras) > 3 * p.check_camera_sigma) {
      floor_reason_ =
          "started up to scale, waiting for the map's floor: the camera's "
          "height over it varies";
      return false;
    }
    if (moved < p.check_motion * height) {
      floor_reason_ = "started up to scale, floor seen: waiting for camera motion";
      return false;
    }
  } else if (!fit.ok) {
    // No floor within max_check_angle_deg of the start's: after three times the motion
    // the start was wrong (or the floor left the view), it is undone.
    if (moved > 3 * p.check_motion * p.camera_height_m)
      undoFloorStart("the map shows no floor like the start's: started again");
    else
      floor_reason_ = "floor found, checking it: " + fit.reason;
    return false;
  }
  const Similarity s = floorCorrection(fit, cameras, check.cameras.front(), p.camera_height_m);
  if (!check.unscaled && (normalAngleDeg(fit.up, check.start_up) > p.max_check_angle_deg ||
                          std::abs(s.scale - 1) > p.max_check_scale)) {
    undoFloorStart("the start's floor disagreed with the map's floor: started again");
    return false;
  }
  for (auto& [id, l] : landmarks_) {
    l.position = s.apply(l.position);
    l.anchor_pose = s.apply(l.anchor_pose);
  }
  for (Keyframe& k : keyframes_) k.map_from_camera = s.apply(k.map_from_camera);
  estimate.map_from_camera = s.apply(estimate.map_from_camera);
  last_pose_ = estimate.map_from_camera;
  correction_ = s;
  checked_floor_.ids.clear();
  for (int i : fit.inliers) checked_floor_.ids.push_back(ids[static_cast<size_t>(i)]);
  checked_floor_.image = image_index_;
  if (odom_from_camera) map_from_odom_ = estimate.map_from_camera * odom_from_camera->inverse();
  floor_check_.reset();
  floor_reason_.clear();
  return true;
}

std::optional<PoseEstimate> PoseEstimator::visualPose(const TrackFrame& frame,
                                                      const std::vector<cv::Point2d>& normalized) {
  std::vector<cv::Point3d> object;
  std::vector<cv::Point2d> image;
  std::vector<size_t> index;  // into the frame
  std::array<int, 4> target_at{-1, -1, -1, -1};
  for (size_t i = 0; i < frame.ids.size(); ++i) {
    const auto it = landmarks_.find(frame.ids[i]);
    if (it == landmarks_.end() || !(it->second.triangulated || it->second.fixed)) continue;
    for (size_t k = 0; k < target_ids_.size(); ++k)
      if (frame.ids[i] == target_ids_[k]) target_at[k] = static_cast<int>(i);
    const cv::Vec3d& x = it->second.position;
    object.emplace_back(x[0], x[1], x[2]);
    image.push_back(frame.pixels[i]);
    index.push_back(i);
  }
  const bool whole_target =
      std::all_of(target_at.begin(), target_at.end(), [](int i) { return i >= 0; });

  if (static_cast<int>(object.size()) >= params_.min_pnp_points) {
    cv::Mat rvec, tvec;
    std::vector<int> inliers;
    const bool ok = cv::solvePnPRansac(object, image, K_, distortion_, rvec, tvec, false, 100,
                                       static_cast<float>(params_.max_reprojection_px), 0.99,
                                       inliers, cv::SOLVEPNP_EPNP);
    const int needed = std::max(6, static_cast<int>(std::ceil(params_.min_inlier_share *
                                                              static_cast<double>(object.size()))));
    if (ok && static_cast<int>(inliers.size()) >= needed) {
      std::vector<cv::Point3d> obj_in;
      std::vector<cv::Point2d> img_in;
      std::vector<bool> inlier(object.size(), false);
      for (int k : inliers) {
        obj_in.push_back(object[k]);
        img_in.push_back(image[k]);
        inlier[k] = true;
      }
      cv::solvePnPRefineLM(obj_in, img_in, K_, distortion_, rvec, tvec);
      cv::Matx33d R;
      cv::Rodrigues(rvec, R);
      const Pose map_from_camera =
          Pose{R, cv::Vec3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2))}.inverse();
      const bool jumped =
          last_pose_ && cv::norm(map_from_camera.t - last_pose_->t) > params_.max_jump_m;
      if (!jumped) {
        std::vector<cv::Point2d> projected;
        cv::projectPoints(obj_in, rvec, tvec, K_, distortion_, projected);
        double sum = 0;
        for (size_t k = 0; k < projected.size(); ++k) {
          const cv::Point2d d = projected[k] - img_in[k];
          sum += d.dot(d);
        }
        // Landmarks the pose disagrees with were triangulated wrongly: start them again.
        int target_inliers = 0;
        for (size_t k = 0; k < object.size(); ++k) {
          Landmark& l = landmarks_[frame.ids[index[k]]];
          if (l.fixed) {
            target_inliers += inlier[k];
          } else if (!inlier[k]) {
            l.triangulated = false;
            l.anchor_pose = map_from_camera;
            l.anchor_normalized = normalized[index[k]];
            l.anchor_image = image_index_;
            l.provisional = vision_only_;
          }
        }
        PoseEstimate e;
        e.map_from_camera = map_from_camera;
        e.source = target_inliers == 4 ? PoseSource::kTarget : PoseSource::kLandmarks;
        e.points = static_cast<int>(inliers.size());
        e.rms_px = std::sqrt(sum / static_cast<double>(projected.size()));
        return e;
      }
    }
  }
  if (whole_target) return targetPose(frame);
  return {};
}

std::optional<PoseEstimate> PoseEstimator::targetPose(const TrackFrame& frame) const {
  TargetDetection detection;
  for (int k = 0; k < 4; ++k) {
    const auto at = std::find(frame.ids.begin(), frame.ids.end(), target_ids_[k]);
    if (at == frame.ids.end()) return {};
    detection.corners[k] = frame.pixels[static_cast<size_t>(at - frame.ids.begin())];
  }
  detection.found = true;
  const auto pose = cameraPoseFromTarget(detection, K_, distortion_, target_);
  if (!pose || pose->reprojection_error_px > 2 * params_.max_reprojection_px) return {};
  return PoseEstimate{pose->map_from_camera, PoseSource::kTarget, 4, pose->reprojection_error_px};
}

std::optional<PoseEstimate> PoseEstimator::initialise(const TrackFrame& frame,
                                                      const std::vector<cv::Point2d>& normalized) {
  // No pose is given out before the start succeeds: from one image the small target
  // places the camera only to 0.1-0.3 m (its tilt is poorly defined, two_view_init.h).
  const std::optional<PoseEstimate> own = targetPose(frame);
  if (!own) {
    first_view_.reset();  // the start needs the whole target in both views
    return {};
  }
  // This image as the start's first view, its own orientation the first of the average.
  auto startFromHere = [&] {
    first_view_ = firstView(frame, normalized);
    first_view_->rotation_sum = own->map_from_camera.R;
    first_view_->rotation_count = 1;
  };
  if (!first_view_) {
    startFromHere();
    return {};
  }
  std::unordered_map<std::uint64_t, size_t> in_first;
  for (size_t i = 0; i < first_view_->ids.size(); ++i) in_first.emplace(first_view_->ids[i], i);
  std::vector<cv::Point2d> a, b;
  std::vector<std::uint64_t> ids;
  std::array<int, 4> target{-1, -1, -1, -1};
  for (size_t i = 0; i < frame.ids.size(); ++i) {
    const auto it = in_first.find(frame.ids[i]);
    if (it == in_first.end()) continue;
    for (int k = 0; k < 4; ++k)
      if (frame.ids[i] == target_ids_[k]) target[k] = static_cast<int>(ids.size());
    ids.push_back(frame.ids[i]);
    a.push_back(first_view_->normalized[it->second]);
    b.push_back(normalized[i]);
  }
  const bool target_in_both =
      std::all_of(target.begin(), target.end(), [](int i) { return i >= 0; });
  // Start again from this image when too few of the first view's tracks survive.
  if (!target_in_both || ids.size() * 2 < first_view_->ids.size()) {
    startFromHere();
    return {};
  }
  const TargetPlaneHomography wall =
      targetPlaneHomography(a, b, target, K_(0, 0), params_.two_view);
  if (wall.ok) {
    const cv::Matx33d back = wall.H.inv();
    for (int k = 0; k < 4; ++k) {
      const cv::Vec3d p = back * cv::Vec3d(b[target[k]].x, b[target[k]].y, 1.0);
      first_view_->corner_sum[k] += cv::Point2d(p[0] / p[2], p[1] / p[2]);
    }
    ++first_view_->corner_count;
  }
  std::array<cv::Point2d, 4> corners;
  for (int k = 0; k < 4; ++k) corners[k] = first_view_->corner_sum[k] / first_view_->corner_count;
  if (wall.ok) {
    // This image's orientation from its own corners, carried back to the first view by
    // the relative rotation (the wall's homography with the first view's plane so far).
    // Seen face-on from 2 m, each image's corners fix the tilt only to 1-4 deg, and
    // carried back as corners they take on the homography's error in exactly the tilt;
    // as orientations their errors average out (docs/mapping.md, "The wheeled start's
    // tilt").
    TargetDetection d;
    d.found = true;
    for (int k = 0; k < 4; ++k)
      d.corners[k] =
          cv::Point2f(static_cast<float>(corners[k].x), static_cast<float>(corners[k].y));
    const auto first_pose = cameraPoseFromTarget(d, cv::Matx33d::eye(), cv::Mat(), target_);
    if (first_pose) {
      const Pose first_from_map = first_pose->map_from_camera.inverse();
      const cv::Vec3d n = -(first_from_map.R * cv::Vec3d(0, 0, 1));
      const double dist = n.dot(first_from_map.t);
      if (dist > 0) {
        const Pose now_from_first = motionFromPlane(wall.H, n, dist);
        first_view_->rotation_sum += own->map_from_camera.R * now_from_first.R;
        ++first_view_->rotation_count;
      }
    }
  }
  std::optional<cv::Matx33d> rotation;
  if (first_view_->rotation_count > 1) rotation = nearestRotation(first_view_->rotation_sum);
  const TwoViewInit init =
      initialiseFromTwoViews(a, b, target, K_(0, 0), target_, params_.two_view, corners, rotation);
  if (!init.ok) return {};
  first_view_.reset();
  placeStartLandmarks(frame, ids, a, b, init.points, init.points_map, init.parallax_deg,
                      init.map_from_first, init.map_from_second);
  return PoseEstimate{init.map_from_second, PoseSource::kTarget,
                      static_cast<int>(init.points.size()), 0};
}

void PoseEstimator::placeStartLandmarks(
    const TrackFrame& frame, const std::vector<std::uint64_t>& ids,
    const std::vector<cv::Point2d>& first, const std::vector<cv::Point2d>& second,
    const std::vector<int>& points, const std::vector<cv::Vec3d>& points_map, double parallax_deg,
    const Pose& map_from_first, const Pose& map_from_second) {
  for (size_t k = 0; k < points.size(); ++k) {
    Landmark& l = landmarks_[ids[points[k]]];
    l.triangulated = true;
    l.position = points_map[k];
    l.parallax_deg = parallax_deg;
    l.anchor_pose = map_from_second;
    l.anchor_normalized = second[points[k]];
    l.anchor_image = image_index_;
    l.last_seen = frame.stamp;
  }
  initialised_ = true;
  last_pose_ = map_from_second;
  std::vector<cv::Point2d> normalized;
  cv::undistortPoints(frame.pixels, normalized, K_, distortion_);
  triangulate(frame, normalized, map_from_second);  // anchors for the other tracks
  forgetOldLandmarks();
  // The start's two views are the first keyframes (the bundle adjustment's fixed pair:
  // they hold its scale).
  keyframes_.clear();
  if (params_.bundle_window > 0) {
    // (The first view's number is not kept: -2, which no landmark's anchor_image is.)
    keyframes_.push_back(Keyframe{-2, map_from_first, ids, first});
    keyframes_.push_back(Keyframe{image_index_, map_from_second, frame.ids, normalized});
  }
}

std::optional<PoseEstimate> PoseEstimator::startFromFloor(
    const TrackFrame& frame, const std::vector<cv::Point2d>& normalized, bool& unscaled) {
  unscaled = false;
  std::unordered_map<std::uint64_t, size_t> in_frame;
  for (size_t i = 0; i < frame.ids.size(); ++i) in_frame.emplace(frame.ids[i], i);
  // The tracks a kept view shares with this image: first and second view coordinates.
  struct Pair {
    std::vector<cv::Point2d> a, b;
    std::vector<std::uint64_t> ids;
  };
  auto pair = [&](const FirstView& view) {
    Pair p;
    for (size_t i = 0; i < view.ids.size(); ++i) {
      const auto it = in_frame.find(view.ids[i]);
      if (it == in_frame.end()) continue;
      p.ids.push_back(view.ids[i]);
      p.a.push_back(view.normalized[i]);
      p.b.push_back(normalized[it->second]);
    }
    return p;
  };
  // Views sharing fewer tracks than a floor needs are of no more use.
  const size_t needed = static_cast<size_t>(std::max(8, params_.floor.min_inliers));
  while (!floor_views_.empty() && pair(floor_views_.front()).ids.size() < needed)
    floor_views_.pop_front();
  // A new view is kept once the tracks have moved since the newest one (median image
  // motion of 1 % of the focal length: a still camera adds none), at most 40 of them.
  bool keep = floor_views_.empty();
  if (!keep) {
    const Pair p = pair(floor_views_.back());
    std::vector<double> moved;
    for (size_t i = 0; i < p.a.size(); ++i) moved.push_back(cv::norm(p.a[i] - p.b[i]));
    keep = moved.empty() || median(moved) >= 0.01;
  }
  std::optional<FloorStart> floor;
  Pair shared;
  std::string reason = "waiting for camera motion";
  bool floor_in_view = false;  // the oldest view's pair found a floor (confirmed or not)
  // The oldest view has the most parallax but may have lost its floor tracks: up to 4
  // views from the oldest to the newest are tried, the first that gives the floor wins.
  const size_t views = floor_views_.size(), tries = std::min<size_t>(4, views);
  for (size_t k = 0; k < tries && !floor; ++k) {
    const size_t v = tries > 1 ? k * (views - 1) / (tries - 1) : 0;
    Pair p = pair(floor_views_[v]);
    FloorStart f = floorStart(p.a, p.b, K_(0, 0), params_.floor);
    if (k == 0) {
      reason = f.reason;
      floor_in_view = f.ok || !f.floor_points.empty();
    }
    // A floor of a few tracks can be a chance plane: it must be found again, the same
    // (down within max_floor_change_deg), in `confirmations` images in a row against the
    // same view (measured on the rendered wheeled room: one pair's down scatters by about
    // 2 deg and its scale by 5 %; the humanoid's chance planes change by more).
    FirstView& view = floor_views_[v];
    if (f.ok) {
      const bool same = view.floor_count > 0 && normalAngleDeg(view.floor_down, f.down) <
                                                    params_.floor.max_floor_change_deg;
      view.floor_count = same ? view.floor_count + 1 : 1;
      view.floor_down = f.down;
      if (!same) {
        view.floor_points.clear();
        view.floor_downs.clear();
      }
      std::unordered_map<std::uint64_t, cv::Vec3d> here;
      for (size_t j = 0; j < f.point_index.size(); ++j)
        here.emplace(p.ids[f.point_index[j]], f.points[j]);
      if (view.floor_count < params_.floor.confirmations) {
        view.floor_points.push_back(std::move(here));
        view.floor_downs.push_back(f.down);
        if (k == 0)
          reason = "floor found, seen " + std::to_string(view.floor_count) + " of " +
                   std::to_string(params_.floor.confirmations) + " times";
        continue;
      }
      // One pair's scale scatters (about 5 % on the rendered room): each earlier image's
      // floor scaled the same tracks' points too; the median of those scales over this
      // pair's, and the mean of the downs, are used.
      std::vector<double> scales{1.0};
      cv::Vec3d down = f.down;
      for (size_t j = 0; j < view.floor_points.size(); ++j) {
        std::vector<double> ratios;
        for (const auto& [id, x] : here) {
          const auto it = view.floor_points[j].find(id);
          if (it != view.floor_points[j].end() && cv::norm(x) > 0)
            ratios.push_back(cv::norm(it->second) / cv::norm(x));
        }
        if (ratios.size() >= 8) scales.push_back(median(ratios));
        down += view.floor_downs[j];
      }
      const double scale = median(scales);
      f.second_from_first.t *= scale;
      f.down = down / cv::norm(down);
      view.floor_points.clear();
      view.floor_downs.clear();
      floor = std::move(f);
      shared = std::move(p);
    }
  }
  // No floor in the image between the oldest view and this one (a humanoid's head sees
  // little of it): the map starts up to scale from that pair once it has the parallax,
  // its up and scale left to the floor landmarks (checkFloor).
  if (!floor && !floor_in_view && views > 0) {
    Pair p = pair(floor_views_.front());
    FloorStart f = unscaledStart(p.a, p.b, K_(0, 0), params_.floor);
    if (f.ok) {
      unscaled = true;
      floor = std::move(f);
      shared = std::move(p);
    }
  }
  if (keep) {
    floor_views_.push_back(FirstView{frame.ids, normalized, {}, 0, frame.stamp});
    // Full: the second oldest goes, so the oldest (most parallax) stays while it can.
    if (floor_views_.size() > 40) floor_views_.erase(floor_views_.begin() + 1);
  }
  if (!floor) {
    floor_reason_ = reason;
    return {};
  }
  const std::vector<cv::Point2d>& a = shared.a;
  const std::vector<cv::Point2d>& b = shared.b;
  const std::vector<std::uint64_t>& ids = shared.ids;
  // Every track seen in both views, triangulated with the metric motion.
  const Pose map_from_first = floorMapFromCamera(floor->down, params_.floor.camera_height_m);
  const Pose map_from_second = map_from_first * floor->second_from_first.inverse();
  const cv::Matx34d P1 = projectionMatrix(cv::Matx33d::eye(), cv::Vec3d(0, 0, 0));
  const cv::Matx34d P2 = projectionMatrix(floor->second_from_first.R, floor->second_from_first.t);
  const double max_error = 6 * floor->noise_px / K_(0, 0);  // twice the RANSAC threshold
  std::vector<int> points;
  std::vector<cv::Vec3d> points_map;
  const cv::Matx33d R21 = floor->second_from_first.R;
  for (size_t i = 0; i < ids.size(); ++i) {
    // Each point needs parallax of its own: those near the direction of motion have
    // none and would put PnP off from the first image on.
    const cv::Vec3d r1(a[i].x, a[i].y, 1.0), r2 = R21.t() * cv::Vec3d(b[i].x, b[i].y, 1.0);
    const double parallax =
        std::acos(std::min(1.0, r1.dot(r2) / cv::norm(r1) / cv::norm(r2))) * 180.0 / CV_PI;
    if (parallax < params_.min_parallax_deg) continue;
    const auto p = mono_plane_detection::triangulate(P1, P2, a[i], b[i]);
    if (!p || p->depth1 < params_.min_depth_m || p->depth2 < params_.min_depth_m ||
        p->error > max_error)
      continue;
    points.push_back(static_cast<int>(i));
    points_map.push_back(map_from_first.apply(p->x));
  }
  if (static_cast<int>(points.size()) < params_.floor.min_inliers) {
    floor_reason_ = "too few tracks triangulate";
    return {};
  }
  metric_ = MetricSource::kCameraHeight;
  floor_reason_.clear();
  placeStartLandmarks(frame, ids, a, b, points, points_map, floor->parallax_deg, map_from_first,
                      map_from_second);
  floor_views_.clear();
  return PoseEstimate{map_from_second, PoseSource::kLandmarks, static_cast<int>(points.size()), 0};
}

PoseEstimator::FirstView PoseEstimator::firstView(
    const TrackFrame& frame, const std::vector<cv::Point2d>& normalized) const {
  FirstView view{frame.ids, normalized, {}, 1};
  for (size_t i = 0; i < frame.ids.size(); ++i)
    for (int k = 0; k < 4; ++k)
      if (frame.ids[i] == target_ids_[k]) view.corner_sum[k] = normalized[i];
  return view;
}

void PoseEstimator::triangulate(const TrackFrame& frame, const std::vector<cv::Point2d>& normalized,
                                const Pose& map_from_camera) {
  const double max_error = params_.max_reprojection_px / K_(0, 0);
  const cv::Matx34d P2 = cameraFromMap(map_from_camera);
  for (size_t i = 0; i < frame.ids.size(); ++i) {
    auto [it, is_new] = landmarks_.try_emplace(frame.ids[i]);
    Landmark& l = it->second;
    if (is_new) {
      l.anchor_pose = map_from_camera;
      l.anchor_normalized = normalized[i];
      l.anchor_image = image_index_;
      l.last_seen = frame.stamp;
      l.provisional = vision_only_;
      continue;
    }
    if (l.fixed) continue;
    const double parallax = normalAngleDeg(unitRay(l.anchor_pose, l.anchor_normalized),
                                           unitRay(map_from_camera, normalized[i]));
    if (parallax < params_.min_parallax_deg) continue;
    if (l.triangulated && parallax < params_.retriangulate_factor * l.parallax_deg) continue;
    const auto p = mono_plane_detection::triangulate(cameraFromMap(l.anchor_pose), P2,
                                                     l.anchor_normalized, normalized[i]);
    if (!p || p->depth1 < params_.min_depth_m || p->depth2 < params_.min_depth_m ||
        p->error > max_error)
      continue;
    l.position = p->x;
    l.triangulated = true;
    l.parallax_deg = parallax;
    if (vision_only_) l.provisional = true;
  }
}

void PoseEstimator::restartProvisional(const TrackFrame& frame,
                                       const std::vector<cv::Point2d>& normalized,
                                       const Pose& map_from_camera) {
  std::unordered_map<std::uint64_t, size_t> in_frame;
  for (size_t i = 0; i < frame.ids.size(); ++i) in_frame.emplace(frame.ids[i], i);
  for (auto it = landmarks_.begin(); it != landmarks_.end();) {
    Landmark& l = it->second;
    const auto seen = in_frame.find(it->first);
    if (!l.provisional) {
      ++it;
    } else if (seen == in_frame.end()) {
      it = landmarks_.erase(it);
    } else {
      l = Landmark();
      l.anchor_pose = map_from_camera;
      l.anchor_normalized = normalized[seen->second];
      l.anchor_image = image_index_;
      l.last_seen = frame.stamp;
      ++it;
    }
  }
}

void PoseEstimator::forgetOldLandmarks() {
  if (landmarks_.size() <= params_.max_landmarks) return;
  std::vector<std::pair<double, std::uint64_t>> by_age;
  for (const auto& [id, l] : landmarks_)
    if (!l.fixed) by_age.emplace_back(l.last_seen, id);
  std::sort(by_age.begin(), by_age.end());
  const size_t keep = params_.max_landmarks * 9 / 10;
  for (size_t k = 0; k < by_age.size() && landmarks_.size() > keep; ++k)
    landmarks_.erase(by_age[k].second);
}

}  // namespace mono_plane_detection
