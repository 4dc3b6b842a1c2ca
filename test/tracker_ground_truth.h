// Test support: runs a FeatureTracker over views of a texture through known
// homographies and measures every point against where it truly is.
#pragma once

#include <algorithm>
#include <map>
#include <vector>

#include "mono_plane_detection/feature_tracker.h"
#include "mono_plane_detection/synthetic_views.h"

namespace mono_plane_detection {

struct GroundTruthRun {
  std::vector<std::vector<TrackedPoint>> states;   // per frame
  std::vector<TrackerFrameStats> stats;            // per frame
  std::map<std::uint64_t, cv::Point2d> texture_of; // id -> texture pixel at first sight
  std::vector<double> errors;                      // px, tracked points vs truth
  double meanError() const {
    double s = 0;
    for (double e : errors) s += e;
    return errors.empty() ? 0.0 : s / errors.size();
  }
  double percentileError(double q) const {
    if (errors.empty()) return 0.0;
    std::vector<double> sorted = errors;
    const size_t k = std::min(sorted.size() - 1, static_cast<size_t>(q * sorted.size()));
    std::nth_element(sorted.begin(), sorted.begin() + k, sorted.end());
    return sorted[k];
  }
  double maxError() const {
    double m = 0;
    for (double e : errors) m = std::max(m, e);
    return m;
  }
};

// texture pixel = H^-1 view pixel; a point's error is the distance between its
// position and the transfer of the texture pixel its id was born on.
inline GroundTruthRun runOnViews(FeatureTracker& tracker, const cv::Mat& texture,
                                 const std::vector<cv::Matx33d>& homographies,
                                 const cv::Size& view_size) {
  GroundTruthRun run;
  for (const cv::Matx33d& H : homographies) {
    const auto& points = tracker.process(warpView(texture, H, view_size));
    const cv::Matx33d Hinv = H.inv();
    for (const auto& p : points) {
      const cv::Point2d uv(p.uv.x, p.uv.y);
      auto it = run.texture_of.find(p.id);
      if (it == run.texture_of.end()) {
        run.texture_of[p.id] = transfer(Hinv, uv);
        continue;
      }
      const cv::Point2d truth = transfer(H, it->second);
      if (p.is_tracked) run.errors.push_back(cv::norm(truth - uv));
    }
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
