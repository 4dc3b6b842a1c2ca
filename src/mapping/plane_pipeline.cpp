#include "mono_plane_detection/mapping/plane_pipeline.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <sstream>
#include <unordered_map>
#include <unordered_set>

#include "mono_plane_detection/mapping/plane_from_motion.h"

namespace mono_plane_detection {
namespace {

// A camera whose image up is within this of the map's +y at the map's first placed image
// stands upright along it (robot cameras are mounted upright, pitched less than this); a
// sheet on the floor seen by such a camera is 90 deg - its pitch away.
constexpr double kUprightCameraMaxDeg = 45.0;

// Images between two odometry checks (odometry_check.h): a misconfigured odometry is
// wrong in every image, so a check every sixth of a second at 30 Hz finds it within 2 s.
constexpr long kOdometryCheckEvery = 5;

// (Below.) The median image motion the best rotation between two images leaves.
double rotationFreeParallax(const std::vector<cv::Vec3d>& a, const std::vector<cv::Vec3d>& b);

double jaccard(const std::vector<std::uint64_t>& a, const std::vector<std::uint64_t>& b) {
  const std::unordered_set<std::uint64_t> in_a(a.begin(), a.end());
  size_t both = 0;
  for (auto id : b) both += in_a.count(id);
  const size_t either = a.size() + b.size() - both;
  return either == 0 ? 0 : double(both) / double(either);
}

}  // namespace

std::string cameraIntrinsicsError(const cv::Matx33d& K, const cv::Mat& distortion) {
  std::ostringstream why;
  for (int i = 0; i < 9; ++i)
    if (!std::isfinite(K.val[i])) {
      why << "K[" << i << "] is not finite";
      return why.str();
    }
  if (K(0, 0) <= 0 || K(1, 1) <= 0) {
    why << "focal length fx=" << K(0, 0) << ", fy=" << K(1, 1) << " is not positive";
    return why.str();
  }
  // cv::undistortPoints takes 4, 5, 8, 12 or 14 coefficients and asserts on any other.
  const size_t n = distortion.total();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
    why << distortion.total() << " distortion coefficients: OpenCV takes 0, 4, 5, 8, 12 or 14";
    return why.str();
  }
  if (!distortion.empty()) {
    if (distortion.channels() != 1) return "distortion coefficients must be one channel";
    cv::Mat d;
    distortion.convertTo(d, CV_64F);
    if (!cv::checkRange(d)) return "a distortion coefficient is not finite";
  }
  return {};
}

PlanePipeline::PlanePipeline(const PipelineParams& params) : params_(params), map_(params.map) {}

std::string PlanePipeline::setCamera(const cv::Matx33d& K, const cv::Mat& distortion) {
  if (std::string error = cameraIntrinsicsError(K, distortion); !error.empty()) return error;
  cv::Mat d;
  if (!distortion.empty()) distortion.reshape(1, 1).convertTo(d, CV_64F);
  // A recalibration may change the number of coefficients (5 -> 8): compare sizes first.
  const bool same = pose_ && K == K_ && d.size() == distortion_.size() &&
                    (d.empty() || cv::norm(d, distortion_, cv::NORM_INF) == 0);
  if (same) return {};
  K_ = K;
  distortion_ = d;
  pose_.emplace(K_, distortion_, params_.pose, params_.target);
  map_.reset();
  vertical_decided_ = false;
  pending_.clear();
  history_.clear();
  previous_planes_.clear();
  motion_planes_.clear();
  odometry_monitor_.reset();
  return {};
}

void PlanePipeline::setPerImageParams(const PlaneParams& planes, int frame_gap, double max_gap_s) {
  params_.planes = planes;
  params_.frame_gap = frame_gap;
  params_.max_gap_s = max_gap_s;
}

void PlanePipeline::reset() {
  if (pose_) pose_->reset();
  odometry_monitor_.reset();
  map_.reset();
  vertical_decided_ = false;
  pending_.clear();
  history_.clear();
  stream_.reset();
  previous_planes_.clear();
  motion_planes_.clear();
  newest_id_ = 0;
  tracker_run_ = 0;
}

