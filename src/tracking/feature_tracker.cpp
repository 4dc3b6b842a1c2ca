#include "mono_plane_detection/tracking/feature_tracker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#include <stdexcept>

#include "mono_plane_detection/geometry/stats.h"
#include "mono_plane_detection/params/param_table.h"

namespace mono_plane_detection {
namespace {

// Sub-pixel corner refinement, for new corners and re-anchored live ones alike.
const cv::TermCriteria kSubPixCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 0.01);
// The short backward pass of the forward-backward check: levels 0 and 1.
const int kShortCheckLevel = 1;
// predict_motion: the points whose full pass measures the image's motion (the median of
// 12 stays right with 5 of them wrong); with fewer than three times as many points the
// full pass runs on all.
const size_t kMotionSample = 12;

// The median image motion, per axis, of the displacements dx, dy (reordered in place:
// the tracker's kept buffers, no copy); zero when there are none.
cv::Point2f medianMotion(std::vector<float>& dx, std::vector<float>& dy) {
  if (dx.empty()) return {0.f, 0.f};
  const size_t mid = dx.size() / 2;
  std::nth_element(dx.begin(), dx.begin() + mid, dx.end());
  std::nth_element(dy.begin(), dy.begin() + mid, dy.end());
  return {dx[mid], dy[mid]};
}

// Lucas-Kanade's window and termination, the same for every pass.
cv::Size lkWindow(const TrackerParams& params) {
  return {params.window_size_px, params.window_size_px};
}
cv::TermCriteria lkCriteria(const TrackerParams& params) {
  return {cv::TermCriteria::COUNT | cv::TermCriteria::EPS, params.max_iterations,
          params.epsilon_px};
}

bool inside(const cv::Point2f& p, const cv::Size& size) {
  return p.x >= 0.f && p.y >= 0.f && p.x <= size.width - 1.f && p.y <= size.height - 1.f;
}

// ORB descriptors at given positions; a point too close to the border for ORB's patch
// gets an empty descriptor. ORB blurs the whole image it is given: it gets the region
// around the points only (half a search's points fill half the image), with a margin
// beyond its patch and blur so that the descriptors are those of the whole image.
std::vector<cv::Mat> orbDescriptors(const cv::Mat& gray, const std::vector<cv::Point2f>& uv) {
  static thread_local cv::Ptr<cv::ORB> orb = cv::ORB::create(500, 1.2f, /*nlevels=*/1);
  if (uv.empty()) return {};
  const int margin = orb->getEdgeThreshold() + 8;
  cv::Rect region = cv::boundingRect(uv);
  region = cv::Rect(region.x - margin, region.y - margin, region.width + 2 * margin,
                    region.height + 2 * margin) &
           cv::Rect(0, 0, gray.cols, gray.rows);
  // Points within the margin of the image's own border are left out by ORB either way.
  const cv::Point2f offset(static_cast<float>(region.x), static_cast<float>(region.y));
  std::vector<cv::KeyPoint> keypoints;
  for (size_t i = 0; i < uv.size(); ++i) {
    keypoints.emplace_back(uv[i] - offset, 31.f, 0.f, 0.f, 0, static_cast<int>(i));
  }
  cv::Mat rows;
  orb->compute(gray(region), keypoints, rows);
  std::vector<cv::Mat> out(uv.size());
  for (size_t k = 0; k < keypoints.size(); ++k) {
    out[keypoints[k].class_id] = rows.row(static_cast<int>(k)).clone();
  }
  return out;
}

}  // namespace

FeatureTracker::FeatureTracker(const TrackerParams& params) : params_(params) {}

void FeatureTracker::reset() {
  previous_.clear();
  current_.clear();
  descriptors_.clear();
  lost_.clear();
  stats_ = TrackerFrameStats();
  image_size_ = cv::Size();
  found_at_last_search_ = 0;
  frames_since_search_ = 0;
  coarse_came_short_ = false;
  searches_at_full_ = 0;
  pyramid_previous_ = -1;
  spread_image_ = -1;
  spread_part_ = 0;
  applyPendingParams();  // (no spread search left to wait for, no point to trim)
  trim_to_max_ = false;
}

