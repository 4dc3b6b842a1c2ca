// Feature tracking of paper section II: Shi-Tomasi corners followed by pyramidal
// Lucas-Kanade, a new search on 2/3 loss and every N frames, and matching of new
// corners to old points so that tracks keep their ids. ROS-free.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "mono_plane_detection/tracking/corner_search.h"

namespace mono_plane_detection {

struct TrackerParams {
  // Shi-Tomasi search (paper II-B).
  int max_features = 50;          // corners kept per image
  double min_distance_px = 15.0;  // minimum spacing between corners
  double quality_level = 0.01;    // fraction of the strongest corner's score
  int block_size = 3;             // px, neighbourhood of the corner score
  // Beyond the paper: new corners go first to the cells of a grid that hold the fewest
  // points, strongest first within a cell, instead of the strongest in the image: a
  // weakly textured surface (a painted cabinet front) next to photographs gets corners
  // too. The grid has this many columns of square cells whatever the image size
  // (spreadCellPx: 80 px at 640 px wide, 160 px at 1280). 0: strongest first (the paper).
  int spread_grid_columns = 8;
  // Beyond the paper: each cell of that grid also takes corners above quality_level of
  // its own strongest response (the image's bar is relative to the strongest corner of the
  // whole image, so a plain cabinet front beside photographs gets none), but never under
  // this many times the strongest response of the image's noise (noiseCornerFloor). 0: the
  // image's bar alone (the paper), the default: on the real EuRoC / TUM frames the weak
  // cells' corners doubled the mean tracking error (docs/tracking.md); 2 for weakly
  // textured rooms (the furnished room's planes 0.3-1.5 deg better).
  double corner_noise_margin = 0.0;

  // Pyramidal Lucas-Kanade (paper II-C).
  int pyramid_levels = 5;             // levels including full resolution (paper: 5)
  // LK window side; paper: 3; 7 measured best (docs/benchmarks.md, "LK window size").
  int window_size_px = 7;
  int max_iterations = 30;            // LK termination: iterations per level
  double epsilon_px = 0.01;           // LK termination: step size
  double min_eigen_threshold = 1e-4;  // LK drops points whose gradient matrix is this flat
  // Beyond the paper: measure the image's motion by the full pyramid on a sample of the
  // points, start the others from it on only the pyramid levels the sample's spread
  // needs; the points this short pass loses get the full pyramid from their old position.
  // Off by default: 7-33 % less time on images without a search, but the mean error on
  // the EuRoC rows 0.4-5 % higher, and the furnished room lost its left wall on one run
  // and its floor on one of five noise seeds (docs/benchmarks.md, eighth round).
  bool predict_motion = false;

  // When to search again (paper II-C).
  double redetect_lost_fraction = 2.0 / 3.0;  // of the points found at the last search
  int redetect_every = 10;                    // frames between searches at the latest
  // Beyond the paper: a search's work runs over this many images so that the search
  // image does not cost several images' tracking: the search image's corner response in
  // bands of rows on the first ones, the choice of corners (as on the whole search image)
  // on the next, their adoption on the last (followed there by Lucas-Kanade). 1: all on
  // the search image, the default: 5 flattens frame times at the tracking quality of 1
  // (docs/benchmarks.md, tenth round), but the furnished room's maps were worse with it.
  int search_spread_images = 1;

  // Matching new corners to existing points (paper II-D).
  double match_radius_px = 3.0;