// A reloaded or respawned tracker: its points are none of the map's, whose landmarks
// their ids name (hostile try: "lost" for the rest of the bag).
bool PlanePipeline::trackerStartedOver(const TrackFrame& frame, std::uint64_t newest) const {
  if (history_.empty()) return false;
  // Said by the tracker (Tracks.tracker_run): another run is another tracker.
  if (frame.tracker_run != 0 && tracker_run_ != 0) return frame.tracker_run != tracker_run_;
  // Not said: a new tracker numbers from 1 again, so its newest id is below the newest
  // seen and none of the last image's ids is left. A re-identified point has its old id
  // back: the tracker remembers what it lost, so it did not start over (hostile try: one
  // point left, lost, and found again under its old id, with max_features 1 set live,
  // started the map over). The flag is on one image only: should that message not reach
  // the map and no other point be left, the next still looks like a restart (review).
  if (frame.ids.empty()) return false;
  const bool remembers = std::find(frame.reidentified.begin(), frame.reidentified.end(), true) !=
                         frame.reidentified.end();
  if (newest >= newest_id_ || remembers) return false;
  // (Checked whenever the newest track is gone, not only at restarts: a set, not a search
  // of the last image per id.)
  const std::vector<std::uint64_t>& last_ids = history_.back().frame.ids;
  const std::unordered_set<std::uint64_t> last(last_ids.begin(), last_ids.end());
  return std::none_of(frame.ids.begin(), frame.ids.end(),
                      [&](std::uint64_t id) { return last.count(id) > 0; });
}