std::string FeatureTracker::setParams(const TrackerParams& params) {
  TrackerParams checked = params;
  if (const std::vector<std::string> errors = validate(checked); !errors.empty())
    return "refused: " + errors.front();
  if (params.pyramid_levels != params_.pyramid_levels ||
      params.window_size_px != params_.window_size_px ||
      params.reanchor_window_px != params_.reanchor_window_px)
    return "pyramid_levels, window_size_px and reanchor_window_px cannot change while the "
           "tracker runs (they size its pyramids): restart it with the new values";
  pending_params_ = params;
  if (spread_part_ == 0) applyPendingParams();
  return "";
}

// A lower max_features waiting for a spread search holds already for what it adds: its
// corners would be dropped on the next image (review).
int FeatureTracker::maxFeaturesNow() const {
  return pending_params_ ? std::min(params_.max_features, pending_params_->max_features)
                         : params_.max_features;
}

void FeatureTracker::applyPendingParams() {
  if (!pending_params_) return;
  trim_to_max_ = trim_to_max_ || pending_params_->max_features < params_.max_features;
  params_ = *pending_params_;
  pending_params_.reset();
  if (!params_.reidentify) {  // (what it kept would never be used nor forgotten)
    descriptors_.clear();
    lost_.clear();
  }
}

// After max_features was lowered: the youngest points beyond it go (fewest images
// tracked; the start-up target's corners stay), remembered as lost so that a later search
// can give them their ids back. The loss that triggers a search counts from what is left.
// (Dropping keeps the others' prev_index: it points into previous_.)
void FeatureTracker::trimToMaxFeatures() {
  trim_to_max_ = false;
  const size_t keep = static_cast<size_t>(params_.max_features);
  if (current_.size() <= keep) return;
  std::vector<size_t> order;
  for (size_t k = 0; k < current_.size(); ++k)
    if (!current_[k].is_target_corner) order.push_back(k);
  // Youngest first; among equals the later (newer) one.
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return current_[a].age < current_[b].age || (current_[a].age == current_[b].age && a > b);
  });
  std::vector<bool> drop(current_.size(), false);
  for (size_t k = 0; k < order.size() && k < current_.size() - keep; ++k) drop[order[k]] = true;
  std::vector<TrackedPoint> kept;
  kept.reserve(keep);
  for (size_t k = 0; k < current_.size(); ++k) {
    if (drop[k])
      rememberLost(current_[k]);
    else
      kept.push_back(current_[k]);
  }
  stats_.lost += static_cast<int>(current_.size() - kept.size());
  current_.swap(kept);
  stats_.tracked = static_cast<int>(current_.size());
  found_at_last_search_ = std::min(found_at_last_search_, static_cast<int>(current_.size()));
}

int minimumImageSide(const TrackerParams& params) {
  // cv::cornerSubPix asserts unless the image is at least 2 x window + 5 px on each side:
  // window 3 for new corners, reanchor_window_px for live ones.
  return 2 * std::max(3, params.reanchor_window_px) + 5;
}

std::string imageSizeError(const cv::Size& size, const TrackerParams& params) {
  const int side = minimumImageSide(params);
  if (size.width >= side && size.height >= side) return {};
  return "image of " + std::to_string(size.width) + "x" + std::to_string(size.height) +
         " px is smaller than the " + std::to_string(side) + " px per side the tracker's " +
         "windows need (reanchor_window_px = " + std::to_string(params.reanchor_window_px) + ")";
}