  // Beyond the paper.
  bool forward_backward_check = true;    // track back and drop points that do not return
  double forward_backward_max_px = 1.0;  // allowed round-trip error
  bool reanchor_on_search = true;        // pull live points back onto their corner
  int reanchor_window_px = 3;            // half-size of the cornerSubPix window
  double reanchor_max_shift_px = 1.0;    // larger corrections are not trusted
  bool mask_existing = true;             // no new corner within min_distance of a live point
  bool reidentify = true;                // give a lost point its old id when it comes back
  int reid_memory_frames = 150;          // how long a lost point can come back
  int reid_max_hamming = 30;             // of 256 ORB bits
  double reid_ratio = 0.8;               // best / second-best Hamming distance
  double reid_max_radius_px = 20.0;      // from where the image motion says it went
};

// One record of the paper's state arrays.
struct TrackedPoint {
  std::uint64_t id = 0;  // unique, increasing, never reused
  cv::Point2f uv;        // pixel position in the current image
  // (The paper's 3D position lives with the landmarks: mapping/pose_estimator.h.)
  bool is_new = false;            // new on this image (found by a search)
  bool is_tracked = false;        // followed by Lucas-Kanade from the previous image
  bool is_reidentified = false;   // new corner that got back the id of a lost point
  bool is_target_corner = false;  // a corner of the start-up target (paper II-A)
  int prev_index = -1;            // index in the previous state, -1 if new
  int age = 0;                    // images since the point was first seen (0 when new)
};

// What happened on the last processed image.
struct TrackerFrameStats {
  int tracked = 0;       // points followed from the previous image
  int lost = 0;          // points of the previous image not followed
  int added = 0;         // points with a new id
  int matched = 0;       // new corners that matched a live point (kept its id)
  int reidentified = 0;  // new corners that got back a lost id
  bool searched = false;     // a search started on this image (the paper's search image)
  bool search_rest = false;  // a later image of a spread search started on an earlier one
  int lk_levels = 0;   // pyramid levels of most points' forward pass (fewer when predicted)
  int lk_retried = 0;  // points the full pyramid was run again for (predict_motion)
};

// Paper II-C: search again when the share of points lost since the last search reaches
// lost_fraction, when frames_since_search reaches every_n, or when nothing is left.
bool shouldSearch(int found_at_last_search, int alive, int frames_since_search,
                  const TrackerParams& params);

// Paper II-D's tie rule, shared by matching and re-identification: claimant c wants
// target claim[c] (-1: none) at cost[c]; when several want one target the lowest cost
// wins (the first on equal cost) and the others get -1.
std::vector<int> closestClaimWins(const std::vector<int>& claim, const std::vector<double>& cost,
                                  size_t targets);

// Paper II-D: for each corner, the index of the point within radius it matches, or -1.
// When several corners pick the same point, the closest pair wins.
std::vector<int> matchCornersToPoints(const std::vector<cv::Point2f>& corners,
                                      const std::vector<cv::Point2f>& points, double radius_px);

// The smallest image side the tracker's windows fit in (cornerSubPix's limit).
int minimumImageSide(const TrackerParams& params);
// Empty when an image of this size can be tracked, else why not (naming the sizes).
std::string imageSizeError(const cv::Size& size, const TrackerParams& params);

class FeatureTracker {
 public:
  explicit FeatureTracker(const TrackerParams& params = TrackerParams());

  // Processes the next image and returns the new current state. Throws
  // std::invalid_argument (with the reason) unless the image is CV_8UC1 and
  // imageSizeError is empty for it. An image of another size than the previous one
  // starts over (reset).
  const std::vector<TrackedPoint>& process(const cv::Mat& gray);

  // Adds points found by other means on the image just processed (the start-up target's
  // corners): new ids, flagged new (and target_corner), tracked from the next image on.
  // Returns their ids. Call after process().
  std::vector<std::uint64_t> addPoints(const std::vector<cv::Point2f>& uv, bool target_corner);

  // Moves live points of the image just processed (by id) to positions measured by other
  // means (the start-up target re-detected: tracks that do not drift); they keep their
  // ids and flags and are tracked on from there. Ids not live and positions outside the
  // image are skipped. Returns how many moved. Call after process().
  int movePoints(const std::vector<std::uint64_t>& ids, const std::vector<cv::Point2f>& uv);

  // Forgets every point and image; ids keep increasing so they are never reused.
  void reset();

  // New parameters between images (dynamic_reconfigure); "" when taken, else why not and
  // nothing changes (also for a value out of its range, param_table.h). pyramid_levels,
  // window_size_px and reanchor_window_px size the pyramids and the smallest image: a
  // change of those is refused (it needs a new tracker). A spread search in progress
  // finishes under the old values (a lower max_features caps what it adds); the new ones
  // apply from the image after it. A lower max_features drops the youngest points beyond
  // it on the next image (the start-up target's corners stay; the dropped ones can be
  // re-identified later).
  std::string setParams(const TrackerParams& params);

  const std::vector<TrackedPoint>& current() const { return current_; }
  const std::vector<TrackedPoint>& previous() const { return previous_; }
  const TrackerFrameStats& lastStats() const { return stats_; }
  const TrackerParams& params() const { return params_; }
  long frameCount() const { return frame_count_; }

 private:
  struct LostPoint {
    std::uint64_t id;
    cv::Point2f uv;
    int age;
    long lost_at_frame;
    cv::Mat descriptor;
  };