PipelineResult PlanePipeline::process(const TrackFrame& frame,
                                      const std::optional<Pose>& odom_from_camera) {
  PipelineResult result;
  if (!history_.empty()) {
    const double since = frame.stamp - history_.back().frame.stamp;
    const auto since_ns = static_cast<int64_t>(std::llround(since * 1e9));
    if (since < 0) {  // a bag looping: the map of the old run does not apply
      reset();
      result.was_reset = true;
    } else if (stream_.isPause(since_ns, params_.max_gap_s)) {
      stream_.addPause(since_ns);
      history_.clear();
      previous_planes_.clear();
      motion_planes_.clear();
      if (pose_) pose_->forgetLastPose();
      result.tracking_loss = true;
      result.pause_s = since;
    } else {
      result.missing_images = stream_.add(since_ns);
    }
  }
  const std::uint64_t newest =
      frame.ids.empty() ? 0 : *std::max_element(frame.ids.begin(), frame.ids.end());
  if (trackerStartedOver(frame, newest)) {
    reset();
    result.was_reset = result.tracker_restarted = true;
  }
  newest_id_ = std::max(newest_id_, newest);
  if (frame.tracker_run != 0) tracker_run_ = frame.tracker_run;

  if (pose_) result.pose = pose_->update(frame, odom_from_camera);

  // Paper III compares consecutive images; at 30 images/s their parallax is tiny. Until
  // the camera is placed the reference is frame_gap images back; then it is the most
  // recent image with enough rotation-free parallax (chooseReference).
  std::vector<cv::Point2d> normalized;
  const std::optional<Pose> pose =
      result.pose ? std::optional<Pose>(result.pose->map_from_camera) : std::nullopt;
  if (pose_) normalized = normalize(frame.pixels);
  if (!history_.empty()) {
    const auto [index, parallax] = chooseReference(frame, pose, normalized);
    result.parallax_px = parallax;
    if (index < 0) {
      result.pure_rotation = true;
    } else {
      const TrackFrame& reference = history_[static_cast<size_t>(index)].frame;
      result.reference_stamp = reference.stamp;
      result.pairs = matchById(reference, frame);
      if (result.pairs.ids.size() >= 5) {
        result.segmentation =
            segmentPlanes(result.pairs.first, result.pairs.second, params_.planes);
        for (const HomographyPlane& p : result.segmentation.planes) {
          ImagePlane image_plane;
          image_plane.H = p.H;
          image_plane.rms_error_px = p.rms_error_px;
          for (int i : p.inliers) image_plane.inlier_ids.push_back(result.pairs.ids[i]);
          result.planes.push_back(std::move(image_plane));
        }
      }
      // The odometry's motion against the tracks' (odometry_check.h), every
      // kOdometryCheckEvery images (0.5-0.8 ms a check): said, not acted on. Only where the
      // tracks determine the motion: planes other than the largest hold min_plane_support
      // of them (the tracks of one wall leave its direction two-fold ambiguous). Against
      // the oldest image within reach placed by odometry: the most parallax.
      long off_largest = 0;
      for (int label : result.segmentation.labels) off_largest += label >= 2;
      if (off_largest >= params_.planes.min_plane_support && result.pose &&
          result.pose->source == PoseSource::kOdometry && image_count_ % kOdometryCheckEvery == 0) {
        std::unordered_map<std::uint64_t, size_t> now;
        for (size_t i = 0; i < frame.ids.size(); ++i) now.emplace(frame.ids[i], i);
        for (const PastFrame& old : history_) {
          if (!old.odometry || !old.map_from_camera ||
              old.normalized.size() != old.frame.ids.size())
            continue;
          std::vector<cv::Point2d> a, b;
          std::vector<cv::Vec3d> ra, rb;
          for (size_t i = 0; i < old.frame.ids.size(); ++i) {
            const auto it = now.find(old.frame.ids[i]);
            if (it == now.end()) continue;
            a.push_back(old.normalized[i]);
            b.push_back(normalized[it->second]);
            ra.emplace_back(a.back().x, a.back().y, 1.0);
            rb.emplace_back(b.back().x, b.back().y, 1.0);
          }
          if (static_cast<int>(a.size()) < OdometryCheckParams().min_tracks) continue;
          const double focal = 0.5 * (K_(0, 0) + K_(1, 1));
          result.odometry_check = checkOdometryMotion(
              a, b, result.pose->map_from_camera.inverse() * *old.map_from_camera,
              focal * rotationFreeParallax(ra, rb), result.segmentation.noise_px, focal);
          break;
        }
      }
    }
  }
  // A rotation keeps the planes of the last image with parallax and their ids.
  if (!result.pure_rotation) assignImageIds(result.planes);
  ++image_count_;

  // camera_height: the planes seen while the start is checked wait (track ids, camera)
  // and reach the map, corrected, once the check has passed; an undone start drops them.
  if (pose_ && !pose_->scaleKnown()) {
    // At most 1000 images (33 s at 30 images/s): an up-to-scale start waits for the
    // floor without a time limit, memory must not.
    // An image the start's landmarks do not place adds nothing; an undone start (not
    // initialised any more) drops what waited.
    if (pose_->checkingPose())
      pending_.push_back({frame.stamp, *pose_->checkingPose(), result.planes});
    else if (!pose_->initialised())
      pending_.clear();
    if (pending_.size() > 1000) pending_.pop_front();
  }
  if (result.pose && pose_->scaleKnown()) {
    // The map's +y is the room's vertical (the target upright on a wall, the odometry's z)
    // when the camera of the map's first placed image stood upright along it: a sheet on
    // the floor or hung portrait, or an odometry frame whose z is not up, is not. Not with
    // camera_height: its up is its own floor's first fit, a map plane already.
    if (!vertical_decided_) {
      vertical_decided_ = true;
      const cv::Vec3d up(0, 1, 0);
      const bool upright =
          pose_->metricSource() != MetricSource::kCameraHeight &&
          cameraUpAngleDeg(result.pose->map_from_camera, up) <= kUprightCameraMaxDeg;
      map_.setVertical(upright ? std::optional<cv::Vec3d>(up) : std::nullopt);
    }
    for (PendingView& v : pending_) {
      v.pose.map_from_camera = pose_->floorCorrectionApplied().apply(v.pose.map_from_camera);
      map_.update(observationsOf(v.planes, v.pose), v.stamp);
    }
    pending_.clear();
    // camera_height: the floor landmarks the check fitted the map's up and scale to are
    // its floor, more of them than an image plane of the floor holds (the humanoid's: 30
    // and more against 5-10 after the turn, where 10 points mapped noise seed 7's floor
    // 1.92 deg off): the floor plane starts with them and is as level as the map.
    if (pose_->checkedFloor().image == pose_->imageIndex()) {
      ImagePlane floor;
      floor.inlier_ids = pose_->checkedFloor().ids;
      const std::vector<PlaneObservation> known = observationsOf({floor}, *result.pose);
      map_.addKnownPlane(known.front(), frame.stamp);
    }
    std::vector<PlaneObservation> observations = observationsOf(result.planes, *result.pose);
    if (params_.motion_plane_images > 0 && !result.pure_rotation &&
        result.pose->source == PoseSource::kOdometry)
      addMotionPlanes(result.planes, result.pose->map_from_camera, frame, normalized, observations);
    const std::vector<int> map_ids = map_.update(observations, frame.stamp);
    for (size_t k = 0; k < map_ids.size(); ++k) result.planes[k].map_id = map_ids[k];
  }

  result.odometry_check.stamp = frame.stamp;
  odometry_monitor_.add(result.odometry_check);  // (undecided: only its stamp counts)
  history_.push_back({frame, pose, std::move(normalized),
                      result.pose && result.pose->source == PoseSource::kOdometry});
  const int keep = std::max({1, params_.frame_gap, params_.max_keyframe_age});
  while (history_.size() > static_cast<size_t>(keep)) history_.pop_front();

  if (!pose_) {
    result.state = PipelineState::kNoCamera;
    result.status = "no camera intrinsics: image-space planes only";
  } else if (!pose_->scaleKnown()) {
    result.state = PipelineState::kWaitingForTarget;
    result.status = pose_->waitingFor();  // the target, odometry or the floor
  } else if (!pose_->initialised() && !result.pose) {
    result.state = PipelineState::kInitialising;
    // (One image without all four corners is no news: a corner at the image's edge.)
    result.status = pose_->startTargetUnseenS() > 0.5
                        ? "target seen, initialising: the start-up target is out of view (the "
                          "start needs it in two views with parallax)"
                        : "target seen, initialising: waiting for camera motion (parallax)";
    result.start_wait_s = pose_->startWaitS();
    result.start_target_unseen_s = pose_->startTargetUnseenS();
  } else if (!result.pose) {
    result.state = PipelineState::kLost;
    result.status = "lost: too few mapped points in view";
  } else {
    result.state = PipelineState::kTracking;
    result.status = std::string("tracking (") + toString(result.pose->source) + ")";
  }
  if (result.pure_rotation) {
    std::ostringstream why;
    why.precision(2);
    why << std::fixed << "; too little parallax (" << result.parallax_px
        << " px to every image within reach, under min_parallax_px " << params_.min_parallax_px
        << ": nearly pure rotation or standing still): no planes segmented";
    result.status += why.str();
  }
  return result;
}