const std::vector<TrackedPoint>& FeatureTracker::process(const cv::Mat& gray) {
  if (gray.empty() || gray.type() != CV_8UC1) {
    throw std::invalid_argument("FeatureTracker::process needs a non-empty CV_8UC1 image");
  }
  if (const std::string error = imageSizeError(gray.size(), params_); !error.empty())
    throw std::invalid_argument("FeatureTracker::process: " + error);
  if (gray.size() != image_size_) reset();
  image_size_ = gray.size();
  stats_ = TrackerFrameStats();

  // Built into a buffer that is neither the previous image's nor a spread search's:
  // same sizes, so no new memory.
  pyramid_now_ = 0;
  while (pyramid_now_ == pyramid_previous_ || pyramid_now_ == spread_image_) ++pyramid_now_;
  std::vector<cv::Mat>& pyramid = pyramids_[pyramid_now_];
  // (Never a view into `gray`: a spread search keeps the pyramid for several images.)
  levels_built_ = cv::buildOpticalFlowPyramid(
      gray, pyramid, lkWindow(params_), std::max(0, params_.pyramid_levels - 1), true,
      cv::BORDER_REFLECT_101, cv::BORDER_CONSTANT, /*tryReuseInputImage=*/false);

  std::swap(previous_, current_);  // (swap, not move: both keep their capacity)
  current_.clear();
  if (pyramid_previous_ >= 0)
    trackFromPrevious(pyramids_[pyramid_previous_], pyramid, gray.size());
  if (trim_to_max_) trimToMaxFeatures();
  ++frames_since_search_;

  // Paper II-D: the search runs on this image, before the next one is loaded, so the
  // points still tracked here continue into the new set.
  // A search costs a few images' tracking (at 640x480 a full-resolution corner search
  // costs 3-4 images' Lucas-Kanade): with search_spread_images > 1 its work is spread over
  // that many images, so that no image costs much more than the others. (Whole on the
  // first image, when nothing is left, and in paper mode without the mask, where a search
  // re-finds every live point's corner.)
  if (spread_part_ > 0 && current_.empty()) {
    // Nothing left before a spread search ends: the whole image now, as on the first.
    spread_image_ = -1;
    spread_part_ = 0;
    search(gray, pyramid);
  } else if (spread_part_ > 0) {
    // (The paper's triggers wait for it to end; the points lost meanwhile are not
    // counted towards the next 2/3, which counts from the corners it adds.)
    continueSpreadSearch(gray, pyramid);
  } else if (shouldSearch(found_at_last_search_, static_cast<int>(current_.size()),
                          frames_since_search_, params_)) {
    // (Spread only when corners are wanted: a full tracker's search re-anchors and
    // describes its points, which the whole-image search does at once.)
    if (params_.mask_existing && !current_.empty() && params_.search_spread_images > 1 &&
        static_cast<int>(current_.size()) < params_.max_features) {
      startSpreadSearch(gray);
    } else {
      search(gray, pyramid);
    }
  }
  pyramid_previous_ = pyramid_now_;
  ++frame_count_;
  if (spread_part_ == 0) applyPendingParams();  // (a spread search just ended)
  return current_;
}

std::vector<cv::Point2f>& FeatureTracker::positionsOf(const std::vector<TrackedPoint>& points,
                                                      std::vector<cv::Point2f>& out) const {
  out.clear();
  for (const auto& p : points) out.push_back(p.uv);
  return out;
}

std::vector<std::uint64_t> FeatureTracker::addPoints(const std::vector<cv::Point2f>& uv,
                                                     bool target_corner) {
  std::vector<std::uint64_t> ids;
  for (const auto& p : uv) {
    if (!inside(p, image_size_)) continue;
    TrackedPoint point;
    point.id = next_id_++;
    point.uv = p;
    point.is_new = true;
    point.is_target_corner = target_corner;
    current_.push_back(point);
    ids.push_back(point.id);
    ++stats_.added;
  }
  return ids;
}

int FeatureTracker::movePoints(const std::vector<std::uint64_t>& ids,
                               const std::vector<cv::Point2f>& uv) {
  int moved = 0;
  for (size_t k = 0; k < ids.size() && k < uv.size(); ++k) {
    if (!inside(uv[k], image_size_)) continue;
    for (TrackedPoint& p : current_)
      if (p.id == ids[k]) {
        p.uv = uv[k];
        ++moved;
        break;
      }
  }
  return moved;
}