  void trackFromPrevious(const std::vector<cv::Mat>& previous_pyramid,
                         const std::vector<cv::Mat>& pyramid, const cv::Size& size);
  void checkBackward(const std::vector<cv::Mat>& previous_pyramid,
                     const std::vector<cv::Mat>& pyramid);
  void fullPass(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid,
                const std::vector<cv::Point2f>& from, std::vector<cv::Point2f>& to,
                std::vector<uchar>& status, std::vector<cv::Point2f>& back,
                std::vector<uchar>& back_status);
  void retryOnFullPyramid(const std::vector<cv::Mat>& previous_pyramid,
                          const std::vector<cv::Mat>& pyramid, const cv::Size& size);
  // Point i of previous_ was followed: tracked, inside, back within the check's bound.
  bool followed(size_t i, const cv::Size& size) const;
  // A point Lucas-Kanade took from `from` to `to` (status) inside the image, and, with the
  // forward-backward check, back (back_status) within its bound of `from`.
  bool passedCheck(uchar status, const cv::Point2f& to, uchar back_status,
                   const cv::Point2f& back, const cv::Point2f& from, const cv::Size& size) const;
  int measureImageMotion(const std::vector<cv::Mat>& previous_pyramid,
                         const std::vector<cv::Mat>& pyramid, const cv::Size& size);
  // The top pyramid level Lucas-Kanade can use: pyramid_levels - 1, or fewer when the
  // image is too small to build them.
  int fullLevel() const {
    return std::min(std::max(0, params_.pyramid_levels - 1), levels_built_);
  }
  // A pyramid holds each level's image and, when built with them, its derivatives in turn.
  const cv::Mat& levelImage(const std::vector<cv::Mat>& pyramid, int level) const {
    return pyramid[level * (pyramid.size() / (levels_built_ + 1))];
  }
  // Full resolution's derivatives (CV_16SC2), null when the pyramid has none.
  const cv::Mat* fullDerivatives(const std::vector<cv::Mat>& pyramid) const {
    return pyramid.size() / (levels_built_ + 1) == 2 ? &pyramid[1] : nullptr;
  }
  void search(const cv::Mat& gray, const std::vector<cv::Mat>& pyramid);
  int searchLevel(const cv::Size& size) const;
  void noteSearchLevel(int level);
  void startSpreadSearch(const cv::Mat& gray);
  void continueSpreadSearch(const cv::Mat& gray, const std::vector<cv::Mat>& pyramid);
  // The bands of rows a spread search computes its response in, one per image; the
  // corners are chosen on the image after the last band and (from 3 images on) adopted
  // on the one after that.
  int responseBands() const { return std::max(1, params_.search_spread_images - 2); }
  void responseBand(int band);
  void adoptCorners(const cv::Mat& gray, const std::vector<cv::Point2f>& corners);
  void reanchor(const cv::Mat& gray);
  void applyPendingParams();
  int maxFeaturesNow() const;
  void trimToMaxFeatures();
  void moveLostWithImage();
  void reidentify(const std::vector<cv::Mat>& descriptors, std::vector<TrackedPoint>& fresh);
  void rememberLost(const TrackedPoint& point);
  void refreshDescriptors(const std::vector<cv::Mat>& descriptors);
  std::vector<cv::Point2f>& positionsOf(const std::vector<TrackedPoint>& points,
                                        std::vector<cv::Point2f>& out) const;

  TrackerParams params_;
  std::optional<TrackerParams> pending_params_;  // setParams during a spread search
  bool trim_to_max_ = false;                     // max_features was lowered: trim once
  std::vector<TrackedPoint> previous_;
  std::vector<TrackedPoint> current_;
  TrackerFrameStats stats_;
  // One pyramid per image (with its derivatives), shared by Lucas-Kanade forward and
  // backward and the corner search; kept buffers take turns (the image's, the previous
  // image's, and a spread search's image kept for it) so that the steady state allocates
  // no image memory.
  std::vector<cv::Mat> pyramids_[3];
  int pyramid_now_ = 0;
  int pyramid_previous_ = -1;  // -1: none yet
  int levels_built_ = 0;
  // A spread search in progress (spread_part_ > 0: images of it done so far).
  int spread_image_ = -1;  // its search image's pyramid, -1: none
  int spread_part_ = 0;
  int spread_level_ = 0;   // the pyramid level it searches
  int spread_wanted_ = 0;  // corners it may add
  std::vector<cv::Point2f> spread_live_;     // the live points on its search image (the mask)
  std::vector<cv::Point2f> spread_corners_;  // the corners chosen, on its search image
  std::vector<cv::Point2f> spread_to_, spread_back_;
  std::vector<uchar> spread_status_, spread_back_status_;
  cv::Mat spread_response_;  // its search image's response, computed a band per image
  cv::Mat response_rows_;    // cornerResponseRows' work buffer
  // Per-image work buffers, kept for their capacity.
  std::vector<cv::Point2f> before_, after_, back_, live_uv_, fresh_uv_;
  std::vector<uchar> status_, back_status_;
  std::vector<float> error_, motion_x_, motion_y_;
  std::vector<int> recheck_index_;
  std::vector<cv::Point2f> recheck_from_, recheck_back_;
  std::vector<uchar> recheck_status_, recheck_back_status_;
  std::vector<cv::Point2f> recheck_to_;
  cv::Point2f image_motion_;  // predict_motion: the sample's median motion
  std::vector<TrackedPoint> fresh_;
  CornerSearchBuffers search_buffers_;
  cv::Size image_size_;
  std::uint64_t next_id_ = 1;
  long frame_count_ = 0;
  int found_at_last_search_ = 0;
  int frames_since_search_ = 0;
  bool coarse_came_short_ = false;  // the last coarse search needed full resolution too
  int searches_at_full_ = 0;        // searches since, at full resolution
  std::unordered_map<std::uint64_t, cv::Mat> descriptors_;  // live points, by id
  std::vector<LostPoint> lost_;                             // re-identification pool
};

}  // namespace mono_plane_detection