std::vector<PlaneObservation> PlanePipeline::observationsOf(const std::vector<ImagePlane>& planes,
                                                            const PoseEstimate& pose) const {
  std::vector<PlaneObservation> observations;
  // A landmark's position along its ray is uncertain by about depth x (angular noise)
  // / parallax: the angular noise from this pose's reprojection error (both rays).
  const double focal = 0.5 * (K_(0, 0) + K_(1, 1));
  const double angle_sigma = std::sqrt(2.0) * std::max(0.3, pose.rms_px) / focal;
  const auto& landmarks = pose_->landmarks();
  for (const ImagePlane& p : planes) {
    PlaneObservation obs;
    obs.viewpoint = pose.map_from_camera.t;
    for (auto id : p.inlier_ids)
      if (const auto x = pose_->landmarkPosition(id)) {
        obs.ids.push_back(id);
        obs.points.push_back(*x);
        const auto l = landmarks.find(id);
        double sigma = params_.map.max_residual_m;
        if (l != landmarks.end() && l->second.fixed) {
          sigma = 0.001;
        } else if (l != landmarks.end() && l->second.parallax_deg > 0) {
          const double depth = cv::norm(*x - obs.viewpoint);
          sigma = depth * angle_sigma / std::sin(l->second.parallax_deg * CV_PI / 180);
        }
        obs.sigma_m.push_back(sigma);
      }
    observations.push_back(std::move(obs));
  }
  return observations;
}