// Beyond the paper (predict_motion): most points move nearly as the image does, so the
// image's motion is measured first, by the paper's full pyramidal pass on a sample of
// the points, and the others start from it on only as many pyramid levels as the
// sample's spread about it needs (a pass costs mostly its per-level window set-up: three
// levels fewer is most of it). The points this short pass or the forward-backward check
// does not keep get the full pass from their old position, so a point whose own motion
// is far from the image's costs time, not its track.
void FeatureTracker::trackFromPrevious(const std::vector<cv::Mat>& previous_pyramid,
                                       const std::vector<cv::Mat>& pyramid, const cv::Size& size) {
  if (previous_.empty()) return;
  const cv::Size window = lkWindow(params_);
  const cv::TermCriteria criteria = lkCriteria(params_);
  const std::vector<cv::Point2f>& before = positionsOf(previous_, before_);
  const int level = params_.predict_motion ? measureImageMotion(previous_pyramid, pyramid, size)
                                           : fullLevel();
  const bool predicted = level < fullLevel();
  if (predicted) {
    // The sample keeps its own full-pass results (recheck_*_ from measureImageMotion).
    after_.resize(before.size());
    for (size_t i = 0; i < before.size(); ++i) after_[i] = before[i] + image_motion_;
    cv::calcOpticalFlowPyrLK(previous_pyramid, pyramid, before, after_, status_, error_, window,
                             level, criteria, cv::OPTFLOW_USE_INITIAL_FLOW,
                             params_.min_eigen_threshold);
    for (size_t k = 0; k < recheck_index_.size(); ++k) {
      after_[recheck_index_[k]] = recheck_to_[k];
      status_[recheck_index_[k]] = recheck_status_[k];
    }
  } else {
    cv::calcOpticalFlowPyrLK(previous_pyramid, pyramid, before, after_, status_, error_, window,
                             fullLevel(), criteria, 0, params_.min_eigen_threshold);
  }
  if (params_.forward_backward_check) checkBackward(previous_pyramid, pyramid);
  if (predicted) retryOnFullPyramid(previous_pyramid, pyramid, size);

  for (size_t i = 0; i < previous_.size(); ++i) {
    if (!followed(i, size)) {
      rememberLost(previous_[i]);
      ++stats_.lost;
      continue;
    }
    TrackedPoint p = previous_[i];
    p.uv = after_[i];
    p.is_new = false;
    p.is_tracked = true;
    p.is_reidentified = false;  // (is_target_corner stays: it is the same point)
    p.prev_index = static_cast<int>(i);
    ++p.age;
    current_.push_back(p);
  }
  stats_.tracked = static_cast<int>(current_.size());
  stats_.lk_levels = level + 1;
  moveLostWithImage();
}

bool FeatureTracker::followed(size_t i, const cv::Size& size) const {
  const bool checked = params_.forward_backward_check;  // (back_ is stale without it)
  return passedCheck(status_[i], after_[i], checked ? back_status_[i] : 0,
                     checked ? back_[i] : before_[i], before_[i], size);
}

bool FeatureTracker::passedCheck(uchar status, const cv::Point2f& to, uchar back_status,
                                 const cv::Point2f& back, const cv::Point2f& from,
                                 const cv::Size& size) const {
  if (!status || !inside(to, size)) return false;
  if (!params_.forward_backward_check) return true;
  const cv::Point2f d = back - from;
  const double fb_max = params_.forward_backward_max_px;
  return back_status && d.dot(d) <= fb_max * fb_max;
}

// The full pass on kMotionSample points spread through previous_ (their results stay in
// recheck_index_ / recheck_to_ / recheck_status_); image_motion_ their median motion.
// Returns the pyramid level the others start from: the smallest from which Lucas-Kanade
// reaches twice the sample's 90th percentile distance from that motion plus a pixel
// (from level L a window of half-size h reaches about h (2^(L+1) - 1) px), at least that
// of the backward short pass; the full pyramid when there are too few points, or too
// few of the sample followed, to measure it.
int FeatureTracker::measureImageMotion(const std::vector<cv::Mat>& previous_pyramid,
                                       const std::vector<cv::Mat>& pyramid, const cv::Size& size) {
  const int max_level = fullLevel();
  recheck_index_.clear();
  const size_t n = before_.size();
  if (n < 3 * kMotionSample || max_level <= kShortCheckLevel) return max_level;
  recheck_from_.clear();
  for (size_t k = 0; k < kMotionSample; ++k) {
    recheck_index_.push_back(static_cast<int>(k * n / kMotionSample));
    recheck_from_.push_back(before_[recheck_index_.back()]);
  }
  cv::calcOpticalFlowPyrLK(previous_pyramid, pyramid, recheck_from_, recheck_to_, recheck_status_,
                           error_, lkWindow(params_), max_level, lkCriteria(params_), 0,
                           params_.min_eigen_threshold);
  motion_x_.clear();
  motion_y_.clear();
  for (size_t k = 0; k < kMotionSample; ++k) {
    if (!recheck_status_[k] || !inside(recheck_to_[k], size)) continue;
    motion_x_.push_back(recheck_to_[k].x - recheck_from_[k].x);
    motion_y_.push_back(recheck_to_[k].y - recheck_from_[k].y);
  }
  if (motion_x_.size() < kMotionSample / 2) return max_level;
  image_motion_ = medianMotion(motion_x_, motion_y_);
  motion_x_.clear();  // (now the followed sample's distances from the median motion)
  for (size_t k = 0; k < kMotionSample; ++k) {
    if (!recheck_status_[k] || !inside(recheck_to_[k], size)) continue;
    const cv::Point2f off = recheck_to_[k] - recheck_from_[k] - image_motion_;
    motion_x_.push_back(std::hypot(off.x, off.y));
  }
  const size_t q = motion_x_.size() * 9 / 10;
  std::nth_element(motion_x_.begin(), motion_x_.begin() + q, motion_x_.end());
  const double needed = 2.0 * motion_x_[q] + 1.0;
  const int half = params_.window_size_px / 2;  // (rounded down for an even side)
  for (int level = kShortCheckLevel; level < max_level; ++level) {
    if (half * ((2 << level) - 1) >= needed) return level;
  }
  return max_level;
}

