#include "mono_plane_detection/mapping/plane_pipeline.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_set>

namespace mono_plane_detection {
namespace {

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
  history_.clear();
  previous_planes_.clear();
  return {};
}

void PlanePipeline::setPerImageParams(const PlaneParams& planes, int frame_gap,
                                      double max_gap_s) {
  params_.planes = planes;
  params_.frame_gap = frame_gap;
  params_.max_gap_s = max_gap_s;
}

void PlanePipeline::reset() {
  if (pose_) pose_->reset();
  map_.reset();
  history_.clear();
  previous_planes_.clear();
}

PipelineResult PlanePipeline::process(const TrackFrame& frame,
                                      const std::optional<Pose>& odom_from_camera) {
  PipelineResult result;
  if (!history_.empty()) {
    const double since = frame.stamp - history_.back().stamp;
    if (since < 0) {  // a bag looping: the map of the old run does not apply
      reset();
      result.was_reset = true;
    } else if (since > params_.max_gap_s) {
      history_.clear();
      previous_planes_.clear();
      if (pose_) pose_->forgetLastPose();
      result.tracking_loss = true;
    }
  }

  if (pose_) result.pose = pose_->update(frame, odom_from_camera);

  // Paper III compares consecutive images; at 30 images/s their parallax is tiny, so the
  // reference is frame_gap images back (the tracks' ids give the correspondences).
  if (!history_.empty()) {
    const TrackFrame& reference =
        history_.size() >= static_cast<size_t>(params_.frame_gap)
            ? history_[history_.size() - static_cast<size_t>(params_.frame_gap)]
            : history_.front();
    result.reference_stamp = reference.stamp;
    result.pairs = matchById(reference, frame);
    if (result.pairs.ids.size() >= 5) {
      result.segmentation = segmentPlanes(result.pairs.first, result.pairs.second, params_.planes);
      for (const Plane& p : result.segmentation.planes) {
        ImagePlane image_plane;
        image_plane.H = p.H;
        image_plane.rms_error_px = p.rms_error_px;
        for (int i : p.inliers) image_plane.inlier_ids.push_back(result.pairs.ids[i]);
        result.planes.push_back(std::move(image_plane));
      }
    }
  }
  assignImageIds(result.planes);

  if (result.pose && pose_->scaleKnown()) {
    std::vector<PlaneObservation> observations;
    for (const ImagePlane& p : result.planes) {
      PlaneObservation obs;
      obs.viewpoint = result.pose->map_from_camera.t;
      for (auto id : p.inlier_ids)
        if (const auto x = pose_->landmarkPosition(id)) {
          obs.ids.push_back(id);
          obs.points.push_back(*x);
        }
      observations.push_back(std::move(obs));
    }
    const std::vector<int> map_ids = map_.update(observations, frame.stamp);
    for (size_t k = 0; k < map_ids.size(); ++k) result.planes[k].map_id = map_ids[k];
  }

  history_.push_back(frame);
  while (history_.size() > static_cast<size_t>(std::max(1, params_.frame_gap)))
    history_.pop_front();

  if (!pose_) {
    result.state = PipelineState::kNoCamera;
    result.status = "no camera intrinsics: image-space planes only";
  } else if (!pose_->scaleKnown()) {
    result.state = PipelineState::kWaitingForTarget;
    result.status = pose_->waitingFor();  // the target, odometry or the floor
  } else if (!pose_->initialised() && !result.pose) {
    result.state = PipelineState::kInitialising;
    result.status = "target seen, initialising: waiting for camera motion (parallax)";
  } else if (!result.pose) {
    result.state = PipelineState::kLost;
    result.status = "lost: too few mapped points in view";
  } else {
    result.state = PipelineState::kTracking;
    result.status = std::string("tracking (") + toString(result.pose->source) + ")";
  }
  return result;
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