void PlanePipeline::addMotionPlanes(const std::vector<ImagePlane>& planes,
                                    const Pose& map_from_camera, const TrackFrame& frame,
                                    const std::vector<cv::Point2d>& normalized,
                                    std::vector<PlaneObservation>& observations) {
  if (normalized.size() != frame.ids.size()) return;
  std::unordered_map<std::uint64_t, size_t> now;
  for (size_t i = 0; i < frame.ids.size(); ++i) now.emplace(frame.ids[i], i);
  const Pose camera_from_map = map_from_camera.inverse();
  const double focal = 0.5 * (K_(0, 0) + K_(1, 1));
  for (size_t k = 0; k < planes.size(); ++k) {
    MotionPlaneState& state = motion_planes_[planes[k].id];
    ++state.images;
    state.last_image = image_count_;
    for (auto id : planes[k].inlier_ids) ++state.member_images[id];
    if (static_cast<int>(observations[k].points.size()) >= params_.map.min_points) continue;
    // The tracks that stayed: members in at least half of the plane's images.
    std::vector<MotionCorrespondence> tracks;
    std::vector<std::uint64_t> ids;
    std::vector<cv::Vec3d> from;
    for (auto id : planes[k].inlier_ids) {
      if (state.member_images[id] < std::max(2.0, 0.5 * state.images)) continue;
      const auto at = now.find(id);
      if (at == now.end()) continue;
      // Its earliest placed image within reach: the widest baseline.
      for (const PastFrame& past : history_) {
        if (!past.odometry || !past.map_from_camera ||
            past.normalized.size() != past.frame.ids.size())
          continue;
        const auto it = std::find(past.frame.ids.begin(), past.frame.ids.end(), id);
        if (it == past.frame.ids.end()) continue;
        const cv::Point2d& y = past.normalized[static_cast<size_t>(it - past.frame.ids.begin())];
        const Pose now_from_then = camera_from_map * *past.map_from_camera;
        const cv::Vec3d ray = now_from_then.R * cv::Vec3d(y.x, y.y, 1);
        tracks.push_back({now_from_then.t, ray / cv::norm(ray), normalized[at->second]});
        ids.push_back(id);
        if (std::find(from.begin(), from.end(), past.map_from_camera->t) == from.end())
          from.push_back(past.map_from_camera->t);
        break;
      }
    }
    const MotionPlane fit = planeFromMotion(tracks, focal);
    if (!fit.ok || fit.normal_sigma_deg <= 0 || fit.distance_sigma <= 0) continue;
    const cv::Vec3d normal = map_from_camera.R * fit.normal;
    const double distance = fit.distance + normal.dot(map_from_camera.t);
    const double weight = 1 / (fit.normal_sigma_deg * fit.normal_sigma_deg);
    const double distance_weight = 1 / std::pow(fit.distance_sigma * fit.distance, 2);
    state.normal_sum += weight * normal;
    state.normal_weight += weight;
    state.distance_sum += distance_weight * distance;
    state.distance_weight += distance_weight;
    ++state.fits;
    if (state.fits < params_.motion_plane_images ||
        1 / std::sqrt(state.normal_weight) > params_.map.max_normal_sigma_deg)
      continue;
    // The fused plane; its tracks on it as seen now (landmarks where they have one).
    const cv::Vec3d n = state.normal_sum / cv::norm(state.normal_sum);
    const double d = state.distance_sum / state.distance_weight;
    const double distance_sigma = 1 / std::sqrt(state.distance_weight);
    PlaneObservation obs;
    obs.viewpoint = map_from_camera.t;
    obs.measured_from = from;
    obs.normal_sigma_deg = 1 / std::sqrt(state.normal_weight);
    for (size_t i = 0; i < ids.size(); ++i) {
      const auto landmark =
          std::find(observations[k].ids.begin(), observations[k].ids.end(), ids[i]);
      if (landmark != observations[k].ids.end()) {
        const size_t at = static_cast<size_t>(landmark - observations[k].ids.begin());
        obs.ids.push_back(ids[i]);
        obs.points.push_back(observations[k].points[at]);
        obs.sigma_m.push_back(observations[k].sigma_m[at]);
        continue;
      }
      const cv::Point2d& z = normalized[now.at(ids[i])];
      const cv::Vec3d ray = map_from_camera.R * cv::Vec3d(z.x, z.y, 1);
      const double along = n.dot(ray);
      if (std::abs(along) < 1e-9) continue;
      const double s = (d - n.dot(map_from_camera.t)) / along;
      if (!(s > 0)) continue;
      obs.ids.push_back(ids[i]);
      obs.points.push_back(map_from_camera.t + s * ray);
      // Along the ray: the plane's distance error over the ray's slant to it.
      obs.sigma_m.push_back(distance_sigma * cv::norm(ray) / std::abs(along));
    }
    observations[k] = std::move(obs);
  }
  // Planes the vote has not returned for a while have lost their id.
  for (auto it = motion_planes_.begin(); it != motion_planes_.end();)
    it = image_count_ - it->second.last_image > params_.max_keyframe_age ? motion_planes_.erase(it)
                                                                         : std::next(it);
}

std::vector<cv::Point2d> PlanePipeline::normalize(const std::vector<cv::Point2d>& pixels) const {
  std::vector<cv::Point2d> out;
  if (pixels.empty()) return out;
  cv::undistortPoints(pixels, out, cv::Mat(K_), distortion_);
  return out;
}