// The paper's full pyramidal pass from `from` to `to` and, with the forward-backward check,
// the full pass back from where they went (back_status empty without the check).
void FeatureTracker::fullPass(const std::vector<cv::Mat>& from_pyramid,
                              const std::vector<cv::Mat>& to_pyramid,
                              const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>& to,
                              std::vector<uchar>& status, std::vector<cv::Point2f>& back,
                              std::vector<uchar>& back_status) {
  const cv::Size window = lkWindow(params_);
  const cv::TermCriteria criteria = lkCriteria(params_);
  cv::calcOpticalFlowPyrLK(from_pyramid, to_pyramid, from, to, status, error_, window,
                           fullLevel(), criteria, 0, params_.min_eigen_threshold);
  back_status.clear();
  if (!params_.forward_backward_check) return;
  back = to;
  cv::calcOpticalFlowPyrLK(to_pyramid, from_pyramid, to, back, back_status, error_, window,
                           fullLevel(), criteria, cv::OPTFLOW_USE_INITIAL_FLOW,
                           params_.min_eigen_threshold);
}

// The paper's full pyramidal pass, from the old position, for the points the short pass
// from the prediction did not keep, with the full backward pass as their check.
void FeatureTracker::retryOnFullPyramid(const std::vector<cv::Mat>& previous_pyramid,
                                        const std::vector<cv::Mat>& pyramid, const cv::Size& size) {
  recheck_index_.clear();
  recheck_from_.clear();
  for (size_t i = 0; i < before_.size(); ++i) {
    if (followed(i, size)) continue;
    recheck_index_.push_back(static_cast<int>(i));
    recheck_from_.push_back(before_[i]);
  }
  stats_.lk_retried = static_cast<int>(recheck_index_.size());
  if (recheck_index_.empty()) return;
  fullPass(previous_pyramid, pyramid, recheck_from_, recheck_to_, recheck_status_, recheck_back_,
           recheck_back_status_);
  for (size_t k = 0; k < recheck_index_.size(); ++k) {
    const int i = recheck_index_[k];
    after_[i] = recheck_to_[k];
    status_[i] = recheck_status_[k];
    if (params_.forward_backward_check) {
      back_[i] = recheck_back_[k];
      back_status_[i] = recheck_back_status_[k];
    }
  }
}

// The forward-backward check without a second full pyramidal pass (which cost as much
// as the forward one: measured, the per-level window set-up dominates, not the
// iterations). Each point is tracked back from where it went, starting from where the
// image's median motion says it came from: that start does not depend on the point's own
// forward result, so a wrong forward track returns to the true origin of its patch, not
// to `before`, and fails. Two levels cover the point's own motion beyond the median (up
// to ~6 px); the points that fail this short pass get the full pyramidal pass back
// (from where they went, as before), so a point is dropped only when that fails too.
void FeatureTracker::checkBackward(const std::vector<cv::Mat>& previous_pyramid,
                                   const std::vector<cv::Mat>& pyramid) {
  const std::vector<cv::Point2f>& before = before_;
  const std::vector<cv::Point2f>& after = after_;
  const cv::Size window = lkWindow(params_);
  const cv::TermCriteria criteria = lkCriteria(params_);
  motion_x_.clear();
  motion_y_.clear();
  for (size_t i = 0; i < before.size(); ++i) {
    if (!status_[i]) continue;
    motion_x_.push_back(after[i].x - before[i].x);
    motion_y_.push_back(after[i].y - before[i].y);
  }
  const cv::Point2f motion = medianMotion(motion_x_, motion_y_);
  back_.resize(after.size());
  for (size_t i = 0; i < after.size(); ++i) back_[i] = after[i] - motion;
  const int short_level = std::min(kShortCheckLevel, fullLevel());
  cv::calcOpticalFlowPyrLK(pyramid, previous_pyramid, after, back_, back_status_, error_, window,
                           short_level, criteria, cv::OPTFLOW_USE_INITIAL_FLOW,
                           params_.min_eigen_threshold);
  back_status_.resize(before.size(), 0);

  // The full pass for the forward-tracked points the short one did not bring back.
  const cv::Size size = pyramid[0].size();
  recheck_index_.clear();
  recheck_from_.clear();
  for (size_t i = 0; i < before.size(); ++i) {
    if (!status_[i] || !inside(after[i], size)) continue;  // lost either way
    if (followed(i, size)) continue;
    recheck_index_.push_back(static_cast<int>(i));
    recheck_from_.push_back(after[i]);
  }
  if (recheck_index_.empty()) return;
  recheck_back_ = recheck_from_;
  cv::calcOpticalFlowPyrLK(pyramid, previous_pyramid, recheck_from_, recheck_back_,
                           recheck_status_, error_, window, fullLevel(), criteria,
                           cv::OPTFLOW_USE_INITIAL_FLOW, params_.min_eigen_threshold);
  for (size_t k = 0; k < recheck_index_.size(); ++k) {
    back_[recheck_index_[k]] = recheck_back_[k];
    back_status_[recheck_index_[k]] = recheck_status_[k];
  }
}

