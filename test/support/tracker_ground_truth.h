// Test support: runs a FeatureTracker over views of a texture through known
// homographies, keeping every state and the TrackScorer's verdict.
#pragma once

#include <vector>

#include "mono_plane_detection/tracking/feature_tracker.h"
#include "mono_plane_detection/sim/synthetic_views.h"
#include "mono_plane_detection/eval/track_scorer.h"

namespace mono_plane_detection {

struct GroundTruthRun {
  std::vector<std::vector<TrackedPoint>> states;  // per frame
  std::vector<TrackerFrameStats> stats;           // per frame
  TrackScorer score;
};

inline GroundTruthRun runOnViews(FeatureTracker& tracker, const cv::Mat& texture,
                                 const std::vector<cv::Matx33d>& homographies,
                                 const cv::Size& view_size) {
  GroundTruthRun run;
  for (const cv::Matx33d& H : homographies) {
    const auto& points = tracker.process(warpView(texture, H, view_size));
    run.score.observe(points, H);
    run.states.push_back(points);
    run.stats.push_back(tracker.lastStats());
  }
  return run;
}

// Translations of the texture by `step` px per frame, starting at `start`.
inline std::vector<cv::Matx33d> translations(int frames, const cv::Point2d& start,
                                             const cv::Point2d& step, double rotation_step = 0.0,
                                             const cv::Point2d& center = {320, 240}) {
  std::vector<cv::Matx33d> hs;
  for (int k = 0; k < frames; ++k) {
    hs.push_back(similarity(rotation_step * k, center, start + k * step));
  }
  return hs;
}

}  // namespace mono_plane_detection
