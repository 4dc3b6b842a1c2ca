#include "mono_plane_detection/tracking/target_startup.h"

#include <algorithm>
#include <limits>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <sstream>
#include <vector>

namespace mono_plane_detection {

TargetStartup::TargetStartup(const TargetParams& params) : params_(params), follow_params_(params) {
  // No aspect check in followTarget's region: its focal length and principal point do not
  // carry over to a crop, and the target is already known: four corners that each land
  // within confirm_tolerance_px of a confirmed track are its corners.
  follow_params_.max_aspect_error = std::numeric_limits<double>::infinity();
}

void TargetStartup::reset() {
  found_ = false;
  consecutive_ = 0;
  previous_.release();
  last_ = TargetDetection();
  corner_ids_.clear();
  reanchored_ = false;
  reanchored_images_ = 0;
  followed_images_ = 0;
  last_shift_px_ = 0;
}

void TargetStartup::setLens(const cv::Matx33d& K, const cv::Mat& D, bool fisheye) {
  const bool no_d = D.empty() || cv::countNonZero(D) == 0;
  // Set with every image: the maps are made again (and D copied) only when the lens changes.
  const bool same = K == K_ && fisheye == fisheye_ &&
                    (no_d ? D_.empty()
                          : D.size() == D_.size() && D.type() == D_.type() &&
                                cv::norm(D, D_, cv::NORM_INF) == 0);
  if (same) return;
  K_ = K;
  D_ = no_d ? cv::Mat() : D.clone();
  fisheye_ = fisheye;
  map_size_ = cv::Size();
}

namespace {

// Pixels of the image undistorted to K back to the raw image of the lens (K, D).
bool toRawPixels(std::array<cv::Point2f, 4>& corners, const cv::Matx33d& K, const cv::Mat& D,
                 bool fisheye, const cv::Size& size) {
  std::vector<cv::Point3d> rays;
  for (const auto& c : corners)
    rays.emplace_back((c.x - K(0, 2)) / K(0, 0), (c.y - K(1, 2)) / K(1, 1), 1.0);
  std::vector<cv::Point2d> raw;
  const cv::Vec3d zero(0, 0, 0);
  if (fisheye)
    cv::fisheye::projectPoints(rays, raw, zero, zero, K, D);
  else
    cv::projectPoints(rays, zero, zero, K, D, raw);
  const double margin = 2.0;  // px: a corner there has no surround to judge it by
  for (int i = 0; i < 4; ++i) {
    if (!(raw[i].x >= margin && raw[i].y >= margin && raw[i].x <= size.width - 1 - margin &&
          raw[i].y <= size.height - 1 - margin))
      return false;
    corners[i] = cv::Point2f(static_cast<float>(raw[i].x), static_cast<float>(raw[i].y));
  }
  return true;
}

}  // namespace

void TargetStartup::ensureMaps(const cv::Size& size) {
  if (D_.empty() || map_size_ == size) return;
  if (fisheye_)
    cv::fisheye::initUndistortRectifyMap(K_, D_, cv::Matx33d::eye(), K_, size, CV_16SC2, map1_,
                                         map2_);
  else
    cv::initUndistortRectifyMap(K_, D_, cv::noArray(), K_, size, CV_16SC2, map1_, map2_);
  map_size_ = size;
}

void TargetStartup::followTarget(const cv::Mat& gray, FeatureTracker& tracker) {
  reanchored_ = false;
  if (corner_ids_.size() != 4 || gray.empty()) return;
  std::array<cv::Point2f, 4> tracked;
  int alive = 0;
  for (const TrackedPoint& p : tracker.current())
    for (int k = 0; k < 4; ++k)
      if (p.id == corner_ids_[k]) {
        tracked[k] = p.uv;
        ++alive;
      }
  if (alive < 4) return;  // a corner lost: the target is leaving the view or hidden
  ++followed_images_;
  // The region: the tracked quadrilateral (undistorted, where the sides are straight) with
  // a margin for the surround the detector measures its sides against (an eighth of the
  // size: a quarter found the same corners at 1.25x the time, benchmark_suite).
  const bool undistort = !D_.empty();
  std::vector<cv::Point2f> where(tracked.begin(), tracked.end());
  if (undistort) {
    ensureMaps(gray.size());
    std::vector<cv::Point2f> raw = where;
    if (fisheye_)
      cv::fisheye::undistortPoints(raw, where, K_, D_, cv::noArray(), K_);
    else
      cv::undistortPoints(raw, where, K_, D_, cv::noArray(), K_);
  }
  const cv::Rect box = cv::boundingRect(where);  // integer, enclosing
  const int margin = std::max(12, std::max(box.width, box.height) / 8);
  cv::Rect roi(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin);
  roi &= cv::Rect(0, 0, gray.cols, gray.rows);
  if (roi.width < 16 || roi.height < 16) return;
  if (undistort)  // only the region: the maps give each of its pixels' raw position
    cv::remap(gray, crop_, map1_(roi), map2_(roi), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  const cv::Mat search = undistort ? crop_ : gray(roi);
  TargetDetection again = detectConfiguredTarget(search, follow_params_);
  if (!again.found) return;  // the tracks stay as they are
  const cv::Point2f offset(static_cast<float>(roi.x), static_cast<float>(roi.y));
  for (auto& c : again.corners) c += offset;
  if (undistort && !toRawPixels(again.corners, K_, D_, fisheye_, gray.size())) return;
  // Each track to its nearest detected corner: four different ones, all close.
  std::vector<cv::Point2f> detected(4);
  std::array<bool, 4> used{};
  double worst = 0;
  for (int k = 0; k < 4; ++k) {
    int best = -1;
    double best_d = std::numeric_limits<double>::infinity();
    for (int j = 0; j < 4; ++j) {
      const double d = cv::norm(again.corners[j] - tracked[k]);
      if (d < best_d) {
        best_d = d;
        best = j;
      }
    }
    if (used[best] || !(best_d <= params_.confirm_tolerance_px)) return;
    used[best] = true;
    detected[k] = again.corners[best];
    worst = std::max(worst, best_d);
  }
  if (tracker.movePoints(corner_ids_, detected) != 4) return;
  reanchored_ = true;
  ++reanchored_images_;
  last_shift_px_ = worst;
}

std::optional<TargetDetection> TargetStartup::process(const cv::Mat& gray, FeatureTracker& tracker,
                                                      double focal_px,
                                                      cv::Point2d principal_px) {
  if (found_) {
    if (params_.redetect_tracked) followTarget(gray, tracker);
    return {};
  }
  const bool undistort = !D_.empty() && !gray.empty();
  if (undistort) {
    ensureMaps(gray.size());
    // Replicated, not black, beyond the raw image: a black fill would be a dark surround.
    cv::remap(gray, undistorted_, map1_, map2_, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    focal_px = K_(0, 0);
    principal_px = {K_(0, 2), K_(1, 2)};
  }
  TargetDetection target =
      detectConfiguredTarget(undistort ? undistorted_ : gray, params_, focal_px, principal_px);
  if (target.found && undistort && !toRawPixels(target.corners, K_, D_, fisheye_, gray.size())) {
    target.found = false;
    target.rejection = TargetRejection::kAtImageEdge;
    target.reason = "target corners on or beyond the raw image's border";
  }
  if (!target.found) {
    consecutive_ = 0;
    previous_.release();
    last_ = target;
    return {};
  }
  // Consistent with the previous image: its corners, tracked by Lucas-Kanade into this
  // image, land on this image's corners.
  bool consistent = false;
  if (consecutive_ > 0 && !previous_.empty() && previous_.size() == gray.size()) {
    const std::vector<cv::Point2f> before(last_.corners.begin(), last_.corners.end());
    std::vector<cv::Point2f> after;
    std::vector<uchar> status;
    std::vector<float> error;
    cv::calcOpticalFlowPyrLK(previous_, gray, before, after, status, error, cv::Size(21, 21), 3);
    consistent = true;
    for (int i = 0; i < 4; ++i)
      consistent = consistent && status[i] &&
                   cv::norm(after[i] - target.corners[i]) <= params_.confirm_tolerance_px;
  }
  consecutive_ = consistent ? consecutive_ + 1 : 1;
  previous_ = gray.clone();
  last_ = target;
  if (consecutive_ < std::max(1, params_.confirm_frames)) {
    std::ostringstream why;
    why << "target seen in " << consecutive_ << " of " << params_.confirm_frames
        << " consecutive images needed";
    last_.reason = why.str();
    return {};
  }
  corner_ids_ = tracker.addPoints({target.corners.begin(), target.corners.end()}, true);
  found_ = true;
  previous_.release();
  return target;
}

}  // namespace mono_plane_detection