// A lost point is out of view or occluded, so nothing tracks it; the median image
// motion of the live points is the best guess of where it went (it follows camera
// rotation, the paper's case of points leaving and coming back).
void FeatureTracker::moveLostWithImage() {
  if (lost_.empty() || current_.empty()) return;
  motion_x_.clear();
  motion_y_.clear();
  for (const auto& p : current_) {
    const cv::Point2f d = p.uv - previous_[p.prev_index].uv;
    motion_x_.push_back(d.x);
    motion_y_.push_back(d.y);
  }
  const cv::Point2f motion = medianMotion(motion_x_, motion_y_);
  for (auto& l : lost_) l.uv += motion;
}

// Paper II-B on the whole image at once.
void FeatureTracker::search(const cv::Mat& gray, const std::vector<cv::Mat>& pyramid) {
  stats_.searched = true;
  if (params_.reanchor_on_search) reanchor(gray);
  const int wanted = params_.mask_existing
                         ? params_.max_features - static_cast<int>(current_.size())
                         : params_.max_features;
  const int level = searchLevel(gray.size());
  const std::vector<cv::Point2f>& live = positionsOf(current_, live_uv_);
  static const std::vector<cv::Point2f> kNone;
  const std::vector<cv::Point2f>& corners =
      findCorners(gray, levelImage(pyramid, level), level, params_.mask_existing ? live : kNone,
                  wanted, params_, search_buffers_, fullDerivatives(pyramid));
  noteSearchLevel(level);
  adoptCorners(gray, corners);
  found_at_last_search_ = static_cast<int>(current_.size());
  frames_since_search_ = 0;
}

// A coarse level that came up short (the image's corners are fine-grained, or more are
// wanted than it holds) costs a second search at full resolution: search there directly,
// and try the coarse level again every fourth search.
int FeatureTracker::searchLevel(const cv::Size& size) const {
  const bool try_coarse = !coarse_came_short_ || searches_at_full_ >= 3;
  return try_coarse ? cornerSearchLevel(size, levels_built_, params_) : 0;
}

void FeatureTracker::noteSearchLevel(int level) {
  if (level > 0) {
    coarse_came_short_ = search_buffers_.from_full_resolution > 0;
    searches_at_full_ = 0;
  } else if (coarse_came_short_) {
    ++searches_at_full_;
  }
}

// A search spread over search_spread_images images (docs/tracking.md): the search image
// is kept, its corner response computed in bands of rows, one per image (responseBands),
// the corners chosen from it on the next image exactly as a search of the whole image
// would choose them there, and adopted on the last: followed from the search image to
// that one by Lucas-Kanade, then matched, re-identified and added as any search's.
void FeatureTracker::startSpreadSearch(const cv::Mat& gray) {
  stats_.searched = true;
  if (params_.reanchor_on_search) reanchor(gray);
  spread_level_ = searchLevel(gray.size());
  spread_wanted_ = params_.max_features - static_cast<int>(current_.size());
  positionsOf(current_, spread_live_);
  spread_image_ = pyramid_now_;
  spread_part_ = 0;
  responseBand(spread_part_++);
  frames_since_search_ = 0;  // (the paper's count runs from the search image)
}