namespace {

// The image motion a rotation cannot explain: the rotation that best maps the reference
// rays onto the current ones (orthogonal Procrustes, twice, the second time without the
// worst tracks), then the median distance left, in normalised image units. Depth
// differences make it; a pure rotation leaves only noise, whatever the pose estimate.
double rotationFreeParallax(const std::vector<cv::Vec3d>& a, const std::vector<cv::Vec3d>& b) {
  std::vector<bool> use(a.size(), true);
  double median = 0;
  for (int round = 0; round < 2; ++round) {
    cv::Matx33d M = cv::Matx33d::zeros();
    for (size_t i = 0; i < a.size(); ++i)
      if (use[i]) M += b[i] * a[i].t();
    cv::Mat w, u, vt;
    cv::SVD::compute(cv::Mat(M), w, u, vt);
    cv::Mat R = u * vt;
    if (cv::determinant(R) < 0) {
      cv::Mat d = cv::Mat::eye(3, 3, CV_64F);
      d.at<double>(2, 2) = -1;
      R = u * d * vt;
    }
    const cv::Matx33d Rm = R;
    std::vector<double> residual;
    residual.reserve(a.size());
    for (size_t i = 0; i < a.size(); ++i) {
      const cv::Vec3d r = Rm * a[i];
      residual.push_back(
          std::hypot(r[0] / r[2] - b[i][0] / b[i][2], r[1] / r[2] - b[i][1] / b[i][2]));
    }
    std::vector<double> sorted = residual;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    median = sorted[sorted.size() / 2];
    for (size_t i = 0; i < a.size(); ++i) use[i] = residual[i] <= 3 * median + 1e-9;
  }
  return median;
}

}  // namespace

std::pair<int, double> PlanePipeline::chooseReference(
    const TrackFrame& frame, const std::optional<Pose>& /*pose*/,
    const std::vector<cv::Point2d>& normalized) const {
  const int n = static_cast<int>(history_.size());
  const int fixed = std::max(0, n - std::max(1, params_.frame_gap));
  if (!pose_ || n == 0 || normalized.size() != frame.ids.size()) return {fixed, -1.0};
  std::unordered_map<std::uint64_t, size_t> current;
  for (size_t i = 0; i < frame.ids.size(); ++i) current.emplace(frame.ids[i], i);
  const double focal = 0.5 * (K_(0, 0) + K_(1, 1));
  int fallback = -1;
  double fallback_parallax = -1;
  // Newest first: the most recent image with enough parallax shares the most tracks.
  for (int k = n - 1; k >= 0; --k) {
    const PastFrame& past = history_[static_cast<size_t>(k)];
    if (past.normalized.size() != past.frame.ids.size()) continue;
    std::vector<cv::Vec3d> a, b;
    for (size_t i = 0; i < past.frame.ids.size(); ++i) {
      const auto it = current.find(past.frame.ids[i]);
      if (it == current.end()) continue;
      const cv::Point2d& p = past.normalized[i];
      const cv::Point2d& q = normalized[it->second];
      a.emplace_back(p.x, p.y, 1.0);
      b.emplace_back(q.x, q.y, 1.0);
    }
    if (a.size() < 8 ||
        static_cast<double>(a.size()) < params_.min_keyframe_shared * frame.ids.size())
      continue;
    const double parallax = focal * rotationFreeParallax(a, b);
    if (parallax >= params_.keyframe_parallax_px) return {k, parallax};
    if (parallax > fallback_parallax) {
      fallback = k;
      fallback_parallax = parallax;
    }
  }
  if (fallback >= 0 && fallback_parallax >= params_.min_parallax_px)
    return {fallback, fallback_parallax};
  // No image within reach shares enough tracks (a jump): the fixed gap, as before.
  if (fallback < 0) return {fixed, -1.0};
  return {-1, std::max(0.0, fallback_parallax)};
}

void PlanePipeline::assignImageIds(std::vector<ImagePlane>& planes) {
  std::vector<bool> taken(previous_planes_.size(), false);
  for (ImagePlane& plane : planes) {
    int best = -1;
    double best_overlap = 0.3;  // below this share of common tracks it is another plane
    for (size_t k = 0; k < previous_planes_.size(); ++k) {
      if (taken[k]) continue;
      const double overlap = jaccard(plane.inlier_ids, previous_planes_[k].inlier_ids);
      if (overlap >= best_overlap) {
        best_overlap = overlap;
        best = static_cast<int>(k);
      }
    }
    if (best >= 0) {
      taken[best] = true;
      plane.id = previous_planes_[best].id;
    } else {
      plane.id = next_image_id_++;
    }
  }
  previous_planes_ = planes;
}

}  // namespace mono_plane_detection