// Band b of responseBands() of the kept search image's response.
void FeatureTracker::responseBand(int b) {
  const cv::Mat& level_image = levelImage(pyramids_[spread_image_], spread_level_);
  const int bands = responseBands();
  cornerResponseRows(level_image, params_.block_size, bandTop(b, level_image.rows, bands),
                     bandTop(b + 1, level_image.rows, bands), spread_response_, response_rows_);
}

void FeatureTracker::continueSpreadSearch(const cv::Mat& gray,
                                          const std::vector<cv::Mat>& pyramid) {
  stats_.search_rest = true;
  const int bands = responseBands();
  const int part = spread_part_++;
  if (part < bands) {
    responseBand(part);
    return;
  }
  const std::vector<cv::Mat>& kept = pyramids_[spread_image_];
  if (part == bands) {
    spread_corners_ = findCorners(kept[0], levelImage(kept, spread_level_), spread_level_,
                                  spread_live_, spread_wanted_, params_, search_buffers_,
                                  fullDerivatives(kept), &spread_response_);
    noteSearchLevel(spread_level_);
    // With three images or more, the corners are adopted on the next one.
    if (params_.search_spread_images >= 3) return;
  }
  // The corners followed from the search image to this one: the full pyramid and the
  // forward-backward check, as any point.
  const std::vector<cv::Point2f>& corners = spread_corners_;
  std::vector<cv::Point2f>& followed = fresh_uv_;
  followed.clear();
  if (!corners.empty()) {
    fullPass(kept, pyramid, corners, spread_to_, spread_status_, spread_back_,
             spread_back_status_);
    const bool checked = params_.forward_backward_check;
    for (size_t c = 0; c < corners.size(); ++c)
      if (passedCheck(spread_status_[c], spread_to_[c], checked ? spread_back_status_[c] : 0,
                      checked ? spread_back_[c] : corners[c], corners[c], gray.size()))
        followed.push_back(spread_to_[c]);
  }
  spread_image_ = -1;
  spread_part_ = 0;
  // Two points may have come closer since the search image: the spacing rule again.
  const int wanted = maxFeaturesNow() - static_cast<int>(current_.size());
  keepApart(followed, positionsOf(current_, live_uv_), params_.min_distance_px,
            std::max(0, wanted));
  adoptCorners(gray, followed);
  found_at_last_search_ = static_cast<int>(current_.size());
}

// Paper II-D: corners that match a live point are that point (it keeps its id and its
// sub-pixel tracked position); the others are new points, or lost points come back (by
// their ORB descriptors).
void FeatureTracker::adoptCorners(const cv::Mat& gray, const std::vector<cv::Point2f>& corners) {
  const std::vector<cv::Point2f>& live = positionsOf(current_, live_uv_);
  const std::vector<int> match = matchCornersToPoints(corners, live, params_.match_radius_px);
  std::vector<TrackedPoint>& fresh = fresh_;
  fresh.clear();
  for (size_t c = 0; c < corners.size(); ++c) {
    if (match[c] >= 0) {
      ++stats_.matched;
      continue;
    }
    // Full: later corners are still checked, so `matched` counts every re-found point.
    if (static_cast<int>(current_.size() + fresh.size()) >= maxFeaturesNow()) continue;
    TrackedPoint p;
    p.uv = corners[c];
    p.is_new = true;
    fresh.push_back(p);
  }

  // One ORB call for the live points and the new corners: the new corners' part is
  // compared with the lost points, and all are remembered for when they get lost.
  // (descriptors[k] is current_[k]'s once the fresh points are appended.)
  std::vector<cv::Mat> descriptors;
  if (params_.reidentify) {
    positionsOf(current_, live_uv_);
    for (const auto& p : fresh) live_uv_.push_back(p.uv);
    descriptors = orbDescriptors(gray, live_uv_);
    const std::vector<cv::Mat> fresh_descriptors(descriptors.begin() + current_.size(),
                                                 descriptors.end());
    reidentify(fresh_descriptors, fresh);
  }
  for (auto& p : fresh) {
    if (!p.is_reidentified) {
      p.id = next_id_++;
      ++stats_.added;
    }
    current_.push_back(p);
  }
  if (params_.reidentify) refreshDescriptors(descriptors);
}

// Lucas-Kanade with a translation-only window follows the centroid of the window's
// gradients, not the corner itself: under image rotation or scale this drifts a few
// hundredths of a pixel per image and accumulates. Pulling live points back onto their
// corner at each search bounds the drift to the images between searches. (Spreading it
// over the images, a share of the points on each, was measured: errors grew by up to
// half on real textures and the search image's time hardly changed.)
void FeatureTracker::reanchor(const cv::Mat& gray) {
  std::vector<cv::Point2f>& refined = positionsOf(current_, live_uv_);
  if (refined.empty()) return;
  const int half = params_.reanchor_window_px;
  cv::cornerSubPix(gray, refined, cv::Size(half, half), cv::Size(-1, -1), kSubPixCriteria);
  const double max_shift2 = params_.reanchor_max_shift_px * params_.reanchor_max_shift_px;
  for (size_t k = 0; k < current_.size(); ++k) {
    TrackedPoint& point = current_[k];
    const cv::Point2f d = refined[k] - point.uv;
    if (d.dot(d) <= max_shift2 && inside(refined[k], gray.size())) point.uv = refined[k];
  }
}

void FeatureTracker::rememberLost(const TrackedPoint& point) {
  if (!params_.reidentify) return;
  auto it = descriptors_.find(point.id);
  if (it == descriptors_.end() || it->second.empty()) return;
  lost_.push_back({point.id, point.uv, point.age, frame_count_, it->second});
  descriptors_.erase(it);
}

void FeatureTracker::reidentify(const std::vector<cv::Mat>& descriptors,
                                std::vector<TrackedPoint>& fresh) {
  lost_.erase(std::remove_if(lost_.begin(), lost_.end(),
                             [this](const LostPoint& l) {
                               return frame_count_ - l.lost_at_frame > params_.reid_memory_frames;
                             }),
              lost_.end());
  if (lost_.empty() || fresh.empty()) return;

  // Each fresh corner claims its best lost point; paper II-D's rule settles conflicts.
  std::vector<int> claim(fresh.size(), -1);
  std::vector<double> claim_distance(fresh.size(), 0.0);
  const double radius2 = params_.reid_max_radius_px * params_.reid_max_radius_px;
  for (size_t f = 0; f < fresh.size(); ++f) {
    if (descriptors[f].empty()) continue;
    int best = -1;
    int best_d = std::numeric_limits<int>::max();
    int second_d = std::numeric_limits<int>::max();
    for (size_t l = 0; l < lost_.size(); ++l) {
      const cv::Point2f d = fresh[f].uv - lost_[l].uv;
      if (d.dot(d) > radius2) continue;
      const int h =
          static_cast<int>(cv::norm(descriptors[f], lost_[l].descriptor, cv::NORM_HAMMING));
      if (h < best_d) {
        second_d = best_d;
        best_d = h;
        best = static_cast<int>(l);
      } else if (h < second_d) {
        second_d = h;
      }
    }
    const bool distinct =
        second_d == std::numeric_limits<int>::max() || best_d < params_.reid_ratio * second_d;
    if (best >= 0 && best_d <= params_.reid_max_hamming && distinct) {
      claim[f] = best;
      claim_distance[f] = best_d;
    }
  }
  const std::vector<int> granted = closestClaimWins(claim, claim_distance, lost_.size());
  std::vector<bool> taken(lost_.size(), false);
  for (size_t f = 0; f < fresh.size(); ++f) {
    if (granted[f] < 0) continue;
    const LostPoint& l = lost_[granted[f]];
    fresh[f].id = l.id;
    fresh[f].age = l.age;
    fresh[f].is_reidentified = true;
    ++stats_.reidentified;
    taken[granted[f]] = true;
  }
  std::vector<LostPoint> kept;
  for (size_t l = 0; l < lost_.size(); ++l) {
    if (!taken[l]) kept.push_back(std::move(lost_[l]));
  }
  lost_ = std::move(kept);
}

// descriptors[k] belongs to current_[k].
void FeatureTracker::refreshDescriptors(const std::vector<cv::Mat>& descriptors) {
  for (size_t k = 0; k < current_.size(); ++k) {
    const std::uint64_t id = current_[k].id;
    if (descriptors[k].empty()) {
      descriptors_.erase(id);
    } else {
      descriptors_[id] = descriptors[k];
    }
  }
}

}  // namespace mono_plane_detection
